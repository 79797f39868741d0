"""Issue 43's benchmark (docs/blocks.md, docs/benchmarks.md): N oriented points sampled from a shared model,
meshed by `vitri mesh` with its defaults under a memory limit (in blocks when one piece does not fit) and by
Open3D's screened Poisson at a given depth, one after the other on the same machine; the wall time and
the peak resident memory of each (/usr/bin/time -v), and the distance of each mesh to the true model.

Usage:
  /usr/bin/python3 bench/blocks/bench_blocks.py --model ../shared/data/elephant.off --points 1e7 \\
      --vitri build-release/apps/vitri --memory 16G --depth 11 --out /tmp/bench43
  options: --skip-vitri / --skip-poisson (reuse what --out holds), --vitri-args "..." (more vitri flags),
           --seed S, --trim Q (Poisson's density trimming quantile, default 0.05: Open3D's tutorial recipe)

Sampling: area-weighted uniform points on the model's triangles with the face normals (numpy, seeded),
written as a binary PLY of float32 x y z nx ny nz (both tools read it). Distances (Open3D's
RaycastingScene on the true model): from every output vertex to the model (accuracy: mean, p99, max) and
from 10^6 fresh samples of the model to the output mesh (completeness: mean, p99, max); in units of the
model's bounding-box diagonal. Prints a markdown table and writes results.json in --out.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

import numpy as np


def read_off(path):
    with open(path) as f:
        tokens = f.read().split()
    at = 1 if tokens[0].upper() == "OFF" else 0
    nv, nf = int(tokens[at]), int(tokens[at + 1])
    at += 3
    V = np.array(tokens[at:at + 3 * nv], dtype=np.float64).reshape(nv, 3)
    at += 3 * nv
    F = []
    for _ in range(nf):
        k = int(tokens[at])
        F.append([int(x) for x in tokens[at + 1:at + 1 + k]][:3])
        at += 1 + k
    return V, np.array(F, dtype=np.int64)


def sample(V, F, n, seed):
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    cr = np.cross(b - a, c - a)
    area = np.linalg.norm(cr, axis=1)
    rng = np.random.default_rng(seed)
    t = rng.choice(len(F), n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    P = a[t] + u[:, None] * (b[t] - a[t]) + v[:, None] * (c[t] - a[t])
    N = cr[t] / np.maximum(area[t], 1e-300)[:, None]
    return P, N


def write_ply_points(path, P, N):
    a = np.empty(len(P), dtype=[(k, "<f4") for k in ("x", "y", "z", "nx", "ny", "nz")])
    a["x"], a["y"], a["z"] = P.T
    a["nx"], a["ny"], a["nz"] = N.T
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % len(P)).encode())
        for k in ("x", "y", "z", "nx", "ny", "nz"):
            f.write(("property float %s\n" % k).encode())
        f.write(b"end_header\n")
        f.write(a.tobytes())


def timed(cmd, log):
    """Runs cmd under /usr/bin/time -v; returns (wall s, peak GB, rc)."""
    t0 = time.time()
    with open(log, "w") as f:
        rc = subprocess.call(["/usr/bin/time", "-v"] + cmd, stdout=f, stderr=subprocess.STDOUT)
    wall = time.time() - t0
    text = open(log).read()
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    return wall, (int(m.group(1)) / 1e6 if m else float("nan")), rc


POISSON = r'''
import sys, time, json, numpy as np, open3d as o3d
src, out, depth, trim = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
t = {}
t0 = time.time(); pcd = o3d.io.read_point_cloud(src); t["read"] = time.time() - t0
t0 = time.time()
mesh, dens = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=depth)
t["poisson"] = time.time() - t0
t0 = time.time(); d = np.asarray(dens)
mesh.remove_vertices_by_mask(d < np.quantile(d, trim)); t["trim"] = time.time() - t0
t0 = time.time(); o3d.io.write_triangle_mesh(out, mesh); t["write"] = time.time() - t0
print(json.dumps({"stages": t, "points": len(pcd.points), "vertices": len(mesh.vertices),
                  "triangles": len(mesh.triangles)}))
'''


def distances(model_V, model_F, mesh_path, n_samples, seed):
    import open3d as o3d

    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(model_V.astype(np.float32)), o3d.core.Tensor(model_F.astype(np.uint32)))
    m = o3d.io.read_triangle_mesh(mesh_path)
    V = np.asarray(m.vertices)
    F = np.asarray(m.triangles)
    acc = scene.compute_distance(o3d.core.Tensor(V.astype(np.float32))).numpy()
    # The output's scene without its (near-)degenerate triangles: Open3D 0.16's closest-point query trips
    # an Eigen assertion on some of Poisson's slivers (measured: 52 of 516,176 triangles at 10^5 points).
    area = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    diag = float(np.linalg.norm(model_V.max(axis=0) - model_V.min(axis=0)))
    keep = F[area > 1e-12 * diag * diag]
    out = o3d.t.geometry.RaycastingScene()
    out.add_triangles(o3d.core.Tensor(V.astype(np.float32)), o3d.core.Tensor(keep.astype(np.uint32)))
    S, _ = sample(model_V, model_F, n_samples, seed + 1)
    comp = out.compute_distance(o3d.core.Tensor(S.astype(np.float32))).numpy()
    # Topology of the output: boundary and non-manifold edges, Euler characteristic.
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]).astype(np.int64), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    used = len(np.unique(F))
    return {
        "accuracy": {"mean": float(acc.mean()), "p99": float(np.quantile(acc, 0.99)), "max": float(acc.max())},
        "completeness": {"mean": float(comp.mean()), "p99": float(np.quantile(comp, 0.99)),
                         "max": float(comp.max())},
        "vertices": int(len(V)), "triangles": int(len(F)), "boundary_edges": int((counts == 1).sum()),
        "nonmanifold_edges": int((counts > 2).sum()), "euler": int(used - len(counts) + len(F)),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--model", required=True)
    ap.add_argument("--points", type=float, default=1e7)
    ap.add_argument("--vitri", default="build-release/apps/vitri")
    ap.add_argument("--vitri-args", default="")
    ap.add_argument("--memory", default="16G")
    ap.add_argument("--depth", type=int, default=11)
    ap.add_argument("--trim", type=float, default=0.05)
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--out", required=True)
    ap.add_argument("--skip-vitri", action="store_true")
    ap.add_argument("--skip-poisson", action="store_true")
    ap.add_argument("--samples", type=int, default=1000000)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    n = int(a.points)
    V, F = read_off(a.model)
    diag = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    src = os.path.join(a.out, "points-%d.ply" % n)
    if not os.path.exists(src):
        P, N = sample(V, F, n, a.seed)
        write_ply_points(src, P, N)
        del P, N
    results = {"model": a.model, "points": n, "memory": a.memory, "depth": a.depth, "diagonal": diag,
               "machine": "%d cores, %s" % (os.cpu_count(), open("/proc/meminfo").readline().split(":")[1].strip())}
    path = os.path.join(a.out, "results.json")
    if os.path.exists(path):
        old = json.load(open(path))
        results.update({k: v for k, v in old.items() if k in ("vitri", "poisson")})
    if not a.skip_vitri:
        out = os.path.join(a.out, "vitri.ply")
        cmd = [a.vitri, "mesh", src, "-o", out, "--memory", a.memory] + a.vitri_args.split()
        wall, peak, rc = timed(cmd, os.path.join(a.out, "vitri.log"))
        results["vitri"] = {"command": " ".join(cmd), "wall_s": wall, "peak_gb": peak, "rc": rc}
        if rc == 0:
            results["vitri"].update(distances(V, F, out, a.samples, a.seed))
        json.dump(results, open(path, "w"), indent=1)
    if not a.skip_poisson:
        out = os.path.join(a.out, "poisson.ply")
        script = os.path.join(a.out, "poisson_run.py")
        open(script, "w").write(POISSON)
        cmd = [sys.executable, script, src, out, str(a.depth), str(a.trim)]
        wall, peak, rc = timed(cmd, os.path.join(a.out, "poisson.log"))
        results["poisson"] = {"command": " ".join(cmd), "wall_s": wall, "peak_gb": peak, "rc": rc}
        if rc == 0:
            lines = [l for l in open(os.path.join(a.out, "poisson.log")) if l.startswith("{")]
            if lines:
                results["poisson"]["stages"] = json.loads(lines[-1])["stages"]
            results["poisson"].update(distances(V, F, out, a.samples, a.seed))
        json.dump(results, open(path, "w"), indent=1)
    print("| tool | wall s | peak GB | vertices | boundary edges | chi | accuracy mean / p99 / max | "
          "completeness mean / p99 / max (x diagonal) |")
    print("|---|---|---|---|---|---|---|---|")
    for tool in ("vitri", "poisson"):
        r = results.get(tool)
        if not r or "accuracy" not in r:
            continue
        f = lambda d: "%.2e / %.2e / %.2e" % (d["mean"] / diag, d["p99"] / diag, d["max"] / diag)
        print("| %s | %.0f | %.2f | %d | %d | %d | %s | %s |" % (tool, r["wall_s"], r["peak_gb"], r["vertices"],
                                                             r["boundary_edges"], r["euler"], f(r["accuracy"]),
                                                             f(r["completeness"])))


if __name__ == "__main__":
    main()
