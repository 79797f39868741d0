"""vitri.blocks: a scan reconstructed in blocks (docs/blocks.md), in this process or as the tasks of a
Dask distributed cluster.

    import vitri.blocks
    mesh, info = vitri.blocks.reconstruct(points, normals, counts=4)             # in this process
    from dask.distributed import Client
    mesh, info = vitri.blocks.reconstruct(points, normals, counts=4,
                                          client=Client("tcp://scheduler:8786"))  # on a cluster

Both give the same mesh, bit for bit, as ``vitri mesh --blocks 4x4x4`` (the library's mesh_in_blocks):
each pass is a pure function of what it is given (vitri/blocks.hpp), its results pickled with the
library's binary encodings, so that Dask may run a task again on another worker when one is lost.

The task graph (one task per block and pass; B the blocks, the arrows what each task reads):
    refine[b]   <- the points within the data halo of cell b (sent by the client)
    halo[b]     <- refine[b]                    (what the other blocks' votes read of b)
    votes[b]    <- refine[b], halo[c] for the blocks c near b
    flips       <- votes[*]                     (one small task: the orientation's spanning tree)
    border[b]   <- refine[b]                    (the owned vertices within the merge halo of b's faces)
    extract[b]  <- refine[b], border[c] for the blocks c near b, flips
    prepared[b] <- refine[b], flips
    stitch      <- extract[*], prepared[*]      (one task: the seams joined, the scan's finishing)
The client waits for the blocks' precisions after pass 1 (the merge halo is 4 x the largest of them,
up to 64 x in a block's later rounds)
and holds the futures until the end, so that the scheduler can recompute what a lost worker held.

Run from a shell (docs/blocks.md "On a cluster"):
    python3 -m vitri.blocks scan.ply -o out.ply --blocks 4 --scheduler tcp://host:8786
    python3 -m vitri.blocks scan.ply -o out.ply --blocks 2 --local 4      # a local cluster of 4 workers
"""

import numpy as np

from . import _vitri
from ._vitri import BlockPlan, BlockSeeds, BlockSurface  # noqa: F401  (re-exported)

#: The merge halo in units of the largest block precision (BlockOptions::merge_halo_precisions), and the
#: largest a block's later rounds may take (max_merge_halo_precisions: the borders' width): the library's.
MERGE_HALO_PRECISIONS = _vitri.BLOCK_MERGE_HALO_PRECISIONS
MAX_MERGE_HALO_PRECISIONS = _vitri.BLOCK_MAX_MERGE_HALO_PRECISIONS

__all__ = ["reconstruct", "BlockPlan", "BlockSeeds", "BlockSurface", "MERGE_HALO_PRECISIONS"]


def _counts(counts):
    if isinstance(counts, (int, np.integer)):
        c = (int(counts),) * 3
    else:
        c = tuple(int(x) for x in counts)
    if len(c) != 3 or any(x < 1 or x > 64 for x in c):
        raise _vitri.InvalidArgument("counts: an integer or three integers from 1 to 64, got %r" % (counts,))
    return c


def _absolute_precision(points, precision):
    if precision is None:
        return 0.0
    p = float(precision)
    if not (p > 0 and np.isfinite(p)):
        raise _vitri.InvalidArgument("precision must be positive and finite, got %r" % (precision,))
    return p * float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


# ---- Tasks (module-level functions: Dask pickles them by reference) ----------------------------------

def _refine(plan, block, points, normals, precision, options):
    return _vitri.refine_block(plan, block, points, normals, precision, **options)


def _halo(seeds):
    return seeds.halo_only()


def _precision(seeds):
    return seeds.precision, seeds.prepared_count


def _votes(plan, seeds, *others):
    return np.asarray(_vitri.block_votes(plan, seeds, list(others)))


def _flips(counts, *rows):
    return list(_vitri.block_flips([list(r) for r in rows], list(counts)))


def _border(plan, seeds, merge_halo):
    return seeds.border(plan, merge_halo)


def _extract(plan, block, merge_halo, max_merge_halo, flips, nblocks, near, own, *borders):
    view = [None] * nblocks
    for c, s in zip(near, borders):
        view[c] = s.turned_over() if flips[c] else s
    view[block] = own.turned_over() if flips[block] else own
    return _vitri.extract_block(plan, block, view, merge_halo, max_merge_halo)


def _prepared(seeds, flips):
    part = seeds.prepared_part()
    return part.turned_over() if flips[seeds.block] else part


def _stitch(surface, threads, nblocks, *parts):
    surfaces, prepared = list(parts[:nblocks]), list(parts[nblocks:])
    mesh, stats = _vitri.stitch_blocks(surfaces, prepared, surface, threads)
    vertices, faces, normals = mesh
    return vertices, faces, normals, stats


# ---- The run ---------------------------------------------------------------------------------------------

def reconstruct(points, normals=None, *, counts=2, precision=None, client=None, surface="auto", spill=None,
                **options):
    """A scan meshed in counts[0] x counts[1] x counts[2] blocks (docs/blocks.md).

    points: (n, 3) array; normals: (n, 3) array or None (unoriented: oriented once on all the points, as
    the CLI does). counts: blocks per axis (an integer or three). precision: relative to the diagonal of
    the points' box (None: each block's data resolution). client: a dask.distributed.Client (None: this
    process, the library's mesh_in_blocks; `spill` then names a directory where the blocks' results wait
    between the passes). surface: 'closed', 'open' or 'auto'. The other options are reconstruct()'s scan
    options (function, smoothing, offset, sides, off_surface_spacing, neighbours, viewpoint, threads,
    max_vertices, memory); the quality mode and certify do not apply.

    Returns (Mesh, info): info a dict (blocks, flipped, boundary_edges before the finishing, precision,
    open, ...).
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise _vitri.InvalidArgument("points: expected an (n, 3) array, got shape %r" % (points.shape,))
    if normals is not None:
        normals = np.ascontiguousarray(normals, dtype=np.float64)
        if normals.shape != points.shape:
            raise _vitri.InvalidArgument("normals: expected shape %r, got %r" % (points.shape, normals.shape))
    counts = _counts(counts)
    absolute = _absolute_precision(points, precision)
    if client is None:
        return _vitri.mesh_in_blocks(points, normals, counts, absolute, spill or "", surface=surface, **options)
    if spill:
        raise _vitri.InvalidArgument("spill: the cluster's workers keep the blocks' results (Dask spills them "
                                     "itself under memory pressure); not with client")
    return _run_dask(client, points, normals, counts, absolute, surface, options)


def _run_dask(client, points, normals, counts, absolute, surface, options):
    threads = int(options.get("threads") or 0)
    # Unoriented points without a viewpoint: oriented once, here (as mesh_in_blocks does).
    if normals is None and options.get("viewpoint") is None:
        normals = _vitri.orient_for_blocks(points, **options)
    plan = _vitri.plan_blocks(points, counts)
    nb = plan.size
    refine = []
    for b in range(nb):
        idx = plan.block_points(b, points)
        p = points[idx]
        n = normals[idx] if normals is not None else None
        refine.append(client.submit(_refine, plan, b, p, n, absolute, options, key="vitri-refine-%d" % b,
                                    pure=False))
    # The blocks' precisions decide the merge halo: the one synchronization of the client.
    sizes = client.gather([client.submit(_precision, f, key="vitri-precision-%d" % b, pure=False)
                           for b, f in enumerate(refine)])
    max_precision = max(s[0] for s in sizes)
    if not max_precision > 0:
        raise _vitri.InvalidArgument("mesh in blocks: no block found a surface in %d points" % len(points))
    merge_halo = MERGE_HALO_PRECISIONS * max_precision
    max_merge_halo = max(merge_halo, MAX_MERGE_HALO_PRECISIONS * max_precision)
    prepared_counts = [s[1] for s in sizes]
    halo = [client.submit(_halo, f, key="vitri-halo-%d" % b, pure=False) for b, f in enumerate(refine)]
    votes = []
    for b in range(nb):
        near = [c for c in plan.cells_near(b, plan.data_halo) if c != b]
        votes.append(client.submit(_votes, plan, refine[b], *[halo[c] for c in near], key="vitri-votes-%d" % b,
                                   pure=False))
    flips = client.submit(_flips, prepared_counts, *votes, key="vitri-flips", pure=False)
    border = [client.submit(_border, plan, f, max_merge_halo, key="vitri-border-%d" % b, pure=False)
              for b, f in enumerate(refine)]
    surfaces = []
    for b in range(nb):
        near = [c for c in plan.cells_near(b, max_merge_halo) if c != b]
        surfaces.append(client.submit(_extract, plan, b, merge_halo, max_merge_halo, flips, nb, near, refine[b],
                                      *[border[c] for c in near], key="vitri-extract-%d" % b, pure=False))
    prepared = [client.submit(_prepared, f, flips, key="vitri-prepared-%d" % b, pure=False)
                for b, f in enumerate(refine)]
    final = client.submit(_stitch, surface, threads, nb, *surfaces, *prepared, key="vitri-stitch", pure=False)
    vertices, faces, mesh_normals, stats = final.result()
    flip_list = flips.result()
    info = dict(stats)
    info["blocks"] = nb
    info["flipped"] = int(sum(bool(f) for f in flip_list))
    info["unfinished"] = int(sum(s.unfinished for s in client.gather(surfaces)))
    return _vitri.Mesh(vertices, faces, mesh_normals), info


def main(argv=None):
    """python3 -m vitri.blocks INPUT -o OUT [--blocks N|NxMxK] [--scheduler ADDRESS | --local N] ..."""
    import argparse
    import sys
    import time

    ap = argparse.ArgumentParser(prog="python3 -m vitri.blocks",
                                 description="A scan meshed in blocks on a Dask cluster (docs/blocks.md).")
    ap.add_argument("input", help="points: .xyz, .pwn, .ply, .pcd (as vitri mesh reads them)")
    ap.add_argument("-o", "--output", required=True, help="the mesh: .ply, .obj or .off")
    ap.add_argument("--blocks", default="2", help="N or NxMxK blocks (default 2: 2x2x2)")
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    where.add_argument("--local", type=int, metavar="N",
                       help="start a local cluster of N worker processes on this machine (loopback only)")
    ap.add_argument("--precision", type=float, help="relative to the diagonal (default: the data's)")
    ap.add_argument("--surface", default="auto", choices=["closed", "open", "auto"])
    ap.add_argument("--threads", type=int, default=1, help="threads per block task (default 1)")
    args = ap.parse_args(argv)

    counts = [int(x) for x in args.blocks.lower().split("x")]
    if len(counts) == 1:
        counts = counts * 3
    data = _vitri.read(args.input)
    if getattr(data, "kind", None) != "points":
        sys.exit("vitri.blocks: %s: blocks mesh points (a scan)" % args.input)
    if getattr(data, "sensors", None) is not None:
        sys.exit("vitri.blocks: %s: per-point sensor positions are not supported by the distributed run; "
                 "use vitri mesh --blocks" % args.input)
    options = {"threads": args.threads}
    if getattr(data, "viewpoint", None) is not None:
        options["viewpoint"] = data.viewpoint
    t0 = time.time()
    client = cluster = None
    if args.scheduler or args.local:
        from dask.distributed import Client, LocalCluster
        if args.scheduler:
            client = Client(args.scheduler)
        else:
            cluster = LocalCluster(n_workers=args.local, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None)
            client = Client(cluster)
    try:
        mesh, info = reconstruct(data.points, data.normals, counts=counts, precision=args.precision,
                                 client=client, surface=args.surface, **options)
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    _vitri.write(args.output, mesh)
    print("%s: %d points in %d blocks: %d vertices, %d triangles -> %s (%.1f s)"
          % (args.input, len(data.points), info["blocks"], len(mesh.vertices), len(mesh.faces), args.output,
             time.time() - t0))
    if info.get("unfinished") or info.get("boundary_edges"):
        print("warning: %d transverse tetrahedra uncertified, %d boundary edges before the finishing"
              % (info.get("unfinished", 0), info.get("boundary_edges", 0)), file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
