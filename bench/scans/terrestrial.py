#!/usr/bin/python3
"""A simulated terrestrial laser scan (one station), vitri with and without its viewpoint, Open3D's Poisson.

A terrestrial scanner samples a scene on a grid of angles: dense near the station, ever sparser with the
range, and on the ground at grazing angles the points fall on rings metres apart (each ring a line of
points). This scene (seeded, numpy only) has a station 2 m above the ground at the origin, rays every
`--step` degrees (azimuth 0-360, elevation -60 to +10), the first hit of each ray among: the ground z = 0
out to 150 m, a building (the box [10, 20] x [-5, 5] x [0, 8]: its front x = 10 faces the station), a pole
(radius 0.3 m at (5, 5), 6 m high) and a wall x = -30 (|y| < 40, 5 m high); Gaussian range noise of
`--noise` m. It writes tls.xyz and tls.viewpoint (the station), and the same points as tls-nv.xyz without
one.

Per run (`vitri mesh` defaults, with the viewpoint file beside the input and without; Open3D's Poisson,
depth 10, normals from 30 neighbours oriented toward the station, the 5% density trim): time and peak
memory (GNU time), mesh vertices, components, Euler characteristic, boundary loops, the mesh vertices on
the building's front, the far wall and the ground beyond 10 m (against the points there), and the
vertices' distance to the scene's true surfaces (median and 99th percentile, m). Prints a markdown table.

Usage: /usr/bin/python3 bench/scans/terrestrial.py [--vitri build-release/apps/vitri] [--step 0.4]
       [--noise 0.01] [--seed 5] [--work /tmp/vitri-terrestrial] [--no-poisson]
About 30 s per run on 2 cores at the default step (141,548 points).
"""
import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
from noise_topology import topology  # noqa: E402  (same folder)

EYE = np.array([0.0, 0.0, 2.0])


def scene(step, noise, seed):
    """The scan's points (n x 3)."""
    rng = np.random.default_rng(seed)
    az = np.deg2rad(np.arange(0, 360, step))
    el = np.deg2rad(np.arange(-60, 10, step))
    a, e = np.meshgrid(az, el)
    d = np.stack([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)], -1).reshape(-1, 3)
    best = np.full(len(d), np.inf)

    def hit(t, ok):
        ok = ok & (t > 0) & (t < best)
        best[ok] = t[ok]

    with np.errstate(divide="ignore", invalid="ignore"):
        t = -EYE[2] / d[:, 2]
        p = EYE + t[:, None] * d
        hit(t, np.hypot(p[:, 0], p[:, 1]) < 150)
        # The building's faces: (axis, value, the two other axes, their ranges).
        for ax, val, (u, w), ((u0, u1), (w0, w1)) in [
                (0, 10, (1, 2), ((-5, 5), (0, 8))), (0, 20, (1, 2), ((-5, 5), (0, 8))),
                (1, -5, (0, 2), ((10, 20), (0, 8))), (1, 5, (0, 2), ((10, 20), (0, 8))),
                (2, 8, (0, 1), ((10, 20), (-5, 5)))]:
            t = (val - EYE[ax]) / d[:, ax]
            p = EYE + t[:, None] * d
            hit(t, (p[:, u] >= u0) & (p[:, u] <= u1) & (p[:, w] >= w0) & (p[:, w] <= w1))
        t = (-30 - EYE[0]) / d[:, 0]
        p = EYE + t[:, None] * d
        hit(t, (np.abs(p[:, 1]) < 40) & (p[:, 2] > 0) & (p[:, 2] < 5))
        o = EYE[:2] - np.array([5.0, 5.0])
        dd = d[:, :2]
        qa, qb, qc = (dd ** 2).sum(1), 2 * (dd @ o), (o ** 2).sum() - 0.09
        disc = qb * qb - 4 * qa * qc
        t = (-qb - np.sqrt(np.maximum(disc, 0))) / (2 * qa)
        p = EYE + t[:, None] * d
        hit(t, (disc > 0) & (p[:, 2] > 0) & (p[:, 2] < 6))
    ok = np.isfinite(best)
    r = best[ok] + rng.normal(0, noise, ok.sum())
    return EYE + r[:, None] * d[ok]


def truth_distance(v):
    """Distance of each point to the nearest true surface of the scene."""
    ground = np.abs(v[:, 2])
    lo, hi = np.array([10, -5, 0]), np.array([20, 5, 8])
    out = np.maximum(np.maximum(lo - v, v - hi), 0)
    inside = np.minimum(v - lo, hi - v).min(1)
    box = np.where((out == 0).all(1), inside, np.linalg.norm(out, axis=1))
    wall = np.hypot(v[:, 0] + 30, np.maximum(np.abs(v[:, 1]) - 40, 0) + np.maximum(v[:, 2] - 5, 0))
    rad = np.hypot(v[:, 0] - 5, v[:, 1] - 5)
    pole = np.hypot(np.abs(rad - 0.3), np.maximum(v[:, 2] - 6, 0))
    return np.minimum.reduce([ground, box, wall, pole])


def regions(v):
    r = np.hypot(v[:, 0], v[:, 1])
    front = (v[:, 0] > 9.5) & (v[:, 0] < 10.5) & (np.abs(v[:, 1]) < 5.5) & (v[:, 2] > 0.3)
    wall = (v[:, 0] < -29) & (v[:, 0] > -31) & (v[:, 2] > 0.3)
    far_ground = (np.abs(v[:, 2]) < 0.3) & (r >= 10)
    return int(front.sum()), int(wall.sum()), int(far_ground.sum())


def read_mesh(path):
    import open3d as o3d
    m = o3d.io.read_triangle_mesh(str(path))
    return np.asarray(m.vertices), np.asarray(m.triangles)


def timed(cmd, log):
    with open(log, "w") as out:
        res = subprocess.run(["/usr/bin/time", "-f", "TIME %e %M"] + cmd, stdout=out, stderr=subprocess.STDOUT)
    last = [l for l in Path(log).read_text().splitlines() if l.startswith("TIME ")]
    s, kb = last[-1].split()[1:] if last else ("nan", "0")
    return res.returncode, float(s), int(kb) / 1024


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vitri", default=str(ROOT / "build-release" / "apps" / "vitri"))
    ap.add_argument("--step", type=float, default=0.4, help="angular step of the scanner, degrees")
    ap.add_argument("--noise", type=float, default=0.01, help="range noise, m")
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--work", default="/tmp/vitri-terrestrial")
    ap.add_argument("--no-poisson", action="store_true")
    a = ap.parse_args()
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    p = scene(a.step, a.noise, a.seed)
    np.savetxt(work / "tls.xyz", p, fmt="%.4f")
    np.savetxt(work / "tls-nv.xyz", p, fmt="%.4f")
    (work / "tls.viewpoint").write_text("%g %g %g\n" % tuple(EYE))
    pts = regions(p)
    runs = [("vitri (viewpoint)", [a.vitri, "mesh", str(work / "tls.xyz"), "-o", str(work / "vitri-vp.ply")],
             work / "vitri-vp.ply"),
            ("vitri (no viewpoint)", [a.vitri, "mesh", str(work / "tls-nv.xyz"), "-o", str(work / "vitri-nv.ply")],
             work / "vitri-nv.ply")]
    if not a.no_poisson:
        runs.append(("Open3D Poisson d10", ["/usr/bin/python3", str(HERE / "open3d_poisson.py"), str(work / "tls.xyz"),
                                            str(work / "poisson.ply"), "--depth", "10", "--viewpoint",
                                            str(work / "tls.viewpoint")], work / "poisson.ply"))
    print(f"{len(p)} points (step {a.step} degrees, noise {a.noise} m, seed {a.seed}); building front / far wall /"
          f" ground beyond 10 m: {pts[0]} / {pts[1]} / {pts[2]} points\n")
    print("| method | status | s | peak MB | vertices | comp. | chi | loops | front / wall / far ground vertices |"
          " truth dist. med / p99 (m) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---|---|")
    for name, cmd, out in runs:
        rc, s, mb = timed(cmd, str(out) + ".log")
        if rc != 0 or not out.exists():
            print(f"| {name} | exit {rc} | {s:.1f} | {mb:.0f} | - | - | - | - | - | - |")
            continue
        v, f = read_mesh(out)
        chi, comps, loops = topology(f)
        r = regions(v)
        dist = truth_distance(v)
        print(f"| {name} | ok | {s:.1f} | {mb:.0f} | {len(v)} | {comps} | {chi} | {loops} | {r[0]} / {r[1]} / {r[2]} |"
              f" {np.median(dist):.4f} / {np.percentile(dist, 99):.3f} |")


if __name__ == "__main__":
    main()
