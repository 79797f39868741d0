"""vitri.reconstruct and vitri.mesh_constraints: closed meshes of the right topology, the CLI's result,
levels, the array conventions (dtype, memory order, views)."""
import os
import subprocess

import numpy as np
import pytest

import vitri
from conftest import (assert_closed_manifold, euler_characteristic, signed_volume, sphere_constraints,
                      sphere_points)


def test_version():
    assert isinstance(vitri.__version__, str) and vitri.__version__.count(".") == 2


def test_sphere_scan_is_a_closed_sphere():
    p, _ = sphere_points(800)
    mesh = vitri.reconstruct(p)
    V, F, N = mesh
    assert V.dtype == np.float64 and V.shape[1] == 3 and F.dtype == np.uint32 and N.shape == V.shape
    assert_closed_manifold(V, F)
    assert euler_characteristic(V, F) == 2
    assert signed_volume(V, F) > 0  # counter-clockwise seen from outside
    r = np.linalg.norm(V, axis=1)
    assert np.all(np.abs(r - 1.0) < 0.05)
    assert np.allclose(np.linalg.norm(N, axis=1), 1.0)
    assert np.all(np.einsum("ij,ij->i", N, V) > 0)  # outward normals


def cone_points(n, seed):
    """A closed cone (base radius 0.5 at z = 0, apex at z = 1), n area-uniform samples, no normals."""
    rng = np.random.default_rng(seed)
    r0, h = 0.5, 1.0
    base, side = np.pi * r0 * r0, np.pi * r0 * np.hypot(r0, h)
    t = 2 * np.pi * rng.random(n)
    on_base = rng.random(n) * (base + side) < base
    s = np.sqrt(rng.random(n))  # the base: radius / r0; the side: 0 at the apex, 1 at the rim
    z = np.where(on_base, 0.0, h * (1 - s))
    return np.c_[r0 * s * np.cos(t), r0 * s * np.sin(t), z]


def test_unoriented_cone_with_its_base_flipped_is_repaired():
    # The spanning tree flips this sample's base across the sharp rim (normals 117 degrees apart); the
    # regions repair it (docs/scans.md, step 4) and the stats say how many points it concerned.
    p = cone_points(5000, 3)
    m = vitri.Mesher.from_scan(p)
    stats = m.stats()
    assert stats["scan_regions_flipped"] > 0
    assert stats["scan_regions_flipped"] < len(p)
    assert stats["scan_ambiguous"] >= 0 and stats["scan_repaired"] == 0  # no given normals to repair
    assert stats["scan_edge_normals"] > 0  # clean data: the points along the rim take their face's normal
    V, F, _ = vitri.reconstruct(p)
    assert_closed_manifold(V, F)
    assert euler_characteristic(V, F) == 2
    assert signed_volume(V, F) > 0


def test_outputs_own_their_memory():
    p, _ = sphere_points(300)
    V, F, N = vitri.reconstruct(p, precision=0.1)
    for a in (V, F, N):
        assert a.base is not None and a.flags.c_contiguous  # a view of the library's vector, no copy
        a[0] = a[0]  # writeable


def test_with_normals_and_options():
    p, n = sphere_points(600)
    V, F, _ = vitri.reconstruct(p, n, precision=0.05, function="global", threads=1, surface="closed")
    assert_closed_manifold(V, F)
    assert euler_characteristic(V, F) == 2


def test_levels_of_detail():
    p, n = sphere_points(500)
    meshes = vitri.reconstruct(p, n, precision=[0.1, 0.02])
    assert isinstance(meshes, list) and len(meshes) == 2
    assert len(meshes[1].vertices) > len(meshes[0].vertices)
    for V, F, _ in meshes:
        assert euler_characteristic(V, F) == 2


def test_quality_mode():
    p, n = sphere_points(400)
    V, F, _ = vitri.reconstruct(p, n, precision=0.08, min_angle=25)
    assert_closed_manifold(V, F)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]

    def angle(u, v):
        return np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", u, v) /
                                            (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)), -1, 1)))
    smallest = np.minimum(np.minimum(angle(b - a, c - a), angle(a - b, c - b)), angle(a - c, b - c))
    assert smallest.min() >= 25 - 1e-6


def test_dtypes_and_memory_orders_give_the_same_mesh():
    p, _ = sphere_points(400)
    ref = vitri.reconstruct(p, precision=0.08, threads=1)
    big = np.zeros((800, 6))
    big[::2, 1:4] = p  # a strided view: neither C nor Fortran contiguous
    for variant in (np.asfortranarray(p), big[::2, 1:4], p.tolist()):
        m = vitri.reconstruct(variant, precision=0.08, threads=1)
        assert np.array_equal(m.vertices, ref.vertices) and np.array_equal(m.faces, ref.faces)
    m32 = vitri.reconstruct(p.astype(np.float32), precision=0.08, threads=1)
    assert euler_characteristic(m32.vertices, m32.faces) == 2


def test_mesh_constraints():
    pts, vals = sphere_constraints(200)
    V, F, N = vitri.mesh_constraints(pts, vals, precision=0.05)
    assert_closed_manifold(V, F)
    assert euler_characteristic(V, F) == 2
    assert np.all(np.abs(np.linalg.norm(V, axis=1) - 1) < 0.05)


def test_same_mesh_as_the_cli(cli, tmp_path):
    p, n = sphere_points(700)
    src = tmp_path / "sphere.xyz"
    np.savetxt(src, np.hstack([p, n]), fmt="%.17g")
    out = tmp_path / "out.ply"
    subprocess.run([cli, "mesh", str(src), "-o", str(out), "-q", "--threads", "1", "--precision", "0.04"], check=True)
    cli_mesh = vitri.read(str(out))
    read = vitri.read(str(src))  # the same points as the CLI read them
    mine = vitri.reconstruct(read.points, read.normals, precision=0.04, threads=1)
    assert np.array_equal(mine.faces, cli_mesh.faces)
    assert np.allclose(mine.vertices, cli_mesh.vertices, rtol=0, atol=1e-6)  # binary PLY stores floats


def test_same_mesh_as_the_cli_constraints(cli, tmp_path):
    pts, vals = sphere_constraints(150)
    src = tmp_path / "c.xyzv"
    vitri.write(str(src), type("C", (), {"points": pts, "values": vals})())
    out = tmp_path / "out.obj"
    subprocess.run([cli, "mesh", str(src), "-o", str(out), "-q", "--threads", "1"], check=True)
    cli_mesh = vitri.read(str(out))
    mine = vitri.mesh_constraints(pts, vals, threads=1)
    assert np.array_equal(mine.faces, cli_mesh.faces)
    assert np.allclose(mine.vertices, cli_mesh.vertices, rtol=0, atol=1e-12)


def test_unknown_and_bad_options():
    p, _ = sphere_points(100)
    with pytest.raises(TypeError, match="precsion"):
        vitri.reconstruct(p, precsion=0.1)
    with pytest.raises(vitri.InvalidArgument, match="precision"):
        vitri.reconstruct(p, precision=-1)
    with pytest.raises(ValueError, match="coarse to fine"):
        vitri.reconstruct(p, precision=[0.05, 0.1])
    with pytest.raises(vitri.InvalidArgument, match="function"):
        vitri.reconstruct(p, function="spline")
    with pytest.raises(vitri.LimitError):
        vitri.reconstruct(p, precision=0.001, max_vertices=2000)
    with pytest.raises(vitri.InvalidArgument, match="handles"):
        vitri.reconstruct(p, handles=-1)


def test_handles_option_as_the_cli(cli, tmp_path, data_dir):
    """handles= as --handles: a noisy elephant's mesh with the noise's handles cut (the default) or kept (0)."""
    rng = np.random.default_rng(3)
    model = vitri.read(os.path.join(data_dir, "elephant.off"))
    V, F = model.vertices, model.faces
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    t = rng.choice(len(F), 20000, p=area / area.sum())
    r1, r2 = np.sqrt(rng.random(len(t))), rng.random(len(t))
    p = (1 - r1)[:, None] * a[t] + (r1 * (1 - r2))[:, None] * b[t] + (r1 * r2)[:, None] * c[t]
    spacing = np.sqrt(area.sum() / len(p))
    p += rng.normal(0.0, 0.7 * spacing, p.shape)
    def euler(m):
        return euler_characteristic(m.vertices, m.faces)
    cut, kept = vitri.reconstruct(p, threads=1), vitri.reconstruct(p, threads=1, handles=0)
    assert euler(cut) > euler(kept)  # handles of the noise were cut
    src = tmp_path / "e.xyz"
    np.savetxt(src, p, fmt="%.17g")
    out = tmp_path / "e.ply"
    subprocess.run([cli, "mesh", str(src), "-o", str(out), "-q", "--threads", "1", "--handles", "0"], check=True)
    assert euler(vitri.read(str(out))) == euler(vitri.reconstruct(vitri.read(str(src)).points, threads=1, handles=0))


def test_memory_limit_and_certify_options(cli, tmp_path):
    """memory= as --memory (a size string or bytes); certify= as --certify; both checked like the CLI's."""
    p, n = sphere_points(3000)
    default = vitri.reconstruct(p, n, precision=0.05, threads=1)
    roomy = vitri.reconstruct(p, n, precision=0.05, threads=1, memory="16G")
    assert np.array_equal(default.faces, roomy.faces)  # a limit that holds everything changes nothing
    assert np.array_equal(roomy.faces, vitri.reconstruct(p, n, precision=0.05, threads=1, memory=16 << 30).faces)
    # Far too small for anything: refused before the fit, naming the sizes, as the CLI's --memory 1M.
    with pytest.raises(vitri.LimitError):
        vitri.reconstruct(p, n, precision=0.05, memory="1M")
    src = tmp_path / "sphere.pwn"
    np.savetxt(src, np.hstack([p, n]), fmt="%.17g")
    assert subprocess.run([cli, "mesh", str(src), "-o", str(tmp_path / "o.ply"), "-q", "--memory", "1M"]).returncode == 1
    for bad in ("lots", "-3G", 0):
        with pytest.raises(ValueError, match="memory"):
            vitri.reconstruct(p, n, memory=bad)
    with pytest.raises(ValueError, match="certify_floor"):
        vitri.reconstruct(p, n, certify=True, certify_floor=2.0)
    # The certified mode on the global function (a small sphere of constraints): the Mesher reports how many
    # tetrahedra are left uncertified; an analytic-free check that the option reaches the polygonizer.
    pts, vals = sphere_constraints(60)
    plain = vitri.Mesher(pts, vals, function="global")
    plain.refine(0.3 * plain.stats()["diagonal"])
    assert plain.stats()["uncertified"] == 0  # not asked: nothing counted
    cert = vitri.Mesher(pts, vals, function="global", certify=True, certify_floor=1.0)
    cert.refine(0.3 * cert.stats()["diagonal"])
    assert cert.stats()["uncertified"] >= 0
    assert cert.stats()["delaunay_vertices"] >= plain.stats()["delaunay_vertices"]
    # certify_budget as --certify-budget: a budget of 1e-4 x 25,000 = 3 points ends the level there, said in stats.
    with pytest.raises(ValueError, match="certify_budget"):
        vitri.Mesher(pts, vals, certify=True, certify_budget=-1.0)
    tight = vitri.Mesher(pts, vals, function="global", certify=True, certify_floor=0.01, certify_budget=1e-4)
    tight.refine(0.3 * tight.stats()["diagonal"])
    assert tight.stats()["certify_budget_reached"]
    assert tight.stats()["uncertified"] > 0
    assert not cert.stats()["certify_budget_reached"]
