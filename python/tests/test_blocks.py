"""vitri.blocks (docs/blocks.md): the passes' results pickled and read back unchanged, a reconstruction in
blocks in this process equal with and without spilling, and on a local Dask cluster of worker processes
equal to the one-process result, also when a worker is killed in the middle of the run.

The Dask tests need Debian's python3-distributed (tools/test.sh installs it); the cluster listens on the
loopback only.
"""
import os
import pickle
import signal
import threading
import time

import numpy as np
import pytest

import vitri
import vitri.blocks
from conftest import assert_closed_manifold, euler_characteristic, signed_volume


def torus_points(n, R=1.0, r=0.35, seed=3):
    """n points on a torus (jittered parameters: no lattice) with outward normals."""
    rng = np.random.default_rng(seed)
    u = rng.random(n) * 2 * np.pi
    v = rng.random(n) * 2 * np.pi
    c = np.stack([np.cos(u), np.sin(u), np.zeros(n)], axis=1)
    normals = np.cos(v)[:, None] * c + np.sin(v)[:, None] * np.array([0.0, 0.0, 1.0])
    return R * c + r * normals, normals


@pytest.fixture(scope="module")
def torus():
    return torus_points(6000)


@pytest.fixture(scope="module")
def one_process(torus):
    points, normals = torus
    return vitri.blocks.reconstruct(points, normals, counts=2, threads=1)


def test_one_process_mesh_is_a_closed_torus(one_process):
    mesh, info = one_process
    V, F = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    assert info["blocks"] == 8 and info["unfinished"] == 0 and info["boundary_edges"] == 0
    assert_closed_manifold(V, F)
    assert euler_characteristic(V, F) == 0
    assert signed_volume(V, F) > 0
    # On the torus: distance to the tube's core circle within a fraction of the tube radius.
    d = np.hypot(np.hypot(V[:, 0], V[:, 1]) - 1.0, V[:, 2])
    assert np.abs(d - 0.35).max() < 0.05


def test_spilled_run_equals_the_run_in_memory(torus, one_process, tmp_path):
    points, normals = torus
    spill = tmp_path / "spill"
    mesh, info = vitri.blocks.reconstruct(points, normals, counts=2, threads=1, spill=str(spill))
    assert info["spilled_bytes"] > 0
    assert not spill.exists()  # created by the run, removed at its end
    assert np.array_equal(mesh.vertices, one_process[0].vertices)
    assert np.array_equal(mesh.faces, one_process[0].faces)


def test_pass_results_pickle_unchanged(torus):
    points, normals = torus
    plan = vitri._vitri.plan_blocks(points, (2, 1, 1))
    plan2 = pickle.loads(pickle.dumps(plan))
    assert plan2.counts == plan.counts and plan2.spacing == plan.spacing and plan2.domain == plan.domain
    idx = plan.block_points(0, points)
    assert 0 < len(idx) < len(points) and np.all(np.diff(idx.astype(np.int64)) > 0)
    seeds = vitri._vitri.refine_block(plan, 0, points[idx], normals[idx], threads=1)
    back = pickle.loads(pickle.dumps(seeds))
    for name in ("points", "values", "gradients", "ids"):
        assert np.array_equal(getattr(back, name), getattr(seeds, name)), name
    assert back.precision == seeds.precision and back.prepared_count == seeds.prepared_count
    # Every owned vertex lies on the block's side of the split (the outer faces of a cell are open), ids
    # are the block's.
    lo, hi = map(np.asarray, plan.cell(0))
    assert len(seeds.points) > 0 and np.all(seeds.points[:, 0] < hi[0])
    assert np.all((seeds.ids >> np.uint64(36)) == 0)
    turned = seeds.turned_over()
    assert np.array_equal(turned.values, -seeds.values) and turned.flipped != seeds.flipped
    surface = vitri._vitri.extract_block(plan, 0, [seeds, None], 4 * seeds.precision)
    again = pickle.loads(pickle.dumps(surface))
    assert (again.crossings, again.triangles, again.unfinished) == (surface.crossings, surface.triangles,
                                                                     surface.unfinished)


def test_damaged_encodings_are_refused(torus):
    points, _ = torus
    plan = vitri._vitri.plan_blocks(points, 2)
    state = plan.__getstate__()
    cls = vitri._vitri.BlockPlan
    with pytest.raises(vitri.InvalidArgument, match="truncated"):
        obj = cls.__new__(cls)
        obj.__setstate__(state[:-3])
    with pytest.raises(vitri.InvalidArgument, match="magic"):
        obj = cls.__new__(cls)
        obj.__setstate__(b"XXXX" + state[4:])
    seeds_cls = vitri._vitri.BlockSeeds
    with pytest.raises(vitri.InvalidArgument, match="block plan"):
        obj = seeds_cls.__new__(seeds_cls)
        obj.__setstate__(state)  # a plan's bytes are not seeds


def test_bad_arguments(torus):
    points, normals = torus
    with pytest.raises(vitri.InvalidArgument, match="counts"):
        vitri.blocks.reconstruct(points, normals, counts=(2, 2))
    with pytest.raises(vitri.InvalidArgument, match="normals"):
        vitri.blocks.reconstruct(points, normals[:10], counts=2)
    with pytest.raises(vitri.InvalidArgument, match="quality"):
        vitri.blocks.reconstruct(points, normals, counts=2, min_angle=25)


# ---- Dask distributed ---------------------------------------------------------------------------------

distributed = pytest.importorskip("distributed")


@pytest.fixture
def cluster():
    from distributed import Client, LocalCluster

    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                     dashboard_address=None, silence_logs=50)
    client = Client(c)
    try:
        yield client
    finally:
        client.close()
        c.close()


def test_dask_run_equals_one_process(cluster, torus, one_process):
    points, normals = torus
    mesh, info = vitri.blocks.reconstruct(points, normals, counts=2, threads=1, client=cluster)
    assert info["blocks"] == 8 and info["unfinished"] == 0
    assert np.array_equal(mesh.vertices, one_process[0].vertices)
    assert np.array_equal(mesh.faces, one_process[0].faces)
    assert np.array_equal(mesh.normals, one_process[0].normals)


def test_dask_run_with_a_block_that_sees_no_point(cluster):
    """Two spheres 20 radii apart in a 3 x 1 x 1 split: the middle block sees no point, not even in its
    halo (a fine split of a real model has such cells: 10^5 elephant samples in 4 x 4 x 2 have two). Its
    pass-1 task returns an empty result, as mesh_in_blocks does in one process; the cluster's mesh is the
    one-process mesh, two closed spheres."""
    a, na = sphere_points(2500, (0.0, 0.0, 0.0), seed=5)
    b, nb = sphere_points(2500, (20.0, 0.0, 0.0), seed=6)
    points, normals = np.vstack([a, b]), np.vstack([na, nb])
    plan = vitri._vitri.plan_blocks(points, (3, 1, 1))
    assert len(plan.block_points(1, points)) == 0
    one, info1 = vitri.blocks.reconstruct(points, normals, counts=(3, 1, 1), threads=1)
    mesh, info = vitri.blocks.reconstruct(points, normals, counts=(3, 1, 1), threads=1, client=cluster)
    V, F = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    assert_closed_manifold(V, F)
    assert euler_characteristic(V, F) == 4  # two spheres
    assert np.array_equal(mesh.vertices, one.vertices)
    assert np.array_equal(mesh.faces, one.faces)


def sphere_points(n, centre, seed):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    return np.asarray(centre) + d, d


def test_dask_run_survives_a_killed_worker(cluster, torus, one_process):
    """A worker holding pass-1 results is killed (SIGKILL) while the run goes on: the scheduler computes
    what it held again on the other worker (and the nanny's new one); the mesh is the one-process mesh."""
    points, normals = torus
    result, error = {}, []

    def run():
        try:
            result["mesh"], result["info"] = vitri.blocks.reconstruct(points, normals, counts=2, threads=1,
                                                                      client=cluster)
        except BaseException as e:  # reported below, in the test's thread
            error.append(e)

    worker_pids = cluster.run(os.getpid)  # address -> pid of the worker processes
    thread = threading.Thread(target=run)
    thread.start()
    victim = None
    deadline = time.time() + 300
    while victim is None and time.time() < deadline and thread.is_alive():
        held = cluster.who_has()
        for key, where in held.items():
            if str(key).startswith("vitri-refine-") and where:
                victim = where[0]
                break
        time.sleep(0.02)
    assert victim is not None, "no pass-1 result was seen on a worker before the run ended"
    stitched_before = any(str(k).startswith("vitri-stitch") for k, w in cluster.who_has().items() if w)
    os.kill(worker_pids[victim], signal.SIGKILL)
    thread.join(timeout=600)
    assert not thread.is_alive(), "the run did not finish after the worker was killed"
    if error:
        raise error[0]
    assert not stitched_before, "the worker was killed after the run's last task"
    assert victim not in cluster.scheduler_info()["workers"], "the killed worker is still registered"
    mesh = result["mesh"]
    assert np.array_equal(mesh.vertices, one_process[0].vertices)
    assert np.array_equal(mesh.faces, one_process[0].faces)


def test_command_line_local_cluster(tmp_path, torus, one_process):
    points, normals = torus
    src = tmp_path / "torus.xyz"
    np.savetxt(src, np.hstack([points, normals]), fmt="%.17g")
    out = tmp_path / "torus.ply"
    assert vitri.blocks.main([str(src), "-o", str(out), "--blocks", "2", "--local", "2"]) == 0
    mesh = vitri.read(str(out))
    # The file's mesh is the one-process mesh of the same points (the text keeps every bit: %.17g).
    assert np.array_equal(np.asarray(mesh.faces), np.asarray(one_process[0].faces))
    assert np.allclose(mesh.vertices, one_process[0].vertices, atol=1e-6)


def test_misaligned_arrays_are_read(torus):
    """Arrays at odd addresses (what pickle protocol 5's out-of-band buffers give Dask's workers) are read
    as any other: the same plan's blocks."""
    points, _ = torus
    raw = bytearray(points.nbytes + 1)
    odd = np.frombuffer(raw, dtype=np.float64, count=points.size, offset=1).reshape(points.shape)
    odd[:] = points
    assert not odd.flags.aligned
    a = vitri._vitri.plan_blocks(points, 2)
    b = vitri._vitri.plan_blocks(odd, 2)
    assert a.spacing == b.spacing and a.domain == b.domain
    assert np.array_equal(a.block_points(3, points), b.block_points(3, odd))
