#!/usr/bin/env python3
"""Unseen shapes with sharp edges, thin parts and several components, meshed by `vitri mesh` with its
defaults from unoriented samples: the topology (components, Euler characteristic, boundary edges) against
the truth's and the distances both ways.

Shapes (Open3D's primitives and two of our own): a box, a thin plate (1 x 1 x 0.04), a cylinder, a cone
(its rim at 63 degrees), a spike (a cone of half-angle 14 degrees), a torus, two linked tori, three spheres,
a tetrahedron, an octahedron, a wedge (a prism with a 30-degree edge); each sampled uniformly (40,000 points,
Open3D's `sample_points_uniformly`, seeded) without normals, clean (n0) and with Gaussian noise of one
spacing sqrt(area / n) (n1). Then analytic cones (the same cone, area-uniform, numpy) of 5,000 to 30,000
points, five seeds each: the cases where the spanning tree flips the base across the rim.

    /usr/bin/python3 bench/scans/primitives.py --vitri build-release/apps/vitri --out bench/scans/results/primitives
    (about 3 minutes on 2 cores; --work keeps the inputs and meshes, default a temporary folder)

Distances: 50,000 points sampled on each mesh, to the other by Open3D's RaycastingScene, in 10^-3 of the
truth's bounding-box diagonal (mean and 99th percentile): "to truth" measures the mesh's accuracy, "from
truth" its completeness. Numbers vary by about 0.01 between runs (the sampling); the topology does not.
"""
import argparse
import csv
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
import open3d as o3d


def primitives():
    """name -> Open3D triangle mesh (the truth)."""
    shapes = {}
    shapes["box"] = o3d.geometry.TriangleMesh.create_box(1, 1, 1)
    shapes["plate"] = o3d.geometry.TriangleMesh.create_box(1, 1, 0.04)
    shapes["cylinder"] = o3d.geometry.TriangleMesh.create_cylinder(0.3, 1.5, 64, 8)
    shapes["cone"] = o3d.geometry.TriangleMesh.create_cone(0.5, 1.0, 64, 8)
    shapes["spike"] = o3d.geometry.TriangleMesh.create_cone(0.5, 2.0, 64, 8)
    shapes["torus"] = o3d.geometry.TriangleMesh.create_torus(1.0, 0.15, 96, 48)
    t1 = o3d.geometry.TriangleMesh.create_torus(1.0, 0.2, 96, 48)
    t2 = o3d.geometry.TriangleMesh.create_torus(1.0, 0.2, 96, 48)
    t2.rotate(o3d.geometry.get_rotation_matrix_from_xyz((np.pi / 2, 0, 0)), center=(0, 0, 0))
    t2.translate((1.0, 0, 0))
    shapes["links"] = t1 + t2
    spheres = o3d.geometry.TriangleMesh()
    for i in range(3):
        s = o3d.geometry.TriangleMesh.create_sphere(0.3 + 0.1 * i, 40)
        s.translate((1.2 * i, 0, 0))
        spheres += s
    shapes["spheres3"] = spheres
    shapes["tetrahedron"] = o3d.geometry.TriangleMesh.create_tetrahedron(1.0)
    shapes["octahedron"] = o3d.geometry.TriangleMesh.create_octahedron(1.0)
    a = np.radians(30)
    V = np.array([[0, 0, 0], [1, 0, 0], [np.cos(a), np.sin(a), 0],
                  [0, 0, 0.6], [1, 0, 0.6], [np.cos(a), np.sin(a), 0.6]])
    F = np.array([[0, 2, 1], [3, 4, 5], [0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [2, 0, 3], [2, 3, 5]])
    wedge = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(V), o3d.utility.Vector3iVector(F))
    shapes["wedge30"] = wedge.subdivide_midpoint(4)
    return shapes


def cone_points(n, seed):
    """The cone of `primitives()` (base radius 0.5 at z = 0, apex at z = 1), n area-uniform samples."""
    rng = np.random.default_rng(seed)
    r0, h = 0.5, 1.0
    base, side = np.pi * r0 * r0, np.pi * r0 * np.hypot(r0, h)
    t = 2 * np.pi * rng.random(n)
    on_base = rng.random(n) * (base + side) < base
    s = np.sqrt(rng.random(n))
    z = np.where(on_base, 0.0, h * (1 - s))
    return np.c_[r0 * s * np.cos(t), r0 * s * np.sin(t), z]


def topology(mesh):
    F = np.asarray(mesh.triangles)
    if len(F) == 0:
        return None
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    used = len(np.unique(F))
    _, sizes, _ = mesh.cluster_connected_triangles()
    return {"components": len(sizes), "euler": used - len(counts) + len(F),
            "boundary_edges": int((counts == 1).sum()), "nonmanifold_edges": int((counts > 2).sum())}


def distances(a, b, diag, samples=50000):
    """Mean and 99th percentile of the distance from points sampled on a to b, in 10^-3 of diag."""
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(b))
    P = np.asarray(a.sample_points_uniformly(samples).points).astype(np.float32)
    d = scene.compute_distance(o3d.core.Tensor(P)).numpy()
    return 1e3 * d.mean() / diag, 1e3 * np.percentile(d, 99) / diag


def run(vitri, xyz, out):
    t0 = time.time()
    r = subprocess.run([vitri, "mesh", xyz, "-o", out], capture_output=True, text=True)
    return r.returncode, time.time() - t0, r.stderr


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--vitri", default=os.environ.get("VITRI", "build-release/apps/vitri"))
    p.add_argument("--out", required=True, help="writes OUT.md and OUT.csv")
    p.add_argument("--work", default=None)
    p.add_argument("--points", type=int, default=40000)
    p.add_argument("--cones", default="5000,10000,20000,30000", help="analytic cone sizes ('' for none)")
    p.add_argument("--seeds", type=int, default=5)
    args = p.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="vitri-primitives-")
    os.makedirs(work, exist_ok=True)
    rng = np.random.default_rng(5)
    o3d.utility.random.seed(5)
    rows = []
    cases = []
    for name, truth in primitives().items():
        truth.compute_vertex_normals()
        P = np.asarray(truth.sample_points_uniformly(args.points).points)
        spacing = np.sqrt(truth.get_surface_area() / args.points)
        for level in (0, 1):
            Q = P + rng.normal(0, level * spacing, P.shape)
            cases.append((f"{name}-n{level}", truth, Q))
    cone_truth = primitives()["cone"]
    for n in [int(c) for c in args.cones.split(",") if c]:
        for seed in range(args.seeds):
            cases.append((f"cone{n}-seed{seed}", cone_truth, cone_points(n, seed)))
    for case, truth, Q in cases:
        xyz = os.path.join(work, case + ".xyz")
        ply = os.path.join(work, case + ".ply")
        np.savetxt(xyz, Q, fmt="%.9f")
        rc, wall, err = run(args.vitri, xyz, ply)
        row = {"case": case, "points": len(Q), "status": "ok" if rc == 0 else f"exit {rc}", "wall_s": round(wall, 2)}
        tt = topology(truth)
        row["truth_components"], row["truth_euler"] = tt["components"], tt["euler"]
        if rc == 0:
            mesh = o3d.io.read_triangle_mesh(ply)
            t = topology(mesh)
            if t:
                row.update(t)
                V = np.asarray(truth.vertices)
                diag = np.linalg.norm(V.max(0) - V.min(0))
                row["to_truth_mean"], row["to_truth_p99"] = distances(mesh, truth, diag)
                row["from_truth_mean"], row["from_truth_p99"] = distances(truth, mesh, diag)
        row["surface"] = next((l.split(";")[0] for l in err.splitlines() if l.startswith("surface:")), "")
        rows.append(row)
        print(case, {k: (round(v, 2) if isinstance(v, float) else v) for k, v in row.items() if k != "case"}, flush=True)
    keys = ["case", "points", "status", "wall_s", "components", "truth_components", "euler", "truth_euler",
            "boundary_edges", "nonmanifold_edges", "to_truth_mean", "to_truth_p99", "from_truth_mean",
            "from_truth_p99", "surface"]
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    right = sum(1 for r in rows if r.get("euler") == r["truth_euler"] and r.get("components") == r["truth_components"]
                and r.get("boundary_edges") == 0)
    with open(args.out + ".md", "w") as f:
        f.write(f"# Unseen primitives, `vitri mesh` defaults, unoriented samples\n\n`{' '.join(sys.argv)}`\n\n")
        f.write(f"{right} of {len(rows)} closed with the truth's components and Euler characteristic.\n\n")
        f.write("| case | points | components (truth) | Euler (truth) | boundary edges | to truth mean / p99 | "
                "from truth mean / p99 | s |\n|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            fmt = lambda k: f"{r[k]:.2f}" if k in r else "-"
            f.write(f"| {r['case']} | {r['points']} | {r.get('components', '-')} ({r['truth_components']}) | "
                    f"{r.get('euler', '-')} ({r['truth_euler']}) | {r.get('boundary_edges', '-')} | "
                    f"{fmt('to_truth_mean')} / {fmt('to_truth_p99')} | {fmt('from_truth_mean')} / "
                    f"{fmt('from_truth_p99')} | {r['wall_s']} |\n")
        f.write("\nDistances in 10^-3 of the truth's diagonal (50,000 samples each way).\n")
    print(f"{right} of {len(rows)} right; wrote {args.out}.md, {args.out}.csv")


if __name__ == "__main__":
    main()
