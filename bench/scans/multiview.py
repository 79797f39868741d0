#!/usr/bin/python3
"""Simulated multi-view range scans of the shared models, vitri against Open3D's Poisson.

Issue 38's first case is a multi-view laser scan of a small object: range images from several stations,
merged with small registration errors, with range noise that grows at grazing angles, flying pixels at
depth jumps and scanner normals. This script makes such scans of the shared models, whose truth is known,
and runs `vitri mesh` (defaults; with the scanner normals, and without them) and Open3D's Poisson (the
scanner normals, depth 9 and 10, trimmed at 5% density as in run_scans.py) on each.

A scan (seeded, numpy + Open3D only): the model scaled to a unit diagonal and centred; `--views` stations
at distance 2 around it (azimuths evenly spread and jittered, elevations -0.5, 0 or 0.5 rad and jittered),
each a `--res` x `--res` pinhole image whose field of view holds the model (0.55 wide at distance 2). A
pixel sees the nearest of 3 x 10^6 area-uniform samples of the model that project into it (a z-buffer;
Open3D's ray casting answers no hit in this Debian build), kept when front-facing with |cos| > 0.1;
its range gets Gaussian noise of `--noise` pixel footprints (the footprint at distance 2) divided by the
cosine of the incidence (capped at 5x); at a depth jump of more than 0.05 to the next pixel right or
below, a flying pixel (probability 0.3) lies on its ray between the two ranges; each station is then
moved by a small rigid motion (a rotation of `--misreg` footprints of arc at radius 0.5 about a random
axis through the centre, and a translation of `--misreg` footprints); the scanner normals are Open3D's
16-neighbour PCA normals of the station's own points, oriented toward its (moved) camera. The merged
cloud is shuffled and written as CASE.xyz (6 columns) and CASE-u.xyz (3 columns), the normalized model
as CASE-truth.off.

Per run: time and peak memory (GNU time), mesh vertices, components, Euler characteristic (truth: the
model's), closed or boundary loops, and the two-sided distance to the truth (vitri_scan_metrics: mean and
99th percentile, in 10^-3 of the diagonal). Prints a markdown table.

Usage: /usr/bin/python3 bench/scans/multiview.py [--vitri build-release/apps/vitri]
       [--metrics build-scans/bench/scans/vitri_scan_metrics] [--models bunny,elephant,hand,bear,knot1]
       [--seeds 1] [--views 8] [--res 400] [--noise 0.3] [--misreg 0.5] [--work /tmp/vitri-multiview]
(build the metrics tool with bench/scans/run_scans.sh, or `cmake --build build-scans --target
vitri_scan_metrics`.) About a minute per model and seed on 2 cores, most of it Poisson's.
"""
import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
SHARED = Path(os.environ.get("VITRI_SHARED_DATA", ROOT.parent / "shared" / "data"))
sys.path.insert(0, str(HERE))
from noise_topology import read_off, topology  # noqa: E402  (same folder)


def simulate(model_off, base, views, res, noise, misreg, seed):
    """Writes base.xyz, base-u.xyz, base-truth.off; returns (points, pixel footprint)."""
    import open3d as o3d
    rng = np.random.default_rng(seed)
    v, f = read_off(model_off)
    lo, hi = v.min(0), v.max(0)
    v = (v - 0.5 * (lo + hi)) / np.linalg.norm(hi - lo)
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f))
    o3d.io.write_triangle_mesh(f"{base}-truth.off", mesh)
    mesh.compute_triangle_normals()  # (after the OFF, which cannot hold them)
    o3d.utility.random.seed(seed)  # Open3D's own generator draws the dense sample: seeded too
    dense = mesh.sample_points_uniformly(number_of_points=3_000_000, use_triangle_normal=True)
    S, SN = np.asarray(dense.points), np.asarray(dense.normals)
    half = 0.55 / 2.0  # tan of half the field of view: 1.1 wide at distance 2, where the unit model fits
    footprint = 2.0 * 2.0 * half / res
    pts, nrm = [], []
    for view in range(views):
        az = 2 * np.pi * view / views + rng.uniform(-0.2, 0.2)
        el = rng.choice([-0.5, 0.0, 0.5]) + rng.uniform(-0.2, 0.2)
        cam = 2.0 * np.array([np.cos(el) * np.sin(az), np.sin(el), np.cos(el) * np.cos(az)])
        fwd = -cam / np.linalg.norm(cam)
        right = np.cross(fwd, [0.0, 1.0, 0.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, fwd)
        rel = S - cam
        z = rel @ fwd
        ix = np.floor(((rel @ right) / z / half + 1) / 2 * res).astype(np.int64)
        iy = np.floor(((rel @ up) / z / half + 1) / 2 * res).astype(np.int64)
        dist = np.linalg.norm(rel, axis=1)
        inside = (ix >= 0) & (ix < res) & (iy >= 0) & (iy < res)
        pixel = np.where(inside, iy * res + ix, -1)
        order = np.lexsort((dist, pixel))
        order = order[inside[order]]
        first = np.ones(len(order), bool)
        first[1:] = pixel[order][1:] != pixel[order][:-1]
        sel = order[first]  # the nearest sample of each pixel
        ray = rel[sel] / dist[sel][:, None]
        cosine = -np.sum(SN[sel] * ray, axis=1)
        keep = cosine > 0.1
        sel, ray, cosine = sel[keep], ray[keep], cosine[keep]
        depth = np.full(res * res, np.inf)
        depth[pixel[sel]] = dist[sel]
        sigma = noise * footprint * np.minimum(1.0 / cosine, 5.0)
        p = [cam + ray * (dist[sel] + rng.normal(size=len(sel)) * sigma)[:, None]]
        D = depth.reshape(res, res)
        for axis in (0, 1):
            D2 = np.roll(D, -1, axis=axis)
            with np.errstate(invalid="ignore"):
                jump = np.isfinite(D) & np.isfinite(D2) & (np.abs(D2 - D) > 0.05) & (rng.random(D.shape) < 0.3)
            jy, jx = np.nonzero(jump)
            w = rng.random(len(jy))
            r = D[jy, jx] * w + D2[jy, jx] * (1 - w)
            d = fwd[None] + half * (((jx + 0.5) / res * 2 - 1)[:, None] * right +
                                    ((jy + 0.5) / res * 2 - 1)[:, None] * up)
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            p.append(cam + d * r[:, None])
        p = np.concatenate(p)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = misreg * footprint / 0.5
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        R = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
        shift = rng.normal(size=3)
        shift *= misreg * footprint / np.linalg.norm(shift)
        p = np.ascontiguousarray(p @ R.T + shift)
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(p))
        cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(16))
        cloud.orient_normals_towards_camera_location(cam @ R.T + shift)
        pts.append(p)
        nrm.append(np.asarray(cloud.normals))
    P, N = np.concatenate(pts), np.concatenate(nrm)
    perm = rng.permutation(len(P))
    P, N = P[perm], N[perm]
    np.savetxt(f"{base}.xyz", np.hstack([P, N]), fmt="%.7g")
    np.savetxt(f"{base}-u.xyz", P, fmt="%.7g")
    return len(P), footprint


def timed(cmd, log):
    t = subprocess.run(["/usr/bin/time", "-f", "TIME %e %M"] + cmd, capture_output=True, text=True)
    Path(log).write_text(t.stdout + t.stderr)
    last = [l for l in t.stderr.splitlines() if l.startswith("TIME ")]
    if t.returncode != 0 or not last:
        return None
    s, kb = last[-1].split()[1:]
    return float(s), float(kb) / 1024.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vitri", default=str(ROOT / "build-release" / "apps" / "vitri"))
    ap.add_argument("--metrics", default=str(ROOT / "build-scans" / "bench" / "scans" / "vitri_scan_metrics"))
    ap.add_argument("--models", default="bunny,elephant,hand,bear,knot1")
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--views", type=int, default=8)
    ap.add_argument("--res", type=int, default=400)
    ap.add_argument("--noise", type=float, default=0.3, help="range noise, pixel footprints at normal incidence")
    ap.add_argument("--misreg", type=float, default=0.5, help="registration error per station, footprints")
    ap.add_argument("--depths", default="9,10", help="Open3D Poisson depths")
    ap.add_argument("--work", default="/tmp/vitri-multiview")
    a = ap.parse_args()
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    print("| case | points | method | s | peak MB | vertices | comp. | chi (truth) | closed | "
          "->truth mean / p99 | truth-> mean / p99 |")
    print("|---|---:|---|---:|---:|---:|---:|---|---|---:|---:|")
    for model in [m for m in a.models.split(",") if m]:
        truth_chi = topology(read_off(SHARED / f"{model}.off")[1])[0]
        for seed in range(1, a.seeds + 1):
            base = work / f"{model}-s{seed}"
            n, _ = simulate(SHARED / f"{model}.off", base, a.views, a.res, a.noise, a.misreg, seed)
            runs = [("vitri (scanner normals)", [a.vitri, "mesh", f"{base}.xyz", "-o", f"{base}-vn.ply"], "vn"),
                    ("vitri (no normals)", [a.vitri, "mesh", f"{base}-u.xyz", "-o", f"{base}-vu.ply"], "vu")]
            for d in [x for x in a.depths.split(",") if x]:
                runs.append((f"Open3D Poisson d{d}", ["/usr/bin/python3", str(HERE / "open3d_poisson.py"),
                                                      f"{base}.xyz", f"{base}-o{d}.ply", "--depth", d], f"o{d}"))
            for label, cmd, tag in runs:
                r = timed(cmd, f"{base}-{tag}.log")
                if r is None:
                    print(f"| {base.name} | {n} | {label} | failed: see {base}-{tag}.log | | | | | | | |")
                    continue
                out = f"{base}-{tag}.ply"
                m = subprocess.run([a.metrics, out, "--points", f"{base}.xyz", "--truth", f"{base}-truth.off",
                                    "--samples", "100000", "--json"], capture_output=True, text=True)
                j = json.loads(m.stdout)
                to, fr = j["to_truth"], j["from_truth"]
                closed = "yes" if j["closed"] else f"no ({j['boundary_edges']} boundary edges)"
                print(f"| {base.name} | {n} | {label} | {r[0]:.1f} | {r[1]:.0f} | {j['vertices']} | "
                      f"{j['components']} | {j['euler']} ({truth_chi}) | {closed} | "
                      f"{1e3 * to['mean_diag']:.2f} / {1e3 * to['p99_diag']:.2f} | "
                      f"{1e3 * fr['mean_diag']:.2f} / {1e3 * fr['p99_diag']:.2f} |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
