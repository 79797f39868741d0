#!/usr/bin/python3
"""Misregistered overlaps other than noise_topology.py's (its MODEL-misreg: the 20% of largest x, a second
sample shifted 2 spacings along +x): `vitri mesh IN.xyz -o OUT.ply` with the CLI's defaults on each, the
Euler characteristic and components of the output against the model's (docs/scans.md, step 7).

Cases, per model (30,000 area-uniform samples of ../shared/data/MODEL.off, seed 7, and a second sample of
the same part, no noise):
  MODEL-x1   the 20% of largest x, the second view shifted 1 spacing along +x
  MODEL-x3   the same, shifted 3 spacings
  MODEL-d3   the 30% of largest y, shifted 3 spacings along (1, 1, 1) / sqrt(3)
  MODEL-rot  the 40% of largest z, rotated about the sample's centroid (axis (1, 2, 0.5)) by 8 spacings
             over the diagonal (radians)
Prints a markdown table. Usage:
  python3 bench/scans/misreg_variants.py --vitri build-release/apps/vitri [--models bunny,hand] [--work DIR]
"""
import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import noise_topology as nt  # noqa: E402  (read_off, read_obj, area_samples, topology; SHARED)


def rotation(axis, angle):
    a = np.asarray(axis, float)
    a /= np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def write_cases(model, work):
    v, f = nt.read_off(nt.SHARED / f"{model}.off")
    rng = np.random.default_rng(7)
    p, area = nt.area_samples(v, f, 30000, rng)
    sp = np.sqrt(area / len(p))
    q, _ = nt.area_samples(v, f, 30000, rng)
    diag = np.linalg.norm(p.max(0) - p.min(0))
    centre = p.mean(0)
    variants = [
        ("x1", q[:, 0] > np.quantile(p[:, 0], 0.8), lambda e: e + [sp, 0, 0]),
        ("x3", q[:, 0] > np.quantile(p[:, 0], 0.8), lambda e: e + [3 * sp, 0, 0]),
        ("d3", q[:, 1] > np.quantile(p[:, 1], 0.7), lambda e: e + 3 * sp * np.ones(3) / np.sqrt(3)),
        ("rot", q[:, 2] > np.quantile(p[:, 2], 0.6),
         lambda e: (e - centre) @ rotation([1, 2, 0.5], 8 * sp / diag).T + centre),
    ]
    out = []
    for name, sel, move in variants:
        path = work / f"{model}-{name}.xyz"
        np.savetxt(path, np.concatenate([p, move(q[sel].copy())]), fmt="%.9g")
        out.append(path)
    return nt.topology(f)[0], out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vitri", default=str(nt.ROOT / "build-release" / "apps" / "vitri"))
    ap.add_argument("--models", default="bunny,elephant,hand,knot1")
    ap.add_argument("--work", default="/tmp/vitri-misreg-variants")
    a = ap.parse_args()
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    print("| case | truth chi | chi | components |")
    print("|---|---|---|---|")
    for model in a.models.split(","):
        truth, paths = write_cases(model, work)
        for path in paths:
            mesh = path.with_suffix(".obj")
            subprocess.run([a.vitri, "mesh", str(path), "-o", str(mesh)], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            vv, ff = nt.read_obj(mesh)
            chi, comps, _ = nt.topology(ff)
            print(f"| {path.stem} | {truth} | {chi} | {comps} |", flush=True)


if __name__ == "__main__":
    main()
