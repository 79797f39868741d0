"""vitri.read / vitri.write: round trips through every format."""
import types

import numpy as np
import pytest

import vitri
from conftest import assert_closed_manifold, euler_characteristic, sphere_points


@pytest.fixture(scope="module")
def mesh():
    return vitri.reconstruct(sphere_points(300)[0], precision=0.1)


@pytest.mark.parametrize("name,ascii", [("m.obj", False), ("m.off", False), ("m.ply", False), ("m.ply", True)])
def test_mesh_round_trip(tmp_path, mesh, name, ascii):
    path = str(tmp_path / name)
    vitri.write(path, mesh, ascii=ascii)
    back = vitri.read(path)
    assert isinstance(back, vitri.Mesh)
    assert np.array_equal(back.faces, mesh.faces)
    exact = not name.endswith(".ply") or ascii  # binary PLY stores float32 positions
    assert np.allclose(back.vertices, mesh.vertices, rtol=0, atol=0 if exact else 1e-6)
    if not name.endswith(".off"):
        assert np.allclose(back.normals, mesh.normals, atol=1e-6)


def test_stl_round_trip(tmp_path, mesh):
    """Binary STL: float32 corners, no normals; read back welded into the same indexed mesh (the vertices
    in the order the triangles first use them)."""
    path = str(tmp_path / "m.stl")
    vitri.write(path, mesh)
    with open(path, "rb") as f:
        data = f.read()
    assert len(data) == 84 + 50 * len(mesh.faces) and not data.startswith(b"solid")
    back = vitri.read(path)
    assert isinstance(back, vitri.Mesh) and back.normals is None
    assert len(back.vertices) == len(mesh.vertices) and len(back.faces) == len(mesh.faces)
    corners = np.asarray(mesh.vertices, dtype=np.float32)[mesh.faces]
    assert np.array_equal(np.asarray(back.vertices)[back.faces], corners.astype(np.float64))
    assert euler_characteristic(back.vertices, back.faces) == euler_characteristic(mesh.vertices, mesh.faces)
    assert_closed_manifold(back.vertices, back.faces)


def test_tuple_and_no_normals(tmp_path, mesh):
    path = str(tmp_path / "t.obj")
    vitri.write(path, (mesh.vertices, mesh.faces))
    back = vitri.read(path)
    assert back.normals is None and np.array_equal(back.faces, mesh.faces)


def test_constraints_and_points_round_trip(tmp_path):
    p, n = sphere_points(100)
    v = np.linspace(-1, 1, 100)
    vitri.write(str(tmp_path / "c.xyzv"), types.SimpleNamespace(points=p, values=v))
    c = vitri.read(str(tmp_path / "c.xyzv"))
    assert c.kind == "constraints" and np.array_equal(c.points, p) and np.array_equal(c.values, v)
    vitri.write(str(tmp_path / "p.pwn"), types.SimpleNamespace(points=p, normals=n))
    q = vitri.read(str(tmp_path / "p.pwn"))
    assert q.kind == "points" and np.array_equal(q.points, p) and np.array_equal(q.normals, n)
    vitri.write(str(tmp_path / "p.xyz"), types.SimpleNamespace(points=p))
    q = vitri.read(str(tmp_path / "p.xyz"))
    assert q.normals is None and np.array_equal(q.points, p)


def test_text_exports_with_colours_and_headers(tmp_path):
    """A CloudCompare-style export (header, commas, colours before the normals) reads its normals; an
    x y z r g b file keeps its colours out of the normals; `columns` says what was read."""
    p, n = sphere_points(50)
    rgb = np.tile([200, 17, 3], (50, 1))
    table = np.hstack([p, rgb, n])
    path = tmp_path / "cc.txt"
    with open(path, "w") as f:
        f.write("//X,Y,Z,R,G,B,Nx,Ny,Nz\n")
        for row in table:
            f.write(",".join(repr(float(x)) for x in row) + "\n")
    q = vitri.read(str(path))
    assert np.array_equal(q.points, p) and np.array_equal(q.normals, n)
    assert "skipped r g b" in q.columns
    np.savetxt(tmp_path / "c.xyz", np.hstack([p, rgb]), fmt="%.17g")
    q = vitri.read(str(tmp_path / "c.xyz"))
    assert q.normals is None and np.array_equal(q.points, p) and "colours" in q.columns


def test_bundled_models(data_dir):
    hand = vitri.read(data_dir + "/hand.off")
    assert euler_characteristic(hand.vertices, hand.faces) == 2
    scan = vitri.read(data_dir + "/hippo1_view.xyz")
    assert scan.kind == "points" and scan.points.shape[1] == 3


def test_write_errors(tmp_path, mesh):
    with pytest.raises(vitri.InvalidArgument, match="obj, .off, .ply or .stl"):
        vitri.write(str(tmp_path / "m.3mf"), mesh)
    with pytest.raises(vitri.InvalidArgument, match="out of range"):
        vitri.write(str(tmp_path / "m.obj"), (mesh.vertices[:3], mesh.faces))
    with pytest.raises(TypeError):
        vitri.write(str(tmp_path / "m.obj"), 42)
