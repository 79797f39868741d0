#!/usr/bin/env python3
"""vitri.reconstruct against `vitri mesh` on the same points: wall time and peak memory of each, in
alternating runs, each in a process of its own (docs/python.md "Performance", issue 41).

    PYTHONPATH=build/python python3 bench/python/bench_reconstruct.py --cli build/apps/vitri \\
        [--points 1000000] [--model data/elephant.off] [--rounds 3] [--threads 0] [--work /tmp/vitri-pybench]

The points: --points samples of the model, area-uniform with the faces' normals (seed 1), written once as
a binary PLY without faces (oriented points). Both sides do the same work: read that file, reconstruct
with the default options, write the mesh as binary PLY. Reported per run: the process's wall time
(interpreter start and imports included for Python), its peak RSS (wait4's ru_maxrss), and for Python the
time of the reconstruct() call alone. Overhead = Python / CLI - 1 on the medians. Also the peak of a Python
process that only imports vitri and reads the points (the interpreter's own memory and the user's arrays):
the Python peak less the CLI's and less that baseline is what the binding itself adds.
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

import numpy as np

PY_RUN = r"""
import sys, time
t0 = time.perf_counter()
import vitri
data = vitri.read(sys.argv[1])
t1 = time.perf_counter()
mesh = vitri.reconstruct(data.points, data.normals, threads=int(sys.argv[3]))
t2 = time.perf_counter()
vitri.write(sys.argv[2], mesh)
t3 = time.perf_counter()
print(f"read {t1 - t0:.3f} reconstruct {t2 - t1:.3f} write {t3 - t2:.3f} vertices {len(mesh.vertices)}")
"""


def sample(model, n, seed=1):
    import vitri
    m = vitri.read(model)
    V, F = m.vertices, m.faces.astype(np.int64)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    cross = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(cross, axis=1)
    rng = np.random.default_rng(seed)
    f = rng.choice(len(F), size=n, p=area / area.sum())
    u, v = rng.uniform(size=n), rng.uniform(size=n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    points = a[f] + u[:, None] * (b[f] - a[f]) + v[:, None] * (c[f] - a[f])
    normals = cross[f] / np.linalg.norm(cross[f], axis=1)[:, None]
    return points, normals


def run(cmd):
    """Wall seconds, peak RSS in MB and stdout of one process."""
    t = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    out, err = p.stdout.read(), p.stderr.read()
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        sys.exit(f"{cmd[0]} failed ({p.returncode}):\n{err}")
    return wall, usage.ru_maxrss / 1024.0, out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", required=True)
    ap.add_argument("--points", type=int, default=1000000)
    ap.add_argument("--model", default=os.path.join(os.path.dirname(__file__), "..", "..", "data", "elephant.off"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--work", default="/tmp/vitri-pybench")
    args = ap.parse_args()
    import vitri
    os.makedirs(args.work, exist_ok=True)
    src = os.path.join(args.work, f"{os.path.splitext(os.path.basename(args.model))[0]}_{args.points}.ply")
    if not os.path.exists(src):
        p, n = sample(args.model, args.points)
        vitri.write(src, vitri.Mesh(p, np.zeros((0, 3), np.uint32), n))
    cli_out, py_out = os.path.join(args.work, "cli.ply"), os.path.join(args.work, "py.ply")
    cli, py, calls = [], [], []
    for r in range(args.rounds):
        order = ["cli", "py"] if r % 2 == 0 else ["py", "cli"]
        for who in order:
            if who == "cli":
                wall, rss, _ = run([args.cli, "mesh", src, "-o", cli_out, "-q", "--threads", str(args.threads)])
                cli.append((wall, rss))
            else:
                wall, rss, out = run([sys.executable, "-c", PY_RUN, src, py_out, str(args.threads)])
                py.append((wall, rss))
                calls.append(float(out.split()[3]))
            print(f"round {r} {who:3s}: {wall:7.2f} s, peak {rss:7.0f} MB", flush=True)
    # The interpreter, numpy and the module, and the points read into numpy: what the Python process holds
    # besides the library's work (its peak over the CLI's, less this, is what the binding adds).
    _, base, _ = run([sys.executable, "-c", "import sys, vitri; d = vitri.read(sys.argv[1])", src])
    a, b = vitri.read(cli_out), vitri.read(py_out)
    same = np.array_equal(a.faces, b.faces) and np.array_equal(a.vertices, b.vertices)
    cw, pw = statistics.median(w for w, _ in cli), statistics.median(w for w, _ in py)
    cm, pm = statistics.median(m for _, m in cli), statistics.median(m for _, m in py)
    print(f"\n{args.points} points of {os.path.basename(args.model)}, {args.rounds} rounds, threads {args.threads}")
    print(f"CLI    wall {cw:.2f} s (runs {', '.join(f'{w:.2f}' for w, _ in cli)}), peak {cm:.0f} MB")
    print(f"Python wall {pw:.2f} s (runs {', '.join(f'{w:.2f}' for w, _ in py)}), peak {pm:.0f} MB; "
          f"reconstruct() alone {statistics.median(calls):.2f} s")
    print(f"overhead: time {100 * (pw / cw - 1):+.1f}%, peak memory {pm - cm:+.0f} MB ({100 * (pm / cm - 1):+.1f}%); "
          f"same mesh file content: {same}")
    print(f"Python baseline (interpreter, numpy, vitri, the points read): peak {base:.0f} MB; "
          f"Python peak - CLI peak - baseline: {pm - cm - base:+.0f} MB")


if __name__ == "__main__":
    main()
