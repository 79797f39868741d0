"""A loop of 1000 small reconstructions does not grow the process's memory (run in a subprocess, so that
the suite's other allocations do not count)."""
import os
import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent("""
    import numpy as np, vitri
    def rss_kb():
        with open("/proc/self/status") as f:
            return next(int(l.split()[1]) for l in f if l.startswith("VmRSS:"))
    i = np.arange(60) + 0.5
    phi = np.arccos(1 - 2 * i / len(i)); th = np.pi * (1 + 5 ** 0.5) * i
    p = np.stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)], axis=1)
    def once():
        m = vitri.reconstruct(p, p, precision=0.3, threads=1)  # about 300 triangles
        assert len(m.faces) > 0
    for _ in range(100):
        once()
    before = rss_kb()
    for _ in range(1000):
        once()
    print(before, rss_kb())
""")


def test_1000_reconstructions_do_not_grow_memory():
    env = dict(os.environ)
    if env.get("VITRI_SANITIZED"):  # ASan's quarantine holds freed blocks: keep it small for this check
        env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":quarantine_size_mb=1:thread_local_quarantine_size_kb=64"
    r = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    before, after = map(int, r.stdout.split())
    assert after - before < 8 * 1024, f"RSS grew from {before} kB to {after} kB"
