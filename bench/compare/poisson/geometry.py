"""Meshes and point sets for the Poisson comparison (bench/compare/poisson/compare.py): an OFF reader,
area-uniform surface sampling with the true face normals, a binary PLY writer for oriented points (the
format `vitri mesh` and Open3D both read), and the measures of an output mesh: topology (boundary and
non-manifold edges, connected components, Euler characteristic) and the two-sided distance to the true
model, relative to the model's bounding-box diagonal.

numpy only, except the exact point-to-triangle distances, which use Open3D's RaycastingScene (imported
where it is needed, so the sampling works without Open3D)."""
import numpy as np


def read_off(path):
    """(V, F) of an OFF / COFF / NOFF file: V float64 (n, 3), F int64 (m, 3). Comments after '#' and the
    counts on the header line are accepted; polygons with more than three corners are refused."""
    tokens = []
    with open(path) as f:
        for line in f:
            tokens.extend(line.split("#", 1)[0].split())
    if not tokens or not tokens[0].endswith("OFF"):
        raise ValueError(f"{path}: not an OFF file (first token {tokens[:1]})")
    per_vertex = 3 + (3 if "N" in tokens[0] else 0) + (4 if "C" in tokens[0] else 0)
    nv, nf = int(tokens[1]), int(tokens[2])
    at = 4
    V = np.array(tokens[at:at + per_vertex * nv], dtype=np.float64).reshape(nv, per_vertex)[:, :3]
    at += per_vertex * nv
    F = np.empty((nf, 3), dtype=np.int64)
    for i in range(nf):
        k = int(tokens[at])
        if k != 3:
            raise ValueError(f"{path}: face {i} has {k} corners; only triangles are handled")
        F[i] = [int(t) for t in tokens[at + 1:at + 4]]
        at += 1 + k
    return V, F


def diagonal(V):
    """Length of the bounding-box diagonal of the points V."""
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def face_cross(V, F):
    """Per-face cross product (B - A) x (C - A): twice the area, along the counter-clockwise normal."""
    A = V[F[:, 0]]
    return np.cross(V[F[:, 1]] - A, V[F[:, 2]] - A)


def signed_volume(V, F):
    """Signed volume enclosed by a closed mesh: > 0 when it is wound counter-clockwise seen from outside."""
    return float(np.einsum("ij,ij->i", V[F[:, 0]], face_cross(V, F)).sum() / 6.0)


def sample_surface(V, F, n, seed):
    """n points drawn uniformly by area on the triangles (V, F) with a fixed seed, and the unit normal of
    the triangle each lies on. Returns (points, normals), float64 (n, 3) each."""
    rng = np.random.default_rng(seed)
    cross = face_cross(V, F)
    twice_area = np.linalg.norm(cross, axis=1)
    keep = twice_area > 0
    faces = np.flatnonzero(keep)
    cdf = np.cumsum(twice_area[keep])
    picked = faces[np.minimum(np.searchsorted(cdf, rng.random(n) * cdf[-1], side="right"), len(faces) - 1)]
    root = np.sqrt(rng.random(n))
    r2 = rng.random(n)
    a, b, c = 1.0 - root, root * (1.0 - r2), root * r2  # uniform barycentric coordinates
    tri = F[picked]
    points = a[:, None] * V[tri[:, 0]] + b[:, None] * V[tri[:, 1]] + c[:, None] * V[tri[:, 2]]
    normals = cross[picked] / twice_area[picked][:, None]
    return points, normals


def write_oriented_ply(path, points, normals):
    """Binary little-endian PLY, one vertex element with double x y z nx ny nz and no faces."""
    header = ("ply\nformat binary_little_endian 1.0\ncomment vitri bench/compare/poisson sample\n"
              f"element vertex {len(points)}\n"
              + "".join(f"property double {p}\n" for p in ("x", "y", "z", "nx", "ny", "nz"))
              + "end_header\n")
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.hstack([points, normals]).astype("<f8").tobytes())


def topology(V, F, diag):
    """Topological measures of the triangle mesh (V, F): vertices used by a face, triangles, boundary
    edges (on one triangle), non-manifold edges (on three or more), connected components (sharing a
    vertex), Euler characteristic V - E + F of the used vertices, triangles with an area below
    1e-14 diag^2, and the signed volume over diag^3 (> 0: outward winding overall)."""
    used = np.unique(F)
    nv = int(V.shape[0])
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    e.sort(axis=1)
    _, per_edge = np.unique(e[:, 0] * nv + e[:, 1], return_counts=True)
    area = 0.5 * np.linalg.norm(face_cross(V, F), axis=1)
    return {
        "vertices": int(len(used)),
        "triangles": int(len(F)),
        "boundary_edges": int((per_edge == 1).sum()),
        "nonmanifold_edges": int((per_edge > 2).sum()),
        "components": components(nv, e, used),
        "euler": int(len(used) - len(per_edge) + len(F)),
        "tiny_triangles": int((area < 1e-14 * diag * diag).sum()),
        "volume": signed_volume(V, F) / diag ** 3,
    }


def components(nv, edges, used):
    """Connected components of the graph (nv vertices, edges (k, 2)) among the vertices in used."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    graph = coo_matrix((np.ones(len(edges), dtype=np.int8), (edges[:, 0], edges[:, 1])), shape=(nv, nv))
    _, label = connected_components(graph, directed=False)
    return int(len(np.unique(label[used])))


class Normalized:
    """The model's frame for distances: coordinates shifted to the model's box centre and divided by its
    diagonal, so that distances come out relative to the diagonal and float32 (Open3D's scene) keeps
    about 1e-7 of it."""

    def __init__(self, model_V):
        self.centre = 0.5 * (model_V.min(axis=0) + model_V.max(axis=0))
        self.diag = diagonal(model_V)

    def __call__(self, P):
        return ((P - self.centre) / self.diag).astype(np.float32)


def distance_to_mesh(frame, V, F, queries):
    """Exact distances (relative to frame's diagonal) from the query points to the triangles (V, F).
    Triangles that are degenerate in float32 (zero cross product: a segment or a point) are left out:
    Debian's Open3D aborts on an Eigen assertion when its closest-point query meets one (Poisson's outputs
    have a few), and in a closed mesh the segment is covered by the edges of the neighbouring triangles."""
    import open3d as o3d
    W = frame(V)
    flat = ~np.any(np.cross(W[F[:, 1]] - W[F[:, 0]], W[F[:, 2]] - W[F[:, 0]]), axis=1)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(W), o3d.core.Tensor(F[~flat].astype(np.uint32)))
    return scene.compute_distance(o3d.core.Tensor(frame(queries))).numpy().astype(np.float64)


def two_sided_distance(frame, model, reference, output, samples, seed):
    """Distances between an output mesh and the true model, relative to the model's diagonal.
    output -> model: `samples` points sampled on the output, exact distance to the model's triangles;
    model -> output: the dense reference samples of the model, exact distance to the output's
    triangles. Returns mean, 99th percentile and max of each side."""
    out_points, _ = sample_surface(output[0], output[1], samples, seed)
    to_model = distance_to_mesh(frame, model[0], model[1], out_points)
    to_output = distance_to_mesh(frame, output[0], output[1], reference)
    result = {}
    for side, d in (("out_to_model", to_model), ("model_to_out", to_output)):
        result[f"{side}_mean"] = float(d.mean())
        result[f"{side}_p99"] = float(np.percentile(d, 99))
        result[f"{side}_max"] = float(d.max())
    return result


def read_mesh(path):
    """(V, F) of a triangle mesh file (PLY, OFF, OBJ) read by Open3D, without any post-processing that
    would merge or remove vertices."""
    import open3d as o3d
    mesh = o3d.io.read_triangle_mesh(str(path), enable_post_processing=False, print_progress=False)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.triangles, dtype=np.int64)


def read_closed_model(path):
    """(V, F) of a closed OFF model, its triangles turned outward (positive signed volume) if needed."""
    V, F = read_off(path)
    return (V, F[:, [0, 2, 1]]) if signed_volume(V, F) < 0 else (V, F)
