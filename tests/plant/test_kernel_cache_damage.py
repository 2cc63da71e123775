"""Issue 20: a damaged numba kernel cache (a truncated entry, a truncated index) is recompiled
with one warning line instead of failing every run that loads it."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from plant import kernels

ROOT = Path(__file__).resolve().parents[2]
RUN = ("import ftcsim; r = ftcsim.run('li2023_pd', mode='inprocess', stop=0.1); "
       "print('complete' if r.complete else r.error)")


@pytest.mark.skipif(not kernels.enabled(), reason="kernels are off")
def test_a_damaged_cache_entry_is_recompiled_with_one_warning(tmp_path):
    # a copy of the warm user cache (make warm) with two of the plant kernel's entries cut short
    copy = tmp_path / "cache" / "numba"
    root = Path(kernels.cache_root())
    if root.is_dir():
        shutil.copytree(root, copy)
    env = dict(os.environ, FTCSIM_CACHE_DIR=str(tmp_path / "cache"))
    first = subprocess.run([sys.executable, "-c", RUN], cwd=ROOT, env=env, capture_output=True, text=True,
                           timeout=600)
    assert first.stdout.strip() == "complete", first.stderr  # now every kernel of the scenario is in the copy
    damaged = []
    for folder in copy.glob("plant.kernels.flexible-*"):
        for pattern in ("flexible.outputs-*.nbc", "flexible.advance-*.nbi"):
            for f in folder.glob(pattern):
                f.write_bytes(f.read_bytes()[:100])
                damaged.append(f)
    assert len(damaged) >= 2
    r = subprocess.run([sys.executable, "-c", RUN], cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert r.stdout.strip() == "complete", r.stderr
    warnings = [line for line in r.stderr.splitlines() if "numba kernel cache entry" in line]
    assert len(warnings) == 1 and "unreadable" in warnings[0] and "recompiling" in warnings[0], r.stderr
    assert "Traceback" not in r.stderr
    # the entries were written again: the next process loads them without a word
    again = subprocess.run([sys.executable, "-c", RUN], cwd=ROOT, env=env, capture_output=True, text=True,
                           timeout=600)
    assert again.stdout.strip() == "complete" and "numba kernel cache" not in again.stderr, again.stderr
