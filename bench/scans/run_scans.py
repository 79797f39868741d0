#!/usr/bin/python3
"""vitri against Poisson (Open3D, CGAL) on scans: simulated ones with a known truth (vitri_scan_cases) and
the shared real scans (../shared/data/scans). See bench/scans/README.md; bench/scans/run_scans.sh installs
what this needs, builds the tools and calls this script.

For each input and method: runs the method in its own process under /usr/bin/time -v with a wall-clock
limit and a memory cap (a failure, a timeout or a crash becomes a row, not the end of the run), measures
the output with vitri_scan_metrics, renders it with `vitri render`, and writes OUT.md (markdown tables),
OUT.csv (every number) and the pictures side by side (OUT-pictures/). With --orient, also the orientation
comparison (bench_orient against Open3D) on the synthetic cases without normals.

Only the standard library here: the Open3D runs are other processes (open3d_poisson.py, open3d_orient.py)."""
import argparse
import csv
import json
import math
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
SHARED = Path(os.environ.get("VITRI_SHARED_DATA", ROOT.parent / "shared" / "data"))
PYTHON = "/usr/bin/python3"  # Debian's, where python3-open3d is


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--build", default=str(ROOT / "build-scans"), help="build folder of the scan tools")
    p.add_argument("--vitri", default=os.environ.get("VITRI", str(ROOT / "build-release" / "apps" / "vitri")),
                   help="the vitri CLI under test (env VITRI)")
    p.add_argument("--render-with", default=None, help="the vitri CLI used for `vitri render` (default --vitri)")
    p.add_argument("--work", default="/tmp/vitri-scans", help="cases, outputs, logs (not committed)")
    p.add_argument("--out", default=str(HERE / "results" / "scans"), help="writes OUT.md and OUT.csv")
    p.add_argument("--pictures", default=None, help="folder of the pictures (default WORK/pictures)")
    p.add_argument("--points", type=int, default=100000, help="points per synthetic case")
    p.add_argument("--models", default=None, help="vitri_scan_cases --models (default: its own list)")
    p.add_argument("--variants", default=None, help="vitri_scan_cases --variants (default: all)")
    p.add_argument("--cases", default=None,
                   help="comma-separated case names to run (e.g. bunny-clean,knot1-noise1); default all; 'none'")
    p.add_argument("--normals", default="without", choices=["without", "with", "both"],
                   help="synthetic inputs without normals (3 columns, default), with (6), or both")
    p.add_argument("--scans", default="all", help="real scans (names in ../shared/data/scans), 'all' or 'none'")
    p.add_argument("--methods", default="vitri,open3d,cgal", help="subset of vitri,open3d,cgal")
    p.add_argument("--depths", default="10", help="Open3D Poisson depths (e.g. 9,10,11)")
    p.add_argument("--timeout", type=float, default=600.0, help="seconds per run")
    p.add_argument("--mem-gb", type=float, default=16.0, help="address-space cap per run (ulimit -v), GB")
    p.add_argument("--samples", type=int, default=200000, help="metrics: samples of each output and truth")
    p.add_argument("--no-render", action="store_true", help="no pictures")
    p.add_argument("--orient", action="store_true", help="also the orientation comparison (synthetic cases)")
    p.add_argument("--resume", action="store_true", help="reuse the results of runs already in --work")
    a = p.parse_args()
    a.methods = a.methods.split(",")
    a.depths = [int(d) for d in a.depths.split(",")]
    a.render_with = a.render_with or a.vitri
    return a


def limit_memory(gb):
    def apply():
        cap = int(gb * 1024 ** 3)
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
    return apply


def run_measured(cmd, timeout, mem_gb, log):
    """Runs cmd under /usr/bin/time -v in its own process group, with RLIMIT_AS. Returns a dict: status
    ('ok', 'exit N', 'signal N', 'timeout'), wall_s, cpu_s, peak_mb, stdout_json (the last line of the
    output that parses as a JSON object, or None), tail (the last meaningful output line)."""
    timing = Path(str(log) + ".time")
    start = time.perf_counter()
    with open(log, "w") as out:
        proc = subprocess.Popen(["/usr/bin/time", "-v", "-o", str(timing)] + [str(c) for c in cmd],
                                stdout=out, stderr=subprocess.STDOUT, start_new_session=True,
                                preexec_fn=limit_memory(mem_gb))
        try:
            proc.wait(timeout=timeout)
            timed_out = False
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            timed_out = True
    wall = time.perf_counter() - start
    text = Path(log).read_text(errors="replace")
    report = timing.read_text(errors="replace") if timing.exists() else ""
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", report)
    cpu = re.findall(r"(?:User|System) time \(seconds\): ([\d.]+)", report)
    killed = re.search(r"Command terminated by signal (\d+)", report)
    code = re.search(r"Exit status: (\d+)", report)
    if timed_out:
        status = "timeout"
    elif killed:
        status = f"signal {killed.group(1)}"
    elif code and code.group(1) == "0":
        status = "ok"
    else:
        status = f"exit {code.group(1) if code else proc.returncode}"
    parsed = None
    for line in reversed(text.splitlines()):
        line = line.strip()
        if line.startswith("{") and line.endswith("}"):
            try:
                parsed = json.loads(line)
                break
            except json.JSONDecodeError:
                pass
    lines = [ln.strip() for ln in text.splitlines()
             if ln.strip() and not ln.startswith("Command ") and not ln.strip().startswith("{")]
    return {"status": status, "wall_s": wall, "cpu_s": sum(float(x) for x in cpu) if cpu else float("nan"),
            "peak_mb": int(rss.group(1)) / 1024.0 if rss else float("nan"), "stdout_json": parsed,
            "tail": lines[-1][:200] if lines else ""}


class Input:
    """One input file with what is known about it."""

    def __init__(self, name, path, kind, viewpoint=None, truth=None, truth_visible=None, spacing=None,
                 outliers=None, reference=None, model=None):
        self.name, self.path, self.kind = name, Path(path), kind
        self.viewpoint = Path(viewpoint) if viewpoint else None
        self.truth = Path(truth) if truth else None
        self.truth_visible = Path(truth_visible) if truth_visible else None
        self.spacing = spacing
        self.outliers = Path(outliers) if outliers else None
        self.reference = Path(reference) if reference else None
        self.model = model
        with open(self.path) as f:
            self.normals = len(f.readline().split()) >= 6


def synthetic_inputs(a, tools):
    cases = Path(a.work) / f"cases-{a.points}"
    manifest = cases / "manifest.csv"
    if not manifest.exists() or not a.resume:
        cmd = [tools["cases"], cases, "--points", a.points]
        if a.models:
            cmd += ["--models", a.models]
        if a.variants:
            cmd += ["--variants", a.variants]
        print("generating cases:", " ".join(str(c) for c in cmd), flush=True)
        subprocess.run([str(c) for c in cmd], check=True, stdout=subprocess.DEVNULL)
    wanted = None if a.cases in (None, "all") else set(a.cases.split(","))
    inputs = []
    with open(manifest) as f:
        for row in csv.DictReader(f):
            if wanted is not None and row["case"] not in wanted:
                continue
            common = dict(viewpoint=cases / row["viewpoint"] if row["viewpoint"] else None,
                          truth=cases / row["truth"],
                          truth_visible=cases / row["truth_visible"] if row["truth_visible"] else None,
                          spacing=float(row["spacing"]),
                          outliers=cases / row["outliers_file"] if row["outliers_file"] else None,
                          model=row["model"])
            ref = cases / row["normals_file"] if row["normals_file"] else None
            if row["file"] and a.normals in ("without", "both"):
                inputs.append(Input(row["case"], cases / row["file"], "synthetic", reference=ref, **common))
            if row["normals_file"] and a.normals in ("with", "both"):
                inputs.append(Input(row["case"] + "-n", ref, "synthetic", **common))
    return inputs


def real_inputs(a):
    folder = SHARED / "scans"
    if a.scans == "none":
        return []
    names = sorted(p.stem for p in folder.glob("*.xyz")) if a.scans == "all" else a.scans.split(",")
    inputs = []
    for n in names:
        vp = folder / f"{n}.viewpoint"
        inputs.append(Input(n, folder / f"{n}.xyz", "real", viewpoint=vp if vp.exists() else None))
    return inputs


def method_runs(a, tools, inp, folder):
    """(method name, command, output path) for every method on one input."""
    runs = []
    if "vitri" in a.methods:
        out = folder / "vitri.ply"
        runs.append(("vitri", [a.vitri, "mesh", inp.path, "-o", out], out))
    if "open3d" in a.methods:
        for d in a.depths:
            out = folder / f"open3d-d{d}.ply"
            cmd = [PYTHON, HERE / "open3d_poisson.py", inp.path, out, "--depth", d]
            if inp.viewpoint and not inp.normals:
                cmd += ["--viewpoint", inp.viewpoint]
            runs.append((f"open3d-d{d}", cmd, out))
    if "cgal" in a.methods and tools.get("cgal"):
        out = folder / "cgal.off"
        cmd = [tools["cgal"], inp.path, "-o", out]
        if inp.viewpoint and not inp.normals:
            cmd += ["--viewpoint", inp.viewpoint]
        runs.append(("cgal", cmd, out))
    return runs


def measure(a, tools, inp, mesh, folder, method):
    cmd = [tools["metrics"], mesh, "--points", inp.path, "--json", "--samples", a.samples,
           "--truth-samples", a.samples]
    if inp.truth:
        cmd += ["--truth", inp.truth]
    if inp.truth_visible:
        cmd += ["--truth-visible", inp.truth_visible]
    if inp.spacing:
        cmd += ["--spacing", inp.spacing]
    log = folder / f"{method}.metrics.log"
    r = run_measured(cmd, a.timeout, a.mem_gb, log)
    if r["status"] != "ok":
        return {"error": f"{r['status']}: {r['tail']}"}
    text = log.read_text(errors="replace")
    try:
        return json.loads(text[text.index("{"):])  # the program prints one JSON object over several lines
    except ValueError:
        return {"error": f"unreadable metrics: {text[-200:]}"}


def view_of(inp, metrics):
    """`vitri render` view options for an input: from its viewpoint when known (azimuth / elevation of
    the sensor seen from the box centre, y up), z up from above for airborne and street LiDAR, else the
    renderer's default."""
    if inp.kind == "real" and (inp.name.startswith("als_") or inp.name.startswith("lidar") or
                               inp.name.startswith("laser")):
        return ["--up", "z", "--view", "30", "45"]
    if inp.kind == "synthetic":
        return ["--view", "30", "20"]  # vitri_scan_cases' default camera: the single views are seen from there
    if inp.viewpoint and metrics and "input_box" in metrics:
        box = metrics["input_box"]
        centre = [(box[i] + box[i + 3]) / 2 for i in range(3)]
        with open(inp.viewpoint) as f:
            eye = [float(x) for x in f.read().split()[:3]]
        d = [eye[i] - centre[i] for i in range(3)]
        n = math.sqrt(sum(x * x for x in d)) or 1.0
        el = math.degrees(math.asin(max(-1.0, min(1.0, d[1] / n))))
        az = math.degrees(math.atan2(d[0], d[2]))
        return ["--view", f"{az:.1f}", f"{el:.1f}"]
    if inp.name.startswith("hippo"):
        return ["--view", "0", "30"]
    return ["--view", "30", "20"]


def fmt(x, digits=2):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if isinstance(x, float):
        if x != 0 and (abs(x) >= 1e4 or abs(x) < 10 ** -digits):
            return f"{x:.{digits}g}" if abs(x) < 1e4 else f"{x:.0f}"
        return f"{x:.{digits}f}"
    return str(x)


def main():
    a = parse_args()
    build = Path(a.build)
    tools = {"cases": build / "bench" / "scans" / "vitri_scan_cases",
             "metrics": build / "bench" / "scans" / "vitri_scan_metrics",
             "orient": build / "bench" / "scans" / "bench_orient",
             "cgal": build / "bench" / "scans" / "vitri_scan_cgal_poisson"}
    for k in ("cases", "metrics"):
        if not tools[k].exists():
            sys.exit(f"run_scans: {tools[k]} missing (build it: bench/scans/run_scans.sh)")
    if not tools["cgal"].exists():
        print("run_scans: vitri_scan_cgal_poisson not built (no CGAL): CGAL rows skipped", flush=True)
        tools["cgal"] = None
    work = Path(a.work)
    work.mkdir(parents=True, exist_ok=True)
    inputs = (synthetic_inputs(a, tools) if a.cases != "none" else []) + real_inputs(a)
    out = Path(a.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    pictures = Path(a.pictures or work / "pictures")
    if not a.no_render:
        pictures.mkdir(parents=True, exist_ok=True)
    montage = shutil.which("montage")
    rows = []
    started = time.time()
    for inp in inputs:
        folder = work / "runs" / inp.name
        folder.mkdir(parents=True, exist_ok=True)
        renders = []
        if not a.no_render and inp.truth:
            png = folder / "truth.png"
            rr = run_measured([a.render_with, "render", inp.truth, "-o", png, "--size", "800x600"] +
                              view_of(inp, None), a.timeout, a.mem_gb, folder / "truth.render.log")
            if rr["status"] == "ok" and png.exists():
                renders.append(("truth", png))
        for method, cmd, mesh in method_runs(a, tools, inp, folder):
            record = folder / f"{method}.json"
            if a.resume and record.exists():
                row = json.loads(record.read_text())
            else:
                print(f"[{time.time() - started:7.0f} s] {inp.name}: {method}", flush=True)
                r = run_measured(cmd, a.timeout, a.mem_gb, folder / f"{method}.log")
                row = {"input": inp.name, "kind": inp.kind, "normals": inp.normals, "method": method,
                       "status": r["status"] if r["status"] != "ok" or mesh.exists() else "no output",
                       "wall_s": r["wall_s"], "cpu_s": r["cpu_s"], "peak_mb": r["peak_mb"],
                       "stages": r["stdout_json"] or {}, "note": "" if r["status"] == "ok" else r["tail"]}
                if row["status"] == "ok":
                    row["metrics"] = measure(a, tools, inp, mesh, folder, method)
                record.write_text(json.dumps(row, indent=1))
            rows.append(row)
            if not a.no_render and row["status"] == "ok" and "error" not in (row.get("metrics") or {"error": 1}):
                png = folder / f"{method}.png"
                rr = run_measured([a.render_with, "render", mesh, "-o", png, "--size", "800x600"] +
                                  view_of(inp, row["metrics"]), a.timeout, a.mem_gb, folder / f"{method}.render.log")
                if rr["status"] == "ok" and png.exists():
                    renders.append((method, png))
        if renders:
            side = pictures / f"{inp.name}.png"
            if montage:
                cmd = [montage]
                font = Path("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf")  # ImageMagick's default may be absent
                if font.exists():
                    cmd += ["-font", str(font), "-pointsize", "20"]
                for method, png in renders:
                    cmd += ["-label", method, str(png)]
                cmd += ["-tile", f"{len(renders)}x1", "-geometry", "600x450+4+4", str(side)]
                subprocess.run(cmd, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            else:
                for method, png in renders:
                    shutil.copy(png, pictures / f"{inp.name}-{method}.png")
    orient_rows = run_orientation(a, tools, inputs, work) if a.orient else []
    write_results(a, out, rows, orient_rows, inputs, time.time() - started, pictures)


def run_orientation(a, tools, inputs, work):
    rows = []
    for inp in inputs:
        if inp.kind != "synthetic" or inp.normals or not inp.reference:
            continue
        folder = work / "runs" / inp.name
        folder.mkdir(parents=True, exist_ok=True)
        row = {"input": inp.name}
        for name, cmd in (("vitri", [tools["orient"], inp.path, "--reference", inp.reference]),
                          ("vitri_scan", [tools["orient"], inp.path, "--reference", inp.reference,
                                          "--method", "scan"]),
                          ("open3d", [PYTHON, HERE / "open3d_orient.py", inp.path, "--reference", inp.reference])):
            if inp.outliers:
                cmd += ["--exclude", inp.outliers]
            if name in ("open3d", "vitri_scan") and inp.viewpoint:
                cmd += ["--viewpoint", inp.viewpoint]
            record = folder / f"orient-{name}.json"
            if a.resume and record.exists():
                row[name] = json.loads(record.read_text())
                continue
            print(f"orientation {inp.name}: {name}", flush=True)
            r = run_measured(cmd, a.timeout, a.mem_gb, folder / f"orient-{name}.log")
            row[name] = r["stdout_json"] or {"status": f"{r['status']}: {r['tail']}"}
            row[name]["peak_mb"] = r["peak_mb"]
            record.write_text(json.dumps(row[name], indent=1))
        rows.append(row)
    return rows


def write_results(a, out, rows, orient_rows, inputs, seconds, pictures):
    columns = ["input", "kind", "normals", "method", "status", "wall_s", "cpu_s", "peak_mb", "vertices",
               "triangles", "components", "closed", "boundary_edges", "non_manifold_edges", "euler",
               "spacing", "acc_median_sp", "acc_p99_sp", "far_area_pct", "completeness_pct",
               "to_truth_mean_sp", "to_truth_median_sp", "to_truth_p90_sp", "to_truth_p99_sp",
               "to_truth_mean_diag", "to_truth_p99_diag", "from_truth_mean_sp", "from_truth_median_sp",
               "from_truth_p90_sp", "from_truth_p99_sp", "from_truth_mean_diag", "from_truth_p99_diag",
               "one_sided_truth", "stages", "note"]
    flat = []
    for r in rows:
        m = r.get("metrics") or {}
        f = {k: r.get(k) for k in ("input", "kind", "normals", "method", "status", "wall_s", "cpu_s", "peak_mb")}
        f["note"] = r.get("note") or m.get("error", "")
        f["stages"] = json.dumps(r.get("stages", {}))
        if m and "error" not in m:
            f.update(vertices=m["vertices"], triangles=m["triangles"], components=m["components"],
                     closed=m["closed"], boundary_edges=m["boundary_edges"],
                     non_manifold_edges=m["non_manifold_edges"], euler=m["euler"], spacing=m["spacing"],
                     acc_median_sp=float(m["accuracy"]["median_spacings"]),
                     acc_p99_sp=float(m["accuracy"]["p99_spacings"]),
                     far_area_pct=100.0 * m["far_area"], completeness_pct=100.0 * m["completeness"])
            if m.get("has_truth"):
                for side in ("to_truth", "from_truth"):
                    for s in ("mean", "median", "p90", "p99"):
                        f[f"{side}_{s}_sp"] = float(m[side][f"{s}_spacings"])
                    for s in ("mean", "p99"):
                        f[f"{side}_{s}_diag"] = float(m[side][f"{s}_diag"])
                f["one_sided_truth"] = m["one_sided_truth"]
        flat.append(f)
    with open(str(out) + ".csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for f in flat:
            w.writerow(f)

    def machine():
        try:
            cpu = re.search(r"Model name:\s*(.*)", subprocess.run(["lscpu"], capture_output=True,
                                                                   text=True).stdout).group(1)
        except Exception:
            cpu = "?"
        return f"{cpu}, {os.cpu_count()} CPUs"

    try:
        rev = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--dirty"], capture_output=True,
                             text=True).stdout.strip()
    except OSError:
        rev = "?"
    lines = [f"# Scans against Poisson ({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())})", "",
             f"Machine: {machine()}; load after: {os.getloadavg()[0]:.2f}. vitri: `{a.vitri}`. "
             f"Tree: {rev}. Limits: {a.timeout:.0f} s, {a.mem_gb:g} GB per run. Whole run: {seconds / 60:.1f} min.",
             "Distances in spacings (median nearest-neighbour distance of the clean sample for synthetic cases, "
             "of the input for real scans). acc: output surface -> nearest input point (median / 99th "
             "percentile); far: output area farther than 10 spacings from every input point; compl.: input "
             "points within 3 spacings of the output; ->truth: output -> true surface; truth->: dense truth "
             "samples -> output (single views: the visible part of the truth only, marked *). Times: wall "
             "clock of the whole process (reading and writing included); memory: peak resident.", "",
             "| input | method | status | time s | peak MB | vertices | comp. | closed | acc med | acc p99 | "
             "far % | compl. % | ->truth mean / p99 | truth-> mean / p99 |",
             "|---|---|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|"]
    for f in flat:
        ok = f["status"] == "ok" and f.get("vertices") is not None
        status = f["status"] if ok else f"{f['status']}: {f['note'][:80]}".replace("|", "/")
        truth = lambda side: (f"{fmt(f.get(side + '_mean_sp'))} / {fmt(f.get(side + '_p99_sp'))}"
                              if f.get(side + "_mean_sp") is not None else "-")
        star = "*" if f.get("one_sided_truth") else ""
        closed = "-" if not ok else ("yes" if f["closed"] else f"no ({f['boundary_edges']})")
        lines.append(f"| {f['input']} | {f['method']} | {status} | {fmt(f['wall_s'], 1)} | {fmt(f['peak_mb'], 0)} | "
                     f"{fmt(f.get('vertices'))} | {fmt(f.get('components'))} | {closed} | "
                     f"{fmt(f.get('acc_median_sp'))} | {fmt(f.get('acc_p99_sp'))} | {fmt(f.get('far_area_pct'), 1)} | "
                     f"{fmt(f.get('completeness_pct'), 1)} | {truth('to_truth')} | {truth('from_truth')}{star} |")
    if orient_rows:
        lines += ["", "## Orientation of unoriented points (synthetic cases)", "",
                  "oriented: points whose normal points to the same side as the true normal (n . n_true > 0; "
                  "outliers excluded); tangent: |n . n_true| >= cos 25 degrees. vitri strict: "
                  "`estimate_oriented_normals(points)` with default options; vitri scan: `prepare_scan(points)` "
                  "with default ScanOptions (what `vitri mesh` does; its points, moved and without outliers and "
                  "thinned ones, matched to the nearest input point; kept = points it returned); Open3D: "
                  "estimate_normals(KNN 30) + orient_normals_consistent_tangent_plane(30) (towards the camera "
                  "for single views).", "",
                  "| input | strict s | strict status | strict oriented % | strict tangent % | scan s | scan status | "
                  "scan kept | scan oriented % | scan tangent % | Open3D s | Open3D oriented % | Open3D tangent % |",
                  "|---|---:|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|"]
        for r in orient_rows:
            v, sc, o = r["vitri"], r.get("vitri_scan", {}), r["open3d"]
            pct = lambda d, k: fmt(100 * d[k], 1) if k in d else "-"
            lines.append(f"| {r['input']} | {fmt(v.get('seconds'))} | {str(v.get('status'))[:90]} | "
                         f"{pct(v, 'oriented')} | {pct(v, 'tangent')} | {fmt(sc.get('seconds'))} | "
                         f"{str(sc.get('status'))[:90]} | {fmt(sc.get('returned'))} | {pct(sc, 'oriented')} | "
                         f"{pct(sc, 'tangent')} | {fmt(o.get('seconds'))} | "
                         f"{pct(o, 'oriented')} | {pct(o, 'tangent')} |")
        with open(Path(a.work) / "orient.json", "w") as fh:
            json.dump(orient_rows, fh, indent=1)
    if not a.no_render:
        lines += ["", f"Pictures (one per input: the truth when known, then the methods): `{pictures}/`."]
    Path(str(out) + ".md").write_text("\n".join(lines) + "\n")
    print(f"wrote {out}.md, {out}.csv", flush=True)


if __name__ == "__main__":
    main()
