"""Shared helpers of the pytest suite (python/tests): sample surfaces with a known truth and mesh checks.

Run: PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests (ctest runs it as the test `python`).
VITRI_CLI, when set (ctest sets it), is the `vitri` executable the results are compared with.
"""
import os
import shutil

import numpy as np
import pytest


def sphere_points(n, radius=1.0, center=(0.0, 0.0, 0.0)):
    """n points spread evenly on a sphere (Fibonacci lattice) and their outward unit normals."""
    i = np.arange(n) + 0.5
    phi = np.arccos(1.0 - 2.0 * i / n)
    theta = np.pi * (1.0 + 5.0 ** 0.5) * i
    normals = np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], axis=1)
    return np.asarray(center) + radius * normals, normals


def sphere_constraints(n, offset=0.1):
    """Constraints of the unit sphere: f = 0 on n points, +offset outside and -offset inside each."""
    p, nrm = sphere_points(n)
    points = np.concatenate([p, p + offset * nrm, p - offset * nrm])
    values = np.concatenate([np.zeros(n), np.full(n, offset), np.full(n, -offset)])
    return points, values


def edges(F):
    """The undirected edges of a triangle list and how many triangles use each."""
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]).astype(np.int64), axis=1)
    return np.unique(e, axis=0, return_counts=True)


def euler_characteristic(V, F):
    e, _ = edges(F)
    used = np.unique(F)
    return len(used) - len(e) + len(F)


def assert_closed_manifold(V, F):
    """Every edge in exactly two triangles, each directed edge once (consistent orientation)."""
    _, counts = edges(F)
    assert np.all(counts == 2), "open or non-manifold edges"
    d = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]).astype(np.int64)
    assert len(np.unique(d, axis=0)) == len(d), "inconsistent orientation"


def signed_volume(V, F):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


@pytest.fixture
def cli():
    """The `vitri` executable (VITRI_CLI or on PATH), or skip."""
    path = os.environ.get("VITRI_CLI") or shutil.which("vitri")
    if not path:
        pytest.skip("the vitri CLI is not available (set VITRI_CLI)")
    return path


@pytest.fixture
def data_dir():
    d = os.environ.get("VITRI_DATA_DIR") or os.path.join(os.path.dirname(__file__), "..", "..", "data")
    return os.path.abspath(d)
