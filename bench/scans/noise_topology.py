#!/usr/bin/python3
"""Topology under noise: `vitri mesh IN.xyz -o OUT.obj` with the CLI's defaults on noisy samples whose
truth is known (docs/scans.md, Limits: "Topology under noise").

Cases (generated here, seeded, numpy only):
  sphere-n{1,2}-s{seed}  6000 points on the unit sphere (Fibonacci lattice), isotropic Gaussian noise of
                         1 or 2 spacings of the clean sample; truth: chi 2, 1 component
  MODEL-n{0,1,2}         30,000 area-uniform samples of ../shared/data/MODEL.off, noise 0, 1 or 2 spacings;
                         truth: the model's own chi (from its file). Not a truth for man.off, whose
                         fingers and toes pass through each other (788 self-intersecting triangle
                         pairs), nor quite for pig.off (open, one pair): compare their rows run to run
  MODEL-misreg           the same sample and a second sample of the 20% of largest x, shifted 2 spacings
                         along +x (a misregistered overlap); MODEL-misreg-noisy: both with noise of 0.5
  MODEL-density10        the sample, one point in 10 kept on the half x < median (10x density change)
For each: Euler characteristic chi = V - E + F of the output (vertices used by triangles), components,
boundary loops, the percentage of the output's area farther than 10 median input spacings from every input
point ("away": blobs and sheets where there is no data), seconds. Prints a markdown table. Usage:
  python3 bench/scans/noise_topology.py [--vitri build-release/apps/vitri] [--models bunny] [--seeds 4]
                                        [--model-seed 1]   (the seed of the models' samples and noise)
"""
import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
SHARED = Path(os.environ.get("VITRI_SHARED_DATA", ROOT.parent / "shared" / "data"))


def read_off(path):
    tok = Path(path).read_text().split()
    assert tok[0] == "OFF"
    nv, nf = int(tok[1]), int(tok[2])
    v = np.array(tok[4:4 + 3 * nv], dtype=float).reshape(nv, 3)
    f, at = [], 4 + 3 * nv
    for _ in range(nf):
        k = int(tok[at])
        poly = [int(x) for x in tok[at + 1:at + 1 + k]]
        f.extend([poly[0], poly[i], poly[i + 1]] for i in range(1, k - 1))
        at += 1 + k
    return v, np.array(f, dtype=np.int64)


def read_obj(path):
    v, f = [], []
    for line in Path(path).read_text().splitlines():
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            f.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
    return np.array(v).reshape(-1, 3), np.array(f, dtype=np.int64).reshape(-1, 3)


def count_classes(pairs, items):
    """Connected classes of `items` under the pairs (union-find)."""
    parent = {int(u): int(u) for u in items}

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b in pairs:
        ra, rb = find(int(a)), find(int(b))
        if ra != rb:
            parent[ra] = rb
    return len({find(u) for u in parent})


def topology(f):
    """chi, components, boundary loops of a triangle list (vertices counted where triangles use them)."""
    if len(f) == 0:
        return 0, 0, 0
    used = np.unique(f)
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    chi = len(used) - len(uniq) + len(f)
    border = uniq[count == 1]
    return chi, count_classes(uniq, used), count_classes(border, np.unique(border))


def area_samples(v, f, n, rng):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    tri = rng.choice(len(f), size=n, p=area / area.sum())
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    return (1 - s)[:, None] * a[tri] + (s * (1 - r2))[:, None] * b[tri] + (s * r2)[:, None] * c[tri], area.sum()


def away_fraction(v, f, points, rng, spacings=10.0, n=20000):
    """Fraction of the output's area farther than `spacings` median input spacings from every input point
    (issue 38's measure of blobs and sheets away from the data). Uses Open3D's k-d tree."""
    import open3d as o3d
    points = np.ascontiguousarray(np.unique(points, axis=0), dtype=float)  # duplicates: spacing 0
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    tree = o3d.geometry.KDTreeFlann(cloud)
    def nearest(q):
        return np.sqrt(tree.search_knn_vector_3d(np.array(q, dtype=float), 2)[2][-1])
    step = np.median([nearest(points[i]) for i in rng.choice(len(points), size=min(2000, len(points)),
                                                                  replace=False)])
    s, _ = area_samples(v, f, n, rng)
    d = np.array([np.sqrt(tree.search_knn_vector_3d(np.array(q, dtype=float), 1)[2][0]) for q in s])
    return float(np.mean(d > spacings * step))


def cases(models, seeds, model_seed=1):
    out = []
    for noise in (1, 2):
        for seed in range(1, seeds + 1):
            out.append((f"sphere-n{noise}-s{seed}", "sphere", noise, seed, 2))
    for m in models:
        v, f = read_off(SHARED / f"{m}.off")
        chi, _, _ = topology(f)
        for noise in (0, 1, 2):
            out.append((f"{m}-n{noise}", m, noise, model_seed, chi))
        out.append((f"{m}-misreg", m, "misreg", model_seed, chi))
        out.append((f"{m}-misreg-noisy", m, "misreg-noisy", model_seed, chi))
        out.append((f"{m}-density10", m, "density10", model_seed, chi))
    return out


def generate(name, model, noise, seed, work):
    rng = np.random.default_rng(seed)
    if model == "sphere":
        n = 6000
        i = np.arange(n)
        z = 1 - (2 * i + 1) / n
        r = np.sqrt(1 - z * z)
        a = 2.399963229728653 * i
        p = np.stack([r * np.cos(a), r * np.sin(a), z], axis=1)
        spacing = np.sqrt(4 * np.pi / n)
    else:
        v, f = read_off(SHARED / f"{model}.off")
        p, area = area_samples(v, f, 30000, rng)
        spacing = np.sqrt(area / len(p))
    if noise == "density10":
        # Uneven density: the half x < median keeps one point in 10 (a 10x density change across a plane).
        mid = np.median(p[:, 0])
        keep = (p[:, 0] >= mid) | (rng.random(len(p)) < 0.1)
        p = p[keep]
    elif noise in ("misreg", "misreg-noisy"):
        # A second view of the 20% of largest x (another sample of it), registered 2 spacings off along
        # +x; misreg-noisy: both views with noise of half a spacing.
        q, _ = area_samples(v, f, 30000, rng)
        cut = np.quantile(p[:, 0], 0.8)
        extra = q[q[:, 0] > cut].copy()
        extra[:, 0] += 2 * spacing
        p = np.concatenate([p, extra])
        if noise == "misreg-noisy":
            p = p + rng.normal(scale=0.5 * spacing, size=p.shape)
    else:
        p = p + rng.normal(scale=noise * spacing, size=p.shape)
    path = work / f"{name}.xyz"
    np.savetxt(path, p, fmt="%.9g")
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vitri", default=str(ROOT / "build-release" / "apps" / "vitri"))
    ap.add_argument("--work", default="/tmp/vitri-noise-topology")
    ap.add_argument("--models", default="bunny")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--model-seed", type=int, default=1, help="seed of the models' samples and noise")
    ap.add_argument("--only", default=None, help="comma-separated prefixes of case names")
    ap.add_argument("--extra", default="", help="more CLI options, e.g. '--threads 1'")
    a = ap.parse_args()
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    models = [m for m in a.models.split(",") if m]
    print("| case | truth chi | chi | components | loops | away % | noise line | s |")
    print("|---|---|---|---|---|---|---|---|")
    for name, model, noise, seed, truth in cases(models, a.seeds, a.model_seed):
        if a.only and not any(name.startswith(x) for x in a.only.split(",")):
            continue
        xyz = generate(name, model, noise, seed, work)
        obj = work / f"{name}.obj"
        t0 = time.time()
        r = subprocess.run([a.vitri, "mesh", str(xyz), "-o", str(obj)] + a.extra.split(),
                           capture_output=True, text=True)
        dt = time.time() - t0
        scan = next((l for l in r.stderr.splitlines() if l.startswith("scan:")), "")
        noise_part = scan.split("spacing ")[-1].split(", points")[0] if scan else ""
        if r.returncode != 0:
            print(f"| {name} | {truth} | exit {r.returncode} | | | {r.stderr.strip()[-120:]} | {dt:.1f} |")
            continue
        v, f = read_obj(obj)
        chi, comps, loops = topology(f)
        away = 100 * away_fraction(v, f, np.loadtxt(xyz)[:, :3], np.random.default_rng(7))
        print(f"| {name} | {truth} | {chi} | {comps} | {loops} | {away:.1f} | {noise_part} | {dt:.1f} |",
              flush=True)


if __name__ == "__main__":
    sys.exit(main())
