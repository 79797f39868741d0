"""Progress callbacks, cancellation, exceptions raised in a callback, Ctrl-C, threads."""
import os
import signal
import subprocess
import sys
import textwrap
import threading

import numpy as np
import pytest

import vitri
from conftest import sphere_constraints, sphere_points


def test_progress_is_called_with_phases():
    p, n = sphere_points(500)
    calls = []
    vitri.reconstruct(p, n, precision=0.03, progress=lambda phase, v, q: calls.append((phase, v, q)))
    phases = [c[0] for c in calls]
    assert phases[0] == "scan" and "refinement" in phases and phases[-1] == "extraction"
    assert any(v > 0 for ph, v, q in calls if ph == "refinement")


class Boom(Exception):
    pass


@pytest.mark.parametrize("where", ["scan", "fit", "refinement"])
def test_exception_in_callback_reaches_the_caller(where):
    p, n = sphere_points(400)

    def cb(phase, vertices, queued):
        if phase.startswith(where):
            raise Boom(phase)

    with pytest.raises(Boom):
        vitri.reconstruct(p, n, precision=0.03, function="global", progress=cb)


def test_false_cancels_and_the_mesher_stays_usable():
    pts, vals = sphere_constraints(100)
    m = vitri.Mesher(pts, vals)
    with pytest.raises(vitri.Cancelled):
        m.refine(0.02, relative=True, progress=lambda *a: False)
    m.refine(0.05, relative=True)  # continues
    assert len(m.mesh().faces) > 0
    with pytest.raises(vitri.Cancelled):
        vitri.mesh_constraints(pts, vals, precision=0.02, progress=lambda *a: False)


CTRL_C = textwrap.dedent("""
    import os, signal, sys, threading, time
    import numpy as np
    import vitri
    i = np.arange(20000) + 0.5
    phi = np.arccos(1 - 2 * i / len(i)); th = np.pi * (1 + 5 ** 0.5) * i
    p = np.stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)], axis=1)
    calls = []
    threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    t = time.time()
    try:
        vitri.reconstruct(p, p, precision=0.0015, progress=lambda *a: calls.append(a))
        print("finished", time.time() - t)
    except KeyboardInterrupt:
        print("interrupted", round(time.time() - t, 1), len(calls))
""")


def test_ctrl_c_interrupts_a_long_call():
    env = dict(os.environ)
    r = subprocess.run([sys.executable, "-c", CTRL_C], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("interrupted"), r.stdout + r.stderr


def test_other_threads_run_during_a_long_call():
    p, n = sphere_points(3000)
    ticks = []
    stop = threading.Event()

    def ticker():
        while not stop.is_set():
            ticks.append(1)
            stop.wait(0.005)

    t = threading.Thread(target=ticker)
    t.start()
    try:
        vitri.reconstruct(p, n, precision=0.01)
    finally:
        stop.set()
        t.join()
    assert len(ticks) > 3  # the GIL was released


def test_two_threads_two_meshers():
    pts, vals = sphere_constraints(100)
    out = [None, None]

    def work(k):
        m = vitri.Mesher(pts, vals)
        m.refine(0.04, relative=True)
        out[k] = m.mesh()

    ts = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert np.array_equal(out[0].faces, out[1].faces)
