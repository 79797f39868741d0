"""Issue 43's speedup of worker processes (docs/blocks.md): N oriented points sampled from a shared model,
meshed in blocks by `vitri.blocks.reconstruct` on a local Dask cluster of W worker processes (one thread
each, loopback), for each W given; beside them the one-process run (`client=None`, the library's
mesh_in_blocks) on one thread. Prints one line per run (wall seconds, speedup against one worker, the
mesh's size and a hash of its vertices and triangles: every run must give the same mesh) and writes
results.json in --out after each run (a run cut short keeps the earlier ones).

Usage (build the Python module first: cmake -DVITRI_BUILD_PYTHON=ON, PYTHONPATH=<build>/python):
  PYTHONPATH=build-release/python /usr/bin/python3 bench/blocks/bench_workers.py \\
      --model ../shared/data/elephant.off --points 5e5 --blocks 2 --workers 1,2,4,8 --out /tmp/workers
"""
import argparse
import hashlib
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_blocks import read_off, sample  # noqa: E402


def mesh_hash(mesh):
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(mesh.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype=np.int64).tobytes())
    return h.hexdigest()[:16]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--model", required=True)
    ap.add_argument("--points", type=float, default=5e5)
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--blocks", default="2", help="N or NxMxK")
    ap.add_argument("--workers", default="1,2,4")
    ap.add_argument("--one-process", action="store_true", help="also the one-process run (mesh_in_blocks)")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()

    import vitri
    from vitri import blocks
    from dask.distributed import Client, LocalCluster

    os.makedirs(args.out, exist_ok=True)
    counts = [int(x) for x in args.blocks.lower().split("x")]
    counts = counts * 3 if len(counts) == 1 else counts
    V, F = read_off(args.model)
    t = time.time()
    P, N = sample(V, F, int(args.points), args.seed)
    print("sampled %d points of %s in %.1f s; %d CPUs" % (len(P), args.model, time.time() - t, os.cpu_count()),
          flush=True)
    results = {"model": os.path.basename(args.model), "points": len(P), "seed": args.seed, "blocks": counts,
               "cpus": os.cpu_count(), "runs": []}

    def record(kind, workers, seconds, mesh, info):
        row = {"kind": kind, "workers": workers, "seconds": round(seconds, 2), "vertices": int(len(mesh.vertices)),
               "triangles": int(len(mesh.faces)), "hash": mesh_hash(mesh), "blocks": int(info.get("blocks", 0))}
        base = [r for r in results["runs"] if r["kind"] == "dask" and r["workers"] == 1]
        if base and kind == "dask":
            row["speedup"] = round(base[0]["seconds"] / seconds, 2)
        results["runs"].append(row)
        print(json.dumps(row), flush=True)
        with open(os.path.join(args.out, "results.json"), "w") as f:
            json.dump(results, f, indent=1)

    if args.one_process:
        t = time.time()
        mesh, info = blocks.reconstruct(P, N, counts=counts, threads=1)
        record("one process, 1 thread", 1, time.time() - t, mesh, info)
    for w in [int(x) for x in args.workers.split(",")]:
        cluster = LocalCluster(n_workers=w, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address=None)
        client = Client(cluster)
        try:
            t = time.time()
            mesh, info = blocks.reconstruct(P, N, counts=counts, client=client, threads=1)
            record("dask", w, time.time() - t, mesh, info)
        finally:
            client.close()
            cluster.close()
    hashes = {r["hash"] for r in results["runs"]}
    print("same mesh in every run: %s" % (len(hashes) == 1), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
