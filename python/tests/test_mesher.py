"""vitri.Mesher: construction from every input, refinement and levels, meshes, deltas, edits equal to
fresh fits, stats."""
import numpy as np
import pytest

import vitri
from conftest import assert_closed_manifold, euler_characteristic, signed_volume, sphere_constraints, sphere_points


def test_from_constraints_levels():
    pts, vals = sphere_constraints(150)
    m = vitri.Mesher(pts, vals)
    assert len(m) == len(pts) and m.function == "global"
    m.refine(0.1, relative=True)
    coarse = m.mesh()
    m.refine(0.04 * m.diagonal)  # absolute; continues the same structure
    fine = m.mesh()
    assert len(fine.vertices) > len(coarse.vertices)
    for V, F, _ in (coarse, fine):
        assert_closed_manifold(V, F)
        assert euler_characteristic(V, F) == 2
    s = m.stats()
    assert s["constraints"] == len(pts) and s["precision"] == pytest.approx(0.04 * m.diagonal)


@pytest.mark.parametrize("make", [
    lambda p, n: vitri.Mesher.from_oriented_points(p, n),
    lambda p, n: vitri.Mesher.from_points(p),
    lambda p, n: vitri.Mesher.from_scan(p),
    lambda p, n: vitri.Mesher.from_scan(p, n, surface="closed"),
])
def test_point_constructors(make):
    p, n = sphere_points(400)
    m = make(p, n)
    m.refine(0.06, relative=True)
    V, F, _ = m.mesh()
    assert euler_characteristic(V, F) == 2


def test_from_mesh():
    sphere = vitri.reconstruct(sphere_points(300)[0], precision=0.1)
    m = vitri.Mesher.from_mesh(sphere.vertices, sphere.faces)
    m.refine(0.08, relative=True)
    V, F, _ = m.mesh()
    assert euler_characteristic(V, F) == 2


def test_from_mesh_facet_check():
    # A cube as a CAD export writes it (8 vertices): its vertices alone interpolate a blob; the facet
    # check adds points on the faces, and the mesh lies on them (docs/guide.md "Meshes with large facets").
    V = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=float)
    F = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                  [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])

    def worst(m):
        m.refine(0.03, relative=True)
        Vout, Fout, _ = m.mesh()
        assert_closed_manifold(Vout, Fout)
        inside = np.minimum(Vout, 1 - Vout).min(axis=1)  # distance to the faces from inside
        outside = np.linalg.norm(np.maximum(Vout - 1, 0) + np.maximum(-Vout, 0), axis=1)
        return np.where(outside > 0, outside, inside).max()

    m = vitri.Mesher.from_mesh(V, F, function="local", threads=2)
    s = m.stats()
    assert s["facet_triangles"] == 12 and s["facet_points"] > 1000 and s["facet_samples"] > 0
    assert worst(m) < 0.03
    plain = vitri.Mesher.from_mesh(V, F, function="local", threads=2, vertices_only=True)
    assert plain.stats()["facet_points"] == 0
    assert worst(plain) > 0.1


def test_from_mesh_merges_a_triangle_soup():
    # A triangle soup (one vertex per corner, as an STL solid has them) was refused as a mesh with a
    # boundary; its coincident vertices are merged, and it gives the indexed mesh's function exactly.
    sphere = vitri.reconstruct(sphere_points(300)[0], precision=0.1)
    soup_v = sphere.vertices[sphere.faces.reshape(-1)]
    soup_f = np.arange(soup_v.shape[0]).reshape(-1, 3)
    m = vitri.Mesher.from_mesh(soup_v, soup_f)
    m.refine(0.08, relative=True)
    indexed = vitri.Mesher.from_mesh(sphere.vertices, sphere.faces)
    indexed.refine(0.08, relative=True)
    V, F, _ = m.mesh()
    V0, F0, _ = indexed.mesh()
    assert_closed_manifold(V, F)
    assert V.shape == V0.shape and F.shape == F0.shape
    assert np.allclose(V, V0, rtol=0, atol=1e-9 * np.ptp(V0, axis=0).max())


def test_from_mesh_leaves_out_triangles_without_area():
    # A triangle that names a vertex twice (exporters leave them): left out with a warning, as `vitri mesh`
    # does; the rest of the closed mesh gives the same mesh as without it (it was refused before).
    sphere = vitri.reconstruct(sphere_points(300)[0], precision=0.1)
    faces = np.vstack([sphere.faces, [[0, 0, 1]]])
    with pytest.warns(RuntimeWarning, match="1 triangle"):
        m = vitri.Mesher.from_mesh(sphere.vertices, faces)
    m.refine(0.08, relative=True)
    clean = vitri.Mesher.from_mesh(sphere.vertices, sphere.faces)
    clean.refine(0.08, relative=True)
    V, F, _ = m.mesh()
    V0, F0, _ = clean.mesh()
    assert np.array_equal(V, V0) and np.array_equal(F, F0)


def test_edits_equal_a_fresh_fit():
    pts, vals = sphere_constraints(100)
    m = vitri.Mesher(pts, vals, function="global")
    m.refine(0.08, relative=True)
    i = m.add([0.0, 0.0, 1.3], 0.0)  # a bump on top
    m.move(5, pts[5] * 1.05)
    m.set_value(2, 0.01)
    m.remove(40)
    cp, cv = m.constraints()
    fresh = vitri.Rbf(cp, cv)
    q = np.random.default_rng(0).uniform(-1.2, 1.2, size=(100, 3))
    assert np.max(np.abs(m.value(q) - fresh(q))) < 1e-6
    assert i == len(pts)
    V, F, _ = m.mesh()
    assert_closed_manifold(V, F)
    assert np.max(V[:, 2]) > 1.2  # the bump is in the mesh
    # the same surface as a fresh Mesher of the edited constraints, to the precision
    other = vitri.Mesher(cp, cv)
    other.refine(0.08, relative=True)
    W = other.mesh().vertices
    assert abs(np.max(W[:, 2]) - np.max(V[:, 2])) < 0.08 * m.diagonal


def test_update_surface_deltas_rebuild_the_mesh():
    pts, vals = sphere_constraints(100)
    m = vitri.Mesher(pts, vals)
    m.refine(0.08, relative=True)
    tris, verts = {}, {}

    def apply(d):
        if d["full"]:
            tris.clear()
            verts.clear()
        for t in d["removed_triangles"]:
            del tris[int(t)]
        for v in d["removed_vertices"]:
            del verts[int(v)]
        changed = np.concatenate([d["added_vertices"], d["moved_vertices"]])
        for v, x in zip(changed, d["changed_vertex_positions"]):
            verts[int(v)] = tuple(x)
        for t, c in zip(d["added_triangles"], d["added_triangle_vertices"]):
            tris[int(t)] = tuple(int(v) for v in c)

    first = m.update_surface()
    assert first["full"]
    apply(first)
    m.move(3, pts[3] * 1.2)
    apply(m.update_surface())
    V, F, _ = m.mesh()
    assert len(tris) == len(F) and len(verts) == len(V)
    mine = sorted(tuple(sorted(verts[v] for v in t)) for t in tris.values())
    ref = sorted(tuple(sorted(map(tuple, V[list(f)]))) for f in F)
    assert mine == ref


def test_quality_mesher_and_restart():
    pts, vals = sphere_constraints(100)
    m = vitri.Mesher(pts, vals, min_angle=20)
    m.refine(0.1, relative=True)
    V, F, _ = m.mesh()
    assert_closed_manifold(V, F)
    m.restart()
    assert m.precision == float("inf")
    m.refine(0.1, relative=True)
    assert len(m.mesh().faces) > 0


def test_edit_errors():
    pts, vals = sphere_constraints(50)
    m = vitri.Mesher(pts, vals)
    with pytest.raises(vitri.InvalidPoint):
        m.move(10**6, [0, 0, 0])
    with pytest.raises(vitri.InvalidPoint):
        m.add(pts[0], 0.0)  # a duplicate
    with pytest.raises(vitri.InvalidArgument):
        m.refine(-1)


def test_stable_constraint_ids():
    pts, vals = sphere_constraints(60)
    m = vitri.Mesher(pts, vals)
    m.refine(0.1, relative=True)
    assert m.ids().tolist() == list(range(len(pts)))
    a = m.add([0.0, 0.0, 0.0], -0.5)
    b = m.add([0.0, 0.0, 0.3], -0.4)
    assert (a, b) == (len(pts), len(pts) + 1)
    m.remove(10)
    assert 10 not in m and 11 in m and a in m
    p11, v11 = m.constraint(11)  # unchanged by the removal of 10
    assert np.array_equal(p11, pts[11]) and v11 == vals[11]
    m.move(b, [0.0, 0.1, 0.3])  # ids, not positions: b is still b after a removal below it
    assert np.allclose(m.constraint(b)[0], [0.0, 0.1, 0.3])
    c = m.add([0.05, 0.0, 0.0], -0.5)
    assert c == len(pts) + 2  # never reused: 10 is not given out again
    ids = m.ids()
    assert 10 not in ids.tolist() and len(ids) == len(m)
    cp, cv = m.constraints()
    assert np.allclose(cp[list(ids).index(b)], [0.0, 0.1, 0.3])
    with pytest.raises(vitri.UnknownConstraint) as e:
        m.move(10, [0, 0, 0])
    assert e.value.id == 10 and isinstance(e.value, vitri.InvalidPoint)
    with pytest.raises(vitri.UnknownConstraint):
        m.set_value(10**9, 0.0)
    V, F, _ = m.mesh()
    assert_closed_manifold(V, F)


def test_a_few_points_keep_their_best_component():
    # 20 points of a sphere in a batch run (vitri.reconstruct, as the CLI): every component is below what
    # they resolve (fewer than 30 nearest to it); the best-supported one is kept, not an empty mesh
    # (docs/scans.md). An editing Mesher judges no component by the data: the flag stays False there.
    p, _ = sphere_points(20)
    V, F, _ = vitri.reconstruct(p)
    assert len(F) > 0
    assert_closed_manifold(V, F)
    assert euler_characteristic(V, F) == 2
    m = vitri.Mesher.from_scan(p)
    m.refine(0.05, relative=True)
    m.mesh()
    assert m.stats()["scan_kept_unresolved"] is False


def test_auto_function_falls_back_to_local_when_the_global_fit_fails():
    # A thin plate's two faces (20 x 20 points each, 0.0005 apart): auto chooses the global function by
    # the count, whose system is then unsolvable; the local one is fitted instead, and stats() says why.
    g = np.linspace(0, 1, 20)
    X, Y = (a.ravel() for a in np.meshgrid(g, g))
    P = np.vstack([np.c_[X, Y, np.zeros_like(X)], np.c_[X, Y, np.full_like(X, 0.0005)]])
    N = np.vstack([np.tile([0, 0, -1.0], (X.size, 1)), np.tile([0, 0, 1.0], (X.size, 1))])
    with pytest.raises(vitri.NumericalError):
        vitri.Mesher.from_oriented_points(P, N, function="global")
    m = vitri.Mesher.from_oriented_points(P, N)
    assert m.function == "local"
    assert "RBF fit failed" in m.stats()["global_fit_failed"]


def test_from_mesh_overlapping_parts_mesh_their_union():
    # Two closed spheres overlapping (an assembly's shells, no boolean union): the points of each inside
    # the other are left out, and the mesh is the union's surface: one closed component, genus 0, its
    # volume the union's (two unit spheres 1 apart: 2 * 4/3 pi - 5 pi / 12 = 7.069).
    sphere = vitri.reconstruct(sphere_points(2000)[0], precision=0.03)
    V0 = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1).max()
    V = np.vstack([V0, V0 + [1.0, 0, 0]])
    F = np.vstack([sphere.faces, sphere.faces + len(V0)])
    m = vitri.Mesher.from_mesh(V, F, threads=2)
    assert m.stats()["mesh_inside_other_parts"] > 0.1 * len(V0)
    m.refine(0.02, relative=True)
    Vo, Fo, _ = m.mesh()
    assert_closed_manifold(Vo, Fo)
    assert euler_characteristic(Vo, Fo) == 2
    assert abs(signed_volume(Vo, Fo) - 7.069) < 0.15
