#!/usr/bin/python3
"""Locate topology defects of a mesh made from a closed model (docs/benchmarks.md, "Topology matrix").

usage:
  locate.py selfint MODEL.off               model vertices buried inside another part (self-intersection)
  locate.py constraints MODEL.off [OFFSET]  the library's normal constraints checked against the model:
                                            off-surface points on the wrong side or too near its surface
  locate.py compare MODEL.off MESH.obj [T]  components of MESH, and groups of MESH vertices farther than
                                            T (fraction of the diagonal, 0.01) from the model's surface
  locate.py localchi MODEL.off MESH.obj [R] balls of radius R (fraction, 0.015) centred on the model's
                                            surface where the MESH's Euler characteristic differs from
                                            the model's: where the extra handles and bubbles are
  locate.py sweep REF MESH [N]              where MESH's topology departs from REF's (a mesh of the same
                                            surface with the right topology, e.g. a coarser one: not a
                                            coarse model, whose critical points sit elsewhere): along
                                            each axis, chi of the sublevel sets {x_k <= h} of both, N
                                            heights (2000); an extra handle is a lasting drop of 2 at
                                            the same height on all three axes. Works at 10^6 vertices.
  locate.py ballchi REF MESH X Y Z          chi of REF and MESH inside balls around (X, Y, Z) (radii
                                            1e-4 to 3e-2 of the diagonal): a handle in the ball gives -1

MESH and REF: .off, .obj or .ply (ascii or binary little-endian, as vitri writes them). sweep and ballchi
use lower-star sublevel complexes (a vertex, edge or triangle belongs when all its vertices do), which
have the topology of the sublevel sets of the piecewise-linear height or distance, whatever the mesh's
resolution (localchi's clipped balls are ragged at 10^6 vertices).

numpy and scipy (Debian python3-numpy, python3-scipy). Distances to the model are taken to dense
area-weighted samples of its triangles (fixed seed); the side (in/out) from the nearest sample's normal.
"""
import sys

import numpy as np
from scipy.cluster.hierarchy import fcluster, linkage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree


def read_off(path):
    toks = []
    with open(path) as f:
        for line in f:
            toks.extend(line.split('#')[0].split())
    nv, nf = int(toks[1]), int(toks[2])
    V = np.array(toks[4:4 + 3 * nv], dtype=float).reshape(nv, 3)
    rest, F, i = toks[4 + 3 * nv:], [], 0
    for _ in range(nf):
        k = int(rest[i])
        F.append([int(x) for x in rest[i + 1:i + 1 + k]])
        i += 1 + k
    return V, np.array(F)


def read_obj(path):
    V, F = [], []
    with open(path) as f:
        for line in f:
            s = line.split()
            if s and s[0] == 'v':
                V.append([float(x) for x in s[1:4]])
            elif s and s[0] == 'f':
                F.append([int(x.split('/')[0]) - 1 for x in s[1:4]])
    return np.array(V), np.array(F)


def read_ply(path):
    with open(path, 'rb') as f:
        nv = nf = 0
        props, binary = 0, False
        while True:
            line = f.readline().decode('ascii', 'replace').strip()
            if line.startswith('format'):
                binary = 'binary_little_endian' in line
            elif line.startswith('element vertex'):
                nv, section = int(line.split()[2]), 'vertex'
            elif line.startswith('element face'):
                nf, section = int(line.split()[2]), 'face'
            elif line.startswith('property') and section == 'vertex':
                props += 1
            elif line == 'end_header':
                break
        data = f.read()
    if binary:  # vitri's layout: doubles per vertex, then uchar 3 + 3 int32 per face
        V = np.frombuffer(data, '<f8', nv * props).reshape(nv, props)[:, :3]
        face = np.dtype([('n', 'u1'), ('i', '<i4', 3)])
        F = np.frombuffer(data, face, nf, nv * props * 8)['i'].astype(np.int64)
        return V.copy(), F
    lines = data.split(b'\n')
    V = np.array(b' '.join(lines[:nv]).split(), dtype=float).reshape(nv, -1)[:, :3]
    F = np.array(b' '.join(lines[nv:nv + nf]).split(), dtype=np.int64).reshape(nf, 4)[:, 1:]
    return V, F


def read_mesh(path):
    if path.endswith('.off'):
        return read_off(path)
    return read_ply(path) if path.endswith('.ply') else read_obj(path)


def lower_star_chi(V, F, height, levels):
    """Euler characteristic of the sublevel complexes {height <= h} for each h of `levels`."""
    E = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
    hv = np.sort(height)
    he = np.sort(np.maximum(height[E[:, 0]], height[E[:, 1]]))
    ht = np.sort(height[F].max(1))
    count = lambda h: np.searchsorted(h, levels, 'right')  # noqa: E731
    return count(hv) - count(he) + count(ht)


def diagonal(V):
    return float(np.linalg.norm(V.max(0) - V.min(0)))


def vertex_normals(V, F):
    """Area-weighted, outwards (as closed_mesh_vertex_normals), unit length."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    n = np.cross(b - a, c - a)
    N = np.zeros_like(V)
    for k in range(3):
        np.add.at(N, F[:, k], n)
    if np.einsum('ij,ij->i', a, np.cross(b, c)).sum() < 0:
        N = -N
    return N / np.linalg.norm(N, axis=1)[:, None]


def surface_samples(V, F, n, seed=0):
    rng = np.random.default_rng(seed)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    cr = np.cross(b - a, c - a)
    area = np.linalg.norm(cr, axis=1)
    idx = rng.choice(len(F), n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    P = a[idx] + u[:, None] * (b[idx] - a[idx]) + v[:, None] * (c[idx] - a[idx])
    return P, cr[idx] / area[idx][:, None]


def euler(F):
    if len(F) == 0:
        return 0
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    return len(np.unique(F)) - len(np.unique(E, axis=0)) + len(F)


def groups(nv, F, selected):
    """Labels of the groups of selected vertices joined by mesh edges between selected vertices."""
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    keep = selected[E[:, 0]] & selected[E[:, 1]]
    A = coo_matrix((np.ones(keep.sum()), (E[keep, 0], E[keep, 1])), shape=(nv, nv))
    return connected_components(A, directed=False)[1]


def print_groups(V, F, selected, describe, limit=15):
    lab = groups(len(V), F, selected)
    labels, counts = np.unique(lab[selected], return_counts=True)
    for label, count in sorted(zip(labels, counts), key=lambda t: -t[1])[:limit]:
        sel = lab == label
        print(f'  {count} vertices around {V[sel].mean(0).round(3)} {describe(sel)}')


def winding(V, F, Q, chunk=64):
    """Generalized winding numbers of the points Q (solid angles of every triangle; O(|Q| |F|))."""
    a0, b0, c0 = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    out = np.empty(len(Q))
    for s in range(0, len(Q), chunk):
        q = Q[s:s + chunk, None, :]
        a, b, c = a0[None] - q, b0[None] - q, c0[None] - q
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        dot = lambda x, y: np.einsum('qfi,qfi->qf', x, y)  # noqa: E731
        det = dot(a, np.cross(b, c))
        den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb
        out[s:s + chunk] = np.arctan2(det, den).sum(1) / (2 * np.pi)
    return out


def cmd_selfint(model):
    V, F = read_off(model)
    N, eps = vertex_normals(V, F), 1e-4 * diagonal(V)
    outside, inside = winding(V, F, V + eps * N), winding(V, F, V - eps * N)
    buried = (np.abs(outside) > 0.5) | (np.abs(inside - 1) > 0.5)
    print(f'{model}: {buried.sum()} of {len(V)} vertices inside another part of the model')
    print_groups(V, F, buried, lambda sel: '')


def cmd_constraints(model, offset=0.01):
    """The builder's rule (rbf/src/constraints.cpp): d halved while a vertex lies within 0.999 d."""
    V, F = read_off(model)
    N, d0 = vertex_normals(V, F), offset * diagonal(V)
    S, SN = surface_samples(V, F, 3000000)
    samples, vertices = cKDTree(S), cKDTree(V)
    for side in (+1, -1):
        d = np.full(len(V), d0)
        Q = V + side * d[:, None] * N
        ok = np.zeros(len(V), bool)
        for _ in range(5):
            ok |= vertices.query_ball_point(Q, 0.999 * d, return_length=True) == 0
            d[~ok] *= 0.5
            Q[~ok] = V[~ok] + side * d[~ok][:, None] * N[~ok]
        dist, j = samples.query(Q[ok])
        wrong = np.sign(np.einsum('ij,ij->i', Q[ok] - S[j], SN[j])) != side
        near = dist < 0.5 * d[ok]
        print(f'{"outside" if side > 0 else "inside"}: kept {ok.sum()}, dropped {(~ok).sum()}, halved '
              f'{(d[ok] < d0).sum()}; on the wrong side of the model {wrong.sum()}; nearer than d / 2 to '
              f'its surface {near.sum()}')


def cmd_compare(model, mesh, threshold=0.01):
    V, F = read_off(model)
    MV, MF = read_mesh(mesh)
    diag = diagonal(V)
    print(f'{mesh}: {len(MV)} vertices, Euler characteristic {euler(MF)} (model {euler(F)})')
    lab = groups(len(MV), MF, np.ones(len(MV), bool))
    for label in np.unique(lab):
        sel = lab == label
        print(f'  component: {sel.sum()} vertices, chi {euler(MF[sel[MF[:, 0]]])}, centre {MV[sel].mean(0).round(3)}')
    S, SN = surface_samples(V, F, 2000000)
    dist, j = cKDTree(S).query(MV)
    side = np.einsum('ij,ij->i', MV - S[j], SN[j])
    far = dist > threshold * diag
    print(f'distance to the model / diagonal: mean {dist.mean() / diag:.2e}, max {dist.max() / diag:.2e}; '
          f'{far.sum()} vertices beyond {threshold}')
    print_groups(MV, MF, far, lambda sel: f'max {dist[sel].max() / diag:.3f}, '
                 f'{"outside" if side[sel].mean() > 0 else "inside"}')


def ball_euler(V, F, tree, centre, r):
    inside = np.zeros(len(V), bool)
    inside[tree.query_ball_point(centre, r)] = True
    return euler(F[inside[F].all(1)])


def cmd_localchi(model, mesh, radius=0.015):
    V, F = read_off(model)
    MV, MF = read_mesh(mesh)
    r = radius * diagonal(V)
    S, _ = surface_samples(V, F, 200000, seed=3)
    samples, covered, centres = cKDTree(S), np.zeros(len(S), bool), []
    for i in np.random.default_rng(0).permutation(len(S)):
        if not covered[i]:
            centres.append(S[i])
            covered[samples.query_ball_point(S[i], r / 2)] = True
    tv, tm = cKDTree(V), cKDTree(MV)
    bad = [(c, ball_euler(V, F, tv, c, r), ball_euler(MV, MF, tm, c, r)) for c in centres]
    bad = [b for b in bad if b[1] != b[2]]
    print(f'{len(centres)} balls of radius {radius}: {len(bad)} differ (model chi, mesh chi)')
    if len(bad) < 2:
        return
    P = np.array([b[0] for b in bad])
    lab = fcluster(linkage(P, 'single'), 2 * r, 'distance')
    for label in np.unique(lab):
        sel = np.nonzero(lab == label)[0]
        print(f'  site {P[sel].mean(0).round(3)}: {len(sel)} balls, e.g. {[bad[k][1:] for k in sel[:4]]}')


def cmd_sweep(ref, mesh, n=2000):
    RV, RF = read_mesh(ref)
    MV, MF = read_mesh(mesh)
    top = np.array([np.inf])
    print(f'chi: {ref} {lower_star_chi(RV, RF, RV[:, 0], top)[0]}, {mesh} {lower_star_chi(MV, MF, MV[:, 0], top)[0]}')
    lo, hi = np.minimum(RV.min(0), MV.min(0)), np.maximum(RV.max(0), MV.max(0))
    for axis in range(3):
        h = np.linspace(lo[axis], hi[axis], int(n))
        d = lower_star_chi(MV, MF, MV[:, axis], h) - lower_star_chi(RV, RF, RV[:, axis], h)
        # Lasting changes: the difference at the end of each run of equal values longer than 1% of n.
        runs, start = [], 0
        for i in range(1, len(h) + 1):
            if i == len(h) or d[i] != d[start]:
                if i - start >= max(2, len(h) // 100) and (not runs or runs[-1][1] != d[start]):
                    runs.append((h[start], d[start]))
                start = i
        steps = [f'{d0:+d} from {h0:.4f}' for (h0, d0) in runs]
        print(f'axis {"xyz"[axis]}: ' + ', '.join(steps))


def cmd_ballchi(ref, mesh, x, y, z):
    RV, RF = read_mesh(ref)
    MV, MF = read_mesh(mesh)
    c = np.array([float(x), float(y), float(z)])
    radii = np.array([1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2]) * diagonal(RV)
    for name, (V, F) in ((ref, (RV, RF)), (mesh, (MV, MF))):
        chi = lower_star_chi(V, F, np.linalg.norm(V - c, axis=1), radii)
        print(f'{name}: ' + ', '.join(f'r {r:.2e}: {k}' for r, k in zip(radii, chi)))


if __name__ == '__main__':
    commands = {'selfint': cmd_selfint, 'constraints': cmd_constraints, 'compare': cmd_compare,
                'localchi': cmd_localchi, 'sweep': cmd_sweep, 'ballchi': cmd_ballchi}
    if len(sys.argv) < 3 or sys.argv[1] not in commands:
        sys.exit(__doc__)
    args = [float(a) if a.replace('.', '', 1).isdigit() else a for a in sys.argv[2:]]
    commands[sys.argv[1]](*args)
