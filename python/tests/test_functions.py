"""vitri.Rbf and vitri.LocalRbf: interpolation residuals, gradients, batch evaluation, edits equal to
fresh fits."""
import numpy as np
import pytest

import vitri
from conftest import sphere_constraints


def random_points(n, seed):
    return np.random.default_rng(seed).uniform(-1.5, 1.5, size=(n, 3))


@pytest.mark.parametrize("cls", [vitri.Rbf, vitri.LocalRbf])
def test_interpolation_residuals(cls):
    pts, vals = sphere_constraints(150)
    f = cls(pts, vals)
    assert len(f) == len(pts)
    assert np.max(np.abs(f(pts) - vals)) < 1e-7
    assert abs(f.value(pts[5]) - vals[5]) < 1e-7  # one point -> float
    q = random_points(50, 1)
    assert np.allclose(f(q), [f.value(x) for x in q], rtol=0, atol=1e-12)
    cp, cv = f.constraints()
    assert np.array_equal(cp, pts) and np.array_equal(cv, vals)


@pytest.mark.parametrize("cls", [vitri.Rbf, vitri.LocalRbf])
def test_gradient_matches_finite_differences(cls):
    pts, vals = sphere_constraints(120)
    f = cls(pts, vals)
    q = random_points(20, 2) * 0.5
    v, g = f.value_gradient(q)
    assert g.shape == (20, 3) and np.allclose(v, f(q))
    h = 1e-6
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        fd = (f(q + e) - f(q - e)) / (2 * h)
        assert np.allclose(g[:, k], fd, rtol=1e-4, atol=1e-5)
    assert np.allclose(f.gradient(q[0]), g[0])


@pytest.mark.parametrize("cls", [vitri.Rbf, vitri.LocalRbf])
def test_edits_equal_fresh_fits(cls):
    pts, vals = sphere_constraints(100)
    f = cls(pts, vals)
    i = f.add([0.1, 0.2, 0.05], -0.8)
    assert i == len(pts) and len(f) == len(pts) + 1
    f.move(3, pts[3] * 1.05)
    f.set_value(7, 0.02)
    f.remove(11)
    p2 = np.vstack([pts, [[0.1, 0.2, 0.05]]])
    v2 = np.append(vals, -0.8)
    p2[3] *= 1.05
    v2[7] = 0.02
    p2 = np.delete(p2, 11, axis=0)
    v2 = np.delete(v2, 11)
    cp, cv = f.constraints()
    assert np.allclose(cp, p2) and np.allclose(cv, v2)
    fresh = cls(p2, v2)
    q = random_points(200, 3)
    assert np.max(np.abs(f(q) - fresh(q))) < 1e-6


def test_rbf_parts():
    pts, vals = sphere_constraints(60)
    f = vitri.Rbf(pts, vals, solver="lu", threads=1)
    w = f.weights()
    c, lin = f.polynomial()
    x = np.array([0.3, -0.2, 0.1])
    r = np.linalg.norm(pts - x, axis=1)
    assert abs(np.sum(w * r ** 3) + c + lin @ x - f(x)) < 1e-9
    with pytest.raises(vitri.InvalidArgument, match="solver"):
        vitri.Rbf(pts, vals, solver="qr")


def test_local_smoothing_approximates():
    pts, vals = sphere_constraints(150)
    noisy = vals + np.random.default_rng(4).normal(0, 0.01, len(vals))
    f = vitri.LocalRbf(pts, noisy, smoothing=0.1)
    assert np.max(np.abs(f(pts) - noisy)) > 1e-6  # no longer interpolates


@pytest.mark.parametrize("cls", [vitri.Rbf, vitri.LocalRbf])
def test_stable_ids(cls):
    pts, vals = sphere_constraints(80)
    f = cls(pts, vals)
    f.remove(5)
    assert 5 not in f and 6 in f and f.ids()[5] == 6
    f.set_value(6, 0.03)
    assert f.constraint(6)[1] == 0.03
    i = f.add([0.0, 0.0, 0.2], -0.6)
    assert i == len(pts) and f.ids()[-1] == i
    with pytest.raises(vitri.UnknownConstraint):
        f.remove(5)
