#!/usr/bin/python3
"""vitri against Open3D's screened Poisson reconstruction on oriented points sampled from the shared
models (issue 12, "Comparison"; results in docs/benchmarks.md, "Against Poisson (Open3D)").

For each model and size: samples oriented points (area-uniform, true face normals, fixed seed) into a
binary PLY; runs Open3D's Poisson at each depth and `vitri mesh --function local` at its default
precision and at precisions matched to Poisson's vertex counts (and `--function global` with --global),
each in its own process under /usr/bin/time -v (wall time, peak resident memory); then measures every
output against the true model: two-sided distance (exact point-to-triangle, relative to the model's
bounding-box diagonal), closed, components, Euler characteristic, vertex count. A run that fails, aborts
or times out becomes a row saying so. Writes OUT.md (markdown tables) and OUT.csv.

Usage: /usr/bin/python3 bench/compare/poisson/compare.py [--quick] [--models bear,man] [--sizes 10000]
       [--depths 8,9,10] [--vitri build-rel/apps/vitri] [--global] [--work DIR] [--out PREFIX]
Setup (Debian packages, Release build of the CLI): bash tools/bench_poisson.sh [these options]."""
import argparse
import csv
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

import geometry as geo

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
DATA = Path(os.environ.get("VITRI_SHARED_DATA", ROOT.parent / "shared" / "data"))
REFERENCE_SEED = 20261124  # the dense reference samples; the inputs use their size as seed
OUTPUT_SAMPLE_SEED = 7
NEAR_DUPLICATE = 2e-6  # x the model's diagonal: vitri refuses points closer than 1e-6 of its box's


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="10^4 and 10^5 points only")
    p.add_argument("--models", default="bear,elephant,turbine,man", help="OFF files of the shared data")
    p.add_argument("--sizes", default=None, help="point counts (default 10000,100000,1000000)")
    p.add_argument("--depths", default="8,9,10", help="Poisson octree depths")
    p.add_argument("--reference", type=int, default=1_000_000, help="dense model samples for distances")
    p.add_argument("--output-samples", type=int, default=1_000_000, help="samples on each output")
    p.add_argument("--vitri", default=str(ROOT / "build-rel" / "apps" / "vitri"))
    p.add_argument("--global", dest="use_global", action="store_true",
                   help="also vitri --function global (refused or very slow beyond ~10^4 points)")
    p.add_argument("--no-match", action="store_true", help="vitri at its default precision only")
    p.add_argument("--match-max", type=int, default=100_000,
                   help="above this many points, vitri is matched to the deepest Poisson run only")
    p.add_argument("--timeout", type=float, default=600.0, help="seconds per run")
    p.add_argument("--work", default=str(ROOT / "build-poisson"), help="samples and meshes (not committed)")
    p.add_argument("--out", default=str(HERE.parent / "results" / "poisson"), help="writes OUT.md, OUT.csv")
    a = p.parse_args()
    sizes = a.sizes or ("10000,100000" if a.quick else "10000,100000,1000000")
    a.sizes = [int(s) for s in sizes.split(",")]
    a.depths = [int(d) for d in a.depths.split(",")]
    a.models = a.models.split(",")
    return a


def run_measured(cmd, timeout, log):
    """Runs cmd under /usr/bin/time -v in its own process group. Returns (status, wall s, CPU s, peak MB,
    text): status 'ok', 'exit N', 'signal N' or 'timeout'; CPU = user + system seconds; text = the
    command's stdout and stderr."""
    timing = log.with_suffix(".time")
    start = time.perf_counter()
    with open(log, "w") as out:
        proc = subprocess.Popen(["/usr/bin/time", "-v", "-o", str(timing)] + [str(c) for c in cmd],
                                stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    wall = time.perf_counter() - start
    text = log.read_text(errors="replace")
    report = timing.read_text(errors="replace") if timing.exists() else ""
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", report)
    peak_mb = int(rss.group(1)) / 1024.0 if rss else float("nan")
    seconds = re.findall(r"(?:User|System) time \(seconds\): ([\d.]+)", report)
    cpu = sum(float(x) for x in seconds) if seconds else float("nan")
    killed = re.search(r"Command terminated by signal (\d+)", report)
    if proc.returncode == -signal.SIGKILL and not killed:
        return "timeout", wall, cpu, peak_mb, text
    if killed:
        return f"signal {killed.group(1)}", wall, cpu, peak_mb, text
    code = re.search(r"Exit status: (\d+)", report)
    status = "ok" if code and code.group(1) == "0" else f"exit {code.group(1) if code else proc.returncode}"
    return status, wall, cpu, peak_mb, text


def failure_note(status, text):
    """The status and the last meaningful line of a failed run's output (the error message)."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip() and not ln.startswith("Command ")]
    return f"{status}: {lines[-1][:160]}" if lines else status


class Model:
    """A shared model: its triangles (outward), diagonal, topology, and the file of its dense samples."""

    def __init__(self, name, n_reference, work):
        self.name = name
        self.path = DATA / f"{name}.off"
        self.V, self.F = geo.read_closed_model(self.path)
        self.diag = geo.diagonal(self.V)
        self.topology = geo.topology(self.V, self.F, self.diag)
        if self.topology["boundary_edges"] or self.topology["nonmanifold_edges"]:
            raise SystemExit(f"{name}.off is not a closed manifold mesh: no true model to measure against")
        self.reference = Path(work) / f"{name}_reference_{n_reference}.npy"
        if not self.reference.exists():
            np.save(self.reference, geo.sample_surface(self.V, self.F, n_reference, REFERENCE_SEED)[0])


class Sweep:
    """The runs of one invocation and their rows."""

    def __init__(self, args, header):
        self.args = args
        self.header = header
        self.work = Path(args.work)
        self.work.mkdir(parents=True, exist_ok=True)
        self.rows = []

    def points_file(self, model, n):
        """The sampled input (a PLY, made once) and, when some samples lie within NEAR_DUPLICATE x the
        diagonal of an earlier one, a copy without those (for vitri, which refuses duplicates closer than
        1e-6 of its constraints' diagonal) and how many it drops; else (path, None, 0)."""
        path = self.work / f"{model.name}_{n}.ply"
        thinned = self.work / f"{model.name}_{n}_thinned.ply"
        points, normals = geo.sample_surface(model.V, model.F, n, seed=n)
        if not path.exists():
            geo.write_oriented_ply(path, points, normals)
        pairs = cKDTree(points).query_pairs(NEAR_DUPLICATE * model.diag, output_type="ndarray")
        later = np.unique(pairs.max(axis=1)) if len(pairs) else np.empty(0, dtype=np.int64)
        if len(later) == 0:
            return path, None, 0
        if not thinned.exists():
            keep = np.setdiff1d(np.arange(n), later)
            geo.write_oriented_ply(thinned, points[keep], normals[keep])
        return path, thinned, len(later)

    def measure(self, model, n, method, param, cmd, mesh_path, extra=None):
        """Runs cmd, measures its output mesh against the model, appends and returns the row."""
        if mesh_path.exists():
            mesh_path.unlink()
        load = os.getloadavg()[0]
        status, wall, cpu, peak, text = run_measured(cmd, self.args.timeout, mesh_path.with_suffix(".log"))
        row = {"model": model.name, "points": n, "method": method, "param": param, "status": status,
               "wall_s": wall, "cpu_s": cpu, "peak_mb": peak, "load": load,
               "model_euler": model.topology["euler"], "model_components": model.topology["components"],
               "output": text}
        row.update(extra(text) if extra and status == "ok" else {})
        if status == "ok" and not mesh_path.exists():
            row["status"] = "no output file"
        if row["status"] != "ok":
            row["status"] = failure_note(row["status"], text)
        else:
            self.measure_mesh(model, mesh_path, row)
        self.rows.append(row)
        print(one_line(row), flush=True)
        write_results(self.args, self.rows, self.header)  # partial results survive an interrupted sweep
        return row

    def measure_mesh(self, model, mesh_path, row):
        """Adds the output's topology and distances to row (measure.py, in its own process)."""
        cmd = ["/usr/bin/python3", HERE / "measure.py", model.path, model.reference, mesh_path,
               self.args.output_samples, OUTPUT_SAMPLE_SEED]
        done = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
        if done.returncode != 0:
            failed = f"measuring failed (exit {done.returncode})"
            row["status"] = failure_note(failed, done.stdout + done.stderr)
        else:
            row.update(json.loads(done.stdout.strip().splitlines()[-1]))

    def poisson(self, model, n, points, depth):
        out = self.work / f"{model.name}_{n}_poisson{depth}.ply"
        cmd = ["/usr/bin/python3", HERE / "poisson_run.py", points, depth, out]
        return self.measure(model, n, f"Poisson depth {depth}", f"depth {depth}", cmd, out, poisson_extra)

    def vitri(self, model, n, points, function, precision=None, label="default", tag="default"):
        out = self.work / f"{model.name}_{n}_vitri_{function}_{tag}.ply"
        cmd = [self.args.vitri, "mesh", points, "-o", out, "--function", function]
        if precision is not None:
            cmd += ["--precision", f"{precision:.6g}"]
        return self.measure(model, n, f"vitri {function} {label}", precision, cmd, out, vitri_extra)

    def model_size(self, model, n):
        """Poisson at every depth, vitri local at its default precision (again on the thinned copy if it
        refuses near-duplicates), matched to Poisson's vertex counts (only the deepest above --match-max
        points), and global with --global."""
        points, thinned, dropped = self.points_file(model, n)
        poisson_rows = [self.poisson(model, n, points, d) for d in self.args.depths]
        base = self.vitri(model, n, points, "local")
        note = ""
        if base["status"] != "ok" and thinned is not None:
            points, note = thinned, f", {dropped} near-duplicates dropped"
            base = self.vitri(model, n, points, "local", label="default" + note, tag="default_thinned")
        if base["status"] == "ok" and base["param"] and not self.args.no_match:
            matched = [base["vertices"]]
            for row in poisson_rows if n <= self.args.match_max else poisson_rows[-1:]:
                target = row.get("vertices")
                if not target or min(abs(target / v - 1) for v in matched) < 0.2:
                    continue  # Poisson failed, or a run at about this size was already made
                matched.append(target)
                precision = base["param"] * math.sqrt(base["vertices"] / target)
                label, tag = f"~{row['param']}{note}", "d" + row["param"].split()[-1]
                self.vitri(model, n, points, "local", precision, label, tag)
        if self.args.use_global:
            precision = base["param"] if base["status"] == "ok" else None
            self.vitri(model, n, points, "global", precision, "default" + note)


def poisson_extra(text):
    m = re.search(r"poisson_s=([\d.]+)", text)
    return {"core_s": float(m.group(1))} if m else {}


def vitri_extra(text):
    """The precision vitri chose (no --precision) and its own total for refinement + extraction."""
    extra = {}
    m = re.search(r"median spacing, ([\d.eE+-]+)", text)
    if m:
        extra["param"] = float(m.group(1))
    m = re.search(r"(local|global) fit (\d+) ms, initial tetrahedralization (\d+) ms", text)
    if m:
        extra["fit_s"], extra["tetrahedralization_s"] = float(m.group(2)) / 1e3, float(m.group(3)) / 1e3
    m = re.search(r"^\s*0\s+([\d.eE+-]+)\s+\d+\s+\d+\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)", text, re.M)
    if m:
        extra["param"] = float(m.group(1))
        extra["refine_s"], extra["extract_s"] = float(m.group(2)) / 1e3, float(m.group(3)) / 1e3
        extra["core_s"] = float(m.group(4)) / 1000.0  # from reading the input to the extracted mesh
    return extra


def fmt(v, spec):
    return "-" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def one_line(r):
    if not r["status"] == "ok":
        return f"{r['model']} {r['points']} {r['method']}: {r['status']} ({r['wall_s']:.1f} s)"
    return (f"{r['model']} {r['points']} {r['method']}: {r['wall_s']:.1f} s, {r['peak_mb']:.0f} MB, "
            f"V {r['vertices']}, chi {r['euler']} ({r['model_euler']}), {r['components']} comp, "
            f"boundary {r['boundary_edges']}, mean {r['out_to_model_mean']:.2e}/{r['model_to_out_mean']:.2e}")


COLUMNS = ["points", "method", "param", "wall s", "CPU s", "core s", "peak MB", "load", "V", "closed", "comp",
           "chi", "mean out->model", "mean model->out", "p99 (both)", "max (both)"]


def markdown_row(r):
    param = r["param"] if isinstance(r["param"], str) else "P " + fmt(r["param"], ".3g")
    head = [str(r["points"]), r["method"], param] + [
        fmt(v, spec) for v, spec in ((r["wall_s"], ".1f"), (r["cpu_s"], ".1f"), (r.get("core_s"), ".1f"),
                                     (r["peak_mb"], ".0f"), (r["load"], ".1f"))]
    if r["status"] != "ok":
        return head + [f"**{r['status']}**"] + [""] * (len(COLUMNS) - len(head) - 1)
    closed = "yes" if r["boundary_edges"] == 0 and r["nonmanifold_edges"] == 0 else (
        f"**no** ({r['boundary_edges']} boundary, {r['nonmanifold_edges']} non-manifold edges)")
    comp = str(r["components"]) if r["components"] == r["model_components"] else f"**{r['components']}**"
    chi = str(r["euler"]) if r["euler"] == r["model_euler"] else f"**{r['euler']}**"
    return head + [str(r["vertices"]), closed, comp, chi, fmt(r["out_to_model_mean"], ".2e"),
                   fmt(r["model_to_out_mean"], ".2e"),
                   fmt(max(r["out_to_model_p99"], r["model_to_out_p99"]), ".2e"),
                   fmt(max(r["out_to_model_max"], r["model_to_out_max"]), ".2e")]


def phase_table(rows):
    """vitri's own phase times (from its output) for every successful vitri run, in seconds."""
    phases = ["fit_s", "tetrahedralization_s", "refine_s", "extract_s", "core_s"]
    sel = [r for r in rows if r["method"].startswith("vitri") and all(k in r for k in phases)]
    if not sel:
        return []
    lines = ["#### vitri phases (s; total = from reading the input to the extracted mesh)", "",
             "Each step's own wall time. With the local function the fit and the initial tetrahedralization's "
             "Delaunay insertion run at the same time (the Mesher overlaps them), so they add up to more "
             "than the time they took together.", "",
             "| model | points | method | fit | initial tetrahedralization | refine | extract | total |",
             "|---|---|---|---|---|---|---|---|"]
    for r in sel:
        lines.append(f"| {r['model']} | {r['points']} | {r['method']} | "
                     + " | ".join(f"{r[k]:.1f}" for k in phases) + " |")
    return lines + [""]


def write_results(args, rows, header):
    lines = header + [""]
    for name in args.models:
        sel = [r for r in rows if r["model"] == name]
        if not sel:
            continue
        lines += [f"#### {name} (model: Euler characteristic {sel[0]['model_euler']}, "
                  f"{sel[0]['model_components']} component)", "",
                  "| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
        lines += ["| " + " | ".join(markdown_row(r)) + " |" for r in sel]
        lines.append("")
    lines += phase_table(rows)
    Path(args.out + ".md").write_text("\n".join(lines) + "\n")
    keys = [k for k in rows[0] if k != "output"] if rows else []
    for r in rows:
        keys += [k for k in r if k not in keys and k != "output"]
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)


def machine():
    cpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    m = re.search(r"Model name:\s*(.*)", cpu)
    return f"{m.group(1).strip() if m else '?'}, {os.cpu_count()} CPUs"


def main():
    args = parse_args()
    if not Path(args.vitri).exists():
        sys.exit(f"compare.py: no vitri binary at {args.vitri} (bash tools/bench_poisson.sh builds it)")
    import open3d
    header = [f"Date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}", "",
              f"Machine: {machine()}; Open3D {open3d.__version__}; load average before: "
              f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}", "",
              "Command: /usr/bin/python3 bench/compare/poisson/compare.py " + " ".join(sys.argv[1:])]
    sweep = Sweep(args, header)
    for name in args.models:
        model = Model(name, args.reference, args.work)
        for n in args.sizes:
            sweep.model_size(model, n)
    header.append(f"\nLoad average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    write_results(args, sweep.rows, header)
    print(f"wrote {args.out}.md and {args.out}.csv")


if __name__ == "__main__":
    main()
