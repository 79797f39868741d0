"""The interop examples of docs/python.md, run as tests: Open3D in and out, the edit loop script."""
import os
import subprocess
import sys

import numpy as np
import pytest

import vitri
from conftest import euler_characteristic, sphere_points

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "examples")


def test_edit_loop_script(tmp_path):
    out = tmp_path / "edited.obj"
    r = subprocess.run([sys.executable, os.path.join(EXAMPLES, "edit_loop.py"), str(out)], capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "final:" in r.stdout
    m = vitri.read(str(out))
    assert euler_characteristic(m.vertices, m.faces) == 2 and m.vertices[:, 2].max() > 1.2


def test_open3d_point_cloud_in_mesh_out():
    o3d = pytest.importorskip("open3d")
    p, n = sphere_points(1000)
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(p))
    pcd.normals = o3d.utility.Vector3dVector(n)
    # docs/python.md, "Open3D"
    V, F, N = vitri.reconstruct(np.asarray(pcd.points), np.asarray(pcd.normals))
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V), o3d.utility.Vector3iVector(F.astype(np.int32)))
    mesh.vertex_normals = o3d.utility.Vector3dVector(N)
    assert mesh.is_watertight() and mesh.is_orientable()
    assert euler_characteristic(np.asarray(mesh.vertices), np.asarray(mesh.triangles)) == 2
