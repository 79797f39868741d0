#!/usr/bin/env python3
"""Markdown tables (param: vitri's absolute precision, CGAL's radius bound, the grid's cells) for docs/benchmarks.md from bench_compare's --csv output (one table per target size,
then the geometric mean over surfaces of vitri's time ratio to each contender).
Usage: bench/compare/summarize.py bench/compare/results/compare.csv"""
import csv
import math
import sys
from collections import defaultdict

rows = list(csv.DictReader(open(sys.argv[1])))
yn = lambda s: "yes" if s == "1" else "**no**"
order = ["vitri-fifo-root", "vitri-fifo-linear", "vitri-largest-root", "vitri-largest-linear", "grid", "cgal"]
for target in sorted({int(r["target"]) for r in rows}):
    print(f"\n#### About {target} vertices\n")
    print("| surface | contender | param | V | F | mesh s (wall) | mesh s (CPU) | evals/V | watertight | manifold | chi "
          "| min angle | < 10 deg | < 20 deg | dist mean | dist max | vitri/this |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    sel = [r for r in rows if int(r["target"]) == target]
    surfaces = []
    for r in sel:
        if r["surface"] not in surfaces:
            surfaces.append(r["surface"])
    for s in surfaces:
        for c in order:
            for r in sel:
                if r["surface"] != s or r["contender"] != c:
                    continue
                print(f"| {s} | {c} | {r['param_name']} {float(r['param']):.4g} | {r['vertices']} | {r['triangles']} | {float(r['mesh_s']):.3f} | "
                      f"{float(r['mesh_cpu_s']):.3f} | {float(r['evals_per_vertex']):.1f} | {yn(r['watertight'])} | "
                      f"{yn(r['manifold'])} | {r['euler']} | {float(r['min_angle']):.2f} | "
                      f"{100 * float(r['share_below_10']):.1f}% | {100 * float(r['share_below_20']):.1f}% | "
                      f"{float(r['dist_mean']):.1e} | {float(r['dist_max']):.1e} | {float(r['ratio_vitri_over_this']):.3f} |")
print("\n#### Time ratio vitri (FIFO, root-found) / contender: geometric mean over the surfaces (wall)\n")
print("| target | surfaces | " + " | ".join(order[1:]) + " |")
print("|---|---|" + "---|" * (len(order) - 1))
groups = [("analytic", lambda s: s in ("sphere", "torus")), ("RBF", lambda s: s not in ("sphere", "torus"))]
for target in sorted({int(r["target"]) for r in rows}):
    for gname, g in groups:
        cells = []
        for c in order[1:]:
            v = [float(r["ratio_vitri_over_this"]) for r in rows
                 if int(r["target"]) == target and r["contender"] == c and g(r["surface"])]
            cells.append(f"{math.exp(sum(map(math.log, v)) / len(v)):.3f} (n={len(v)})" if v else "-")
        print(f"| {target} | {gname} | " + " | ".join(cells) + " |")
