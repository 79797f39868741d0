"""Bad inputs give the documented exceptions, with the argument, the shape or the row named."""
import numpy as np
import pytest

import vitri
from conftest import sphere_points


def test_hierarchy():
    assert issubclass(vitri.InvalidArgument, vitri.Error) and issubclass(vitri.InvalidArgument, ValueError)
    assert issubclass(vitri.InvalidPoint, vitri.InvalidArgument)
    assert issubclass(vitri.OrientationError, vitri.InvalidPoint)
    assert issubclass(vitri.DegenerateNeighbourhood, vitri.InvalidPoint)
    assert issubclass(vitri.UnknownConstraint, vitri.InvalidPoint)
    for e in (vitri.ParseError, vitri.NumericalError, vitri.LimitError, vitri.Cancelled):
        assert issubclass(e, vitri.Error) and not issubclass(e, ValueError)


@pytest.mark.parametrize("fn", [
    lambda a: vitri.reconstruct(a),
    lambda a: vitri.mesh_constraints(a, np.zeros(len(a))),
    lambda a: vitri.Rbf(a, np.zeros(len(a))),
    lambda a: vitri.Delaunay(a),
])
def test_wrong_shape(fn):
    with pytest.raises(ValueError, match=r"points: expected an \(n, 3\) array, got shape \(10, 2\)"):
        fn(np.zeros((10, 2)))
    with pytest.raises(vitri.InvalidArgument, match=r"got shape \(30,\)"):
        fn(np.zeros(30))


def test_nan_names_the_row():
    p, _ = sphere_points(50)
    p[17, 1] = np.nan
    with pytest.raises(vitri.InvalidPoint, match="row 17") as e:
        vitri.reconstruct(p)
    assert e.value.index == 17
    v = np.zeros(50)
    v[3] = np.inf
    with pytest.raises(vitri.InvalidPoint, match="values"):
        vitri.Rbf(sphere_points(50)[0], v)


def test_wrong_dtype():
    p, _ = sphere_points(50)
    for bad in (p.astype(np.complex128), p.astype(str), p > 0, np.array([[None] * 3] * 5, dtype=object)):
        with pytest.raises(TypeError, match="points: expected a float64 or float32 array"):
            vitri.reconstruct(bad)
    p, _ = sphere_points(300)
    m = vitri.reconstruct((p * 1000).astype(np.int64), precision=0.1)  # integers are converted
    assert len(m.faces) > 0


def test_non_contiguous_is_accepted():
    p, _ = sphere_points(200)
    wide = np.zeros((200, 5))
    wide[:, ::2][:, :3] = p  # columns 0, 2, 4
    view = wide[:, ::2]
    assert not view.flags.c_contiguous and not view.flags.f_contiguous
    a = vitri.reconstruct(view, precision=0.1, threads=1)
    b = vitri.reconstruct(p, precision=0.1, threads=1)
    assert np.array_equal(a.vertices, b.vertices)


def test_empty():
    with pytest.raises(vitri.InvalidArgument, match=r"points: empty \(shape \(0, 3\)\)"):
        vitri.reconstruct(np.zeros((0, 3)))
    with pytest.raises(vitri.InvalidArgument, match="empty"):
        vitri.Mesher(np.zeros((0, 3)), np.zeros(0))


def test_mismatched_normals_and_values():
    p, n = sphere_points(50)
    with pytest.raises(vitri.InvalidArgument, match=r"normals: expected \(50, 3\)"):
        vitri.reconstruct(p, n[:40])
    with pytest.raises(vitri.InvalidArgument, match=r"values: expected a \(50,\) array"):
        vitri.mesh_constraints(p, np.zeros(49))


def test_library_errors_keep_their_message_and_data(tmp_path):
    bad = tmp_path / "bad.xyzv"
    bad.write_text("0 0 0 1\n1 2 x 0\n")
    with pytest.raises(vitri.ParseError, match="bad.xyzv:2") as e:
        vitri.read(str(bad))
    assert e.value.line == 2 and e.value.file.endswith("bad.xyzv")
    with pytest.raises(vitri.ParseError):
        vitri.read(str(tmp_path / "missing.off"))
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 0]], dtype=float)
    with pytest.raises(vitri.InvalidPoint) as e:  # a duplicate constraint
        vitri.Rbf(p, [0, 1, 1, 1, -1])
    assert e.value.index == 4
