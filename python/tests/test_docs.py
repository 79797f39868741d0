"""Every ```python block of docs/python.md and README.md runs (in a scratch folder that sees data/)."""
import os
import re
import subprocess
import sys

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def blocks():
    for doc in ("docs/python.md", "README.md"):
        text = open(os.path.join(ROOT, doc)).read()
        for k, code in enumerate(re.findall(r"\n```python\n(.*?)\n```", text, re.S)):
            yield pytest.param(code, id=f"{doc}-{k}")


@pytest.mark.parametrize("code", blocks())
def test_block_runs(code, tmp_path, data_dir):
    os.symlink(data_dir, tmp_path / "data")
    if "open3d" in code:
        pytest.importorskip("open3d")
    r = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
