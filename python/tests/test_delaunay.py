"""vitri.Delaunay: validity after every kind of change, the same tetrahedra as the C++ library (through
`vitri tetrahedralize`) and as a fresh build after edits."""
import subprocess

import numpy as np
import pytest

import vitri


def canonical(tets):
    """The tetrahedra as a set of sorted id tuples."""
    return {tuple(t) for t in np.sort(np.asarray(tets, dtype=np.int64), axis=1)}


def positions_of(d, tets):
    ids, pos = d.vertices()
    where = dict(zip(ids.tolist(), map(tuple, pos)))
    return {tuple(sorted(where[v] for v in t)) for t in np.asarray(tets).tolist()}


def test_bulk_build_is_valid_and_consistent():
    p = np.random.default_rng(1).uniform(size=(300, 3))
    d = vitri.Delaunay(p)
    ids = d.insert(p)
    assert ids.dtype == np.uint32 and len(np.unique(ids)) == 300 and ids.min() >= 8
    assert d.is_valid() and len(d) == 308
    T = d.tetrahedra()
    assert T.shape == (d.num_tetrahedra, 4)
    # positive orientation
    ids_all, pos = d.vertices()
    at = np.empty((ids_all.max() + 1, 3))
    at[ids_all] = pos
    a, b, c, e = (at[T[:, k]] for k in range(4))
    assert np.all(np.einsum("ij,ij->i", np.cross(b - a, c - a), e - a) > 0)
    # neighbours are symmetric and share a face
    nb = d.neighbors()
    hull = 0
    for k in range(len(T)):
        for i in range(4):
            j = nb[k, i]
            if j == 0xFFFFFFFF:
                hull += 1
                continue
            assert k in nb[j]
            assert len(set(T[k]) & set(T[j])) == 3 and T[k, i] not in T[j]
    assert hull == 12  # the box's 6 faces, 2 triangles each


def test_same_tetrahedra_as_the_cli(cli, tmp_path):
    p = np.random.default_rng(2).uniform(size=(200, 3))
    src = tmp_path / "p.xyz"
    np.savetxt(src, p, fmt="%.17g")
    out = tmp_path / "t.txt"
    subprocess.run([cli, "tetrahedralize", str(src), "-o", str(out)], check=True, capture_output=True)
    theirs = canonical(np.loadtxt(out, dtype=np.int64))
    d = vitri.Delaunay(p)
    ids = d.insert(p)
    label = {int(v): i for i, v in enumerate(ids)}
    label.update({k: 200 + k for k in range(8)})  # the CLI numbers the corners after the points
    mine = canonical([[label[int(v)] for v in t] for t in d.tetrahedra()])
    assert mine == theirs


def test_edits_equal_a_fresh_build():
    rng = np.random.default_rng(3)
    p = rng.uniform(size=(150, 3))
    box = [[-1, -1, -1], [2, 2, 2]]
    d = vitri.Delaunay(box=box)
    ids = list(d.insert(p[:100]))
    for q in p[100:]:
        ids.append(d.insert_point(q))
    assert d.is_valid()
    for v in ids[:20]:
        d.remove(int(v))
    assert d.is_valid()
    moved = rng.uniform(size=(10, 3))
    for v, q in zip(ids[20:30], moved):
        assert d.move(int(v), q)
    assert d.is_valid()
    final = np.vstack([moved, p[30:]])
    fresh = vitri.Delaunay(box=box, keep_history=False)
    fresh.insert(final)
    assert positions_of(d, d.tetrahedra()) == positions_of(fresh, fresh.tetrahedra())
    assert np.array_equal(d.point(int(ids[20])), moved[0])


def test_locate_and_rejections():
    p = np.random.default_rng(5).uniform(size=(100, 3))
    d = vitri.Delaunay(p)
    d.insert(p)
    for q in np.random.default_rng(6).uniform(size=(20, 3)):
        t = d.locate(q)
        _, pos = d.vertices()
        ids, _ = d.vertices()
        at = {int(i): x for i, x in zip(ids, pos)}
        a, b, c, e = (at[int(v)] for v in t)
        M = np.column_stack([b - a, c - a, e - a])
        lam = np.linalg.solve(M, q - a)
        assert np.all(lam >= -1e-9) and lam.sum() <= 1 + 1e-9
    assert d.insert_point(p[0]) is None  # duplicate
    assert d.insert(p[:3]).tolist() == [0xFFFFFFFF] * 3
    with pytest.raises(vitri.InvalidPoint):
        d.insert_point([10.0, 0, 0])  # outside the box
    with pytest.raises(vitri.InvalidArgument):
        d.remove(3)  # a corner
