"""Issue 24: a host that loads, runs, frees and exits with our FMUs ends cleanly.

pythonfmu's stock export library released a static shared_ptr twice at exit (fmus/native/README.md):
a write into freed memory that aborted hosts in their exit path. Our FMUs carry our own
export library (fmus/native/ftcsim_export); 20 processes per FMI version (tests/fmus/exit_probe.py: each loads three of the FMUs,
instantiates, steps, terminates and frees each three times, keeps the library loaded, imports
scipy.linalg so that libgfortran's exit-time frees come after the FMUs', then ``sys.exit(0)``)
must all end with status 0. valgrind on the same probe (tests/fmus/valgrind_exit.py) is in
docs/external-tools.md; it takes minutes per process."""
import json
import os
import shutil
import subprocess
import sys
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from fmus.export_library import exit_safe, stock_library_path

pytestmark = [pytest.mark.fmu, pytest.mark.slow]

PROBE = Path(__file__).resolve().parent / "exit_probe.py"
RUNS = 20


def _probe(fmus, tmp_path):
    env = dict(os.environ, FTCSIM_KERNELS="0", TMPDIR=str(tmp_path))  # numba is not what is tested (and slow to load)
    cmd = [sys.executable, str(PROBE), "--keep-library", "--repeat", "3", "--import", "scipy.linalg", *map(str, fmus)]
    return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)


def test_every_fmu_carries_the_corrected_library(any_fmu_dir):
    fmi, folder = any_fmu_dir
    for fmu in sorted(folder.glob("*.fmu")):
        record = json.loads(zipfile.ZipFile(fmu).read("resources/ftcsim_build.json"))["export_library"]
        assert record["variant"] == "ftcsim", fmu.name


def test_twenty_plain_exits_per_fmi_version(any_fmu_dir, tmp_path):
    fmi, folder = any_fmu_dir
    fmus = sorted(folder.glob("*.fmu"))
    n = len(fmus)
    assert n >= 10
    groups = [[fmus[k % n], fmus[(k + 7) % n], fmus[(k + 13) % n]] for k in range(RUNS)]  # every FMU in 3 processes
    with ThreadPoolExecutor(2) as pool:
        done = list(pool.map(lambda g: _probe(g, tmp_path), groups))
    codes = [p.returncode for p in done]
    assert codes == [0] * RUNS, [(c, p.stderr[-800:]) for c, p in zip(codes, done) if c != 0][:2]
    assert all("ran 3 FMUs 3 times" in p.stdout for p in done)


def test_exit_safe_tells_our_library_from_the_stock_one(any_fmu_dir, tmp_path):
    """What makes ftcsim's own processes end without the teardown (orchestrator/common/process_exit.py):
    only a pythonfmu FMU whose binary is not the corrected library it records."""
    fmi, folder = any_fmu_dir
    ours = tmp_path / "ours"
    zipfile.ZipFile(folder / "PDController.fmu").extractall(ours)
    assert exit_safe(ours)
    binary = next((ours / "binaries").glob("*linux*/PDController.so"))
    stock = tmp_path / "stock"
    shutil.copytree(ours, stock)
    shutil.copyfile(stock_library_path(fmi), stock / binary.relative_to(ours))
    assert not exit_safe(stock)  # the stock binary under our record
    (stock / "resources" / "ftcsim_build.json").unlink()
    assert not exit_safe(stock)  # a third-party pythonfmu FMU
    (stock / "resources" / "slavemodule.txt").unlink()
    assert exit_safe(stock)  # not a pythonfmu FMU at all
