"""Campaigns on a cluster started apart, as a lab runs one (issue 25): `dask scheduler
--scheduler-file` and `dask worker` processes started from a folder outside the project (127.0.0.1
only), a shipped campaign (shortened) through `--scheduler-file`, a worker killed part way, a
``distributed.Client`` given to ``ftcsim.campaign``, and a worker that has no FMU on its disk."""
import copy
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

import ftcsim
from orchestrator.campaign.run import run_campaign
from orchestrator.campaign.store import EXECUTION_COLUMNS, SUMMARY

ROOT = Path(__file__).resolve().parents[2]
DASK = str(Path(sys.executable).parent / "dask")
EXECUTION = list(EXECUTION_COLUMNS)


def shortened(tmp_path, runs=2, stop=4.0, fmu_dir=None) -> Path:
    """campaigns/li2023_methods.toml (3 methods, 7 dispersions, settling, trajectories) with fewer
    draws and a shorter stop, next to nothing else."""
    text = (ROOT / "campaigns" / "li2023_methods.toml").read_text(encoding="utf-8")
    text = text.replace("runs = 200", f"runs = {runs}").replace('mode = "fmu"', f'mode = "fmu"\nstop = {stop}')
    text = text.replace("from = 80.0", "from = 0.0")
    if fmu_dir is not None:
        text = text.replace('mode = "fmu"', f'mode = "fmu"\nfmu_dir = "{fmu_dir}"')
    p = tmp_path / "li2023_methods.toml"
    p.write_text(text, encoding="utf-8")
    return p


class Cluster:
    """A scheduler and workers as separate processes, started in ``folder`` (outside the project)."""

    def __init__(self, folder: Path):
        self.folder = folder
        folder.mkdir(parents=True, exist_ok=True)
        self.file = folder / "scheduler.json"
        self.procs = []
        self.scheduler = self._start([DASK, "scheduler", "--scheduler-file", str(self.file), "--host", "127.0.0.1",
                                      "--port", "0", "--no-dashboard"])
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not self._address():
            time.sleep(0.1)
        assert self._address(), "the scheduler did not write its file"

    def _address(self):
        try:
            return json.loads(self.file.read_text())["address"]
        except (OSError, ValueError, KeyError):
            return None

    def _start(self, argv, env=None):
        p = subprocess.Popen(argv, cwd=self.folder, env=env or _env(), stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL, start_new_session=True)
        self.procs.append(p)
        return p

    def worker(self, name, wrap=()):
        """A worker without nanny (SIGKILL kills it), one thread, its folder empty."""
        d = self.folder / name
        d.mkdir()
        return self._start([*wrap, DASK, "worker", "--scheduler-file", str(self.file), "--nthreads", "1", "--no-nanny",
                            "--host", "127.0.0.1", "--no-dashboard", "--local-directory", str(d), "--name", name])

    def wait_for_workers(self, n):
        from distributed import Client

        with Client(scheduler_file=str(self.file), timeout=60, set_as_default=False) as c:
            c.wait_for_workers(n, timeout=120)

    def close(self):
        for p in self.procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
            p.wait()


def _env():
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "FTCSIM_FMU_DIR")}
    return env


@pytest.fixture(scope="module")
def serial_reference(tmp_path_factory, fmu_dir):
    """The shortened shipped campaign with --workers 0 (in this process, without Dask)."""
    tmp = tmp_path_factory.mktemp("serial")
    path = shortened(tmp)
    o = run_campaign(path, tmp / "serial", workers=0)
    assert o.stored == o.total == 6 and o.failed == 0
    return path.read_text(), pd.read_parquet(tmp / "serial" / SUMMARY)


def _same_results(df, reference):
    assert list(df.run_id) == list(reference.run_id)
    pd.testing.assert_frame_equal(df.drop(columns=EXECUTION), reference.drop(columns=EXECUTION))


@pytest.mark.fmu
@pytest.mark.slow
def test_a_client_object_runs_a_campaign_and_leaves_dask_config_as_it_was(tmp_path, serial_reference):
    import dask
    from distributed import Client

    text, reference = serial_reference
    path = tmp_path / "li2023_methods.toml"
    path.write_text(text)
    cluster = Cluster(tmp_path / "cluster")
    try:
        cluster.worker("w1")
        cluster.wait_for_workers(1)
        before = copy.deepcopy(dask.config.config)
        with Client(scheduler_file=str(cluster.file), set_as_default=False) as client:
            df = ftcsim.campaign(path, tmp_path / "out", client=client)
            assert client.status == "running"  # the caller's client stays open
            left = client.run(lambda dask_worker: [p for p in os.listdir(dask_worker.local_directory)
                                                   if p.startswith("ftcsim-inputs")])
            assert list(left.values()) == [[]]  # what was shipped to the worker is removed at the end
        assert dask.config.config == before
    finally:
        cluster.close()
    _same_results(df, reference)


@pytest.mark.fmu
@pytest.mark.slow
def test_scheduler_file_cluster_with_a_worker_killed_part_way_stores_every_run_once(tmp_path, serial_reference):
    text, reference = serial_reference
    path = tmp_path / "li2023_methods.toml"
    path.write_text(text)
    cluster = Cluster(tmp_path / "cluster")
    out = tmp_path / "out"
    try:
        victim = cluster.worker("w1")
        cluster.worker("w2")
        cluster.wait_for_workers(2)
        p = subprocess.Popen([sys.executable, "-m", "orchestrator.cli", "campaign", str(path), "--out", str(out),
                              "--scheduler-file", str(cluster.file), "--batch", "1", "--progress-every", "1"],
                             cwd=ROOT, env=dict(_env(), PYTHONUNBUFFERED="1"), stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 300
        while p.poll() is None and time.monotonic() < deadline and not list(out.glob("runs/*.parquet")):
            time.sleep(0.05)
        stored_at_kill = len(list(out.glob("runs/*.parquet")))
        running = p.poll() is None
        os.kill(victim.pid, signal.SIGKILL)
        stdout, stderr = p.communicate(timeout=600)
    finally:
        cluster.close()
    assert running and stored_at_kill < 6  # killed part way
    assert p.returncode == 0, stderr
    assert "Traceback" not in stderr and "\r" not in stderr  # plain lines in a log file, no bar
    assert "runs done" in stderr and "6 of 6 runs stored" in stdout
    files = sorted(f.name for f in (out / "runs").iterdir())
    assert len(files) == 6 and len({f.split("-")[0] for f in files}) == 6  # every run stored once
    df = pd.read_parquet(out / SUMMARY)
    _same_results(df, reference)


@pytest.mark.fmu
@pytest.mark.slow
def test_a_worker_without_the_fmus_on_its_disk_completes_runs(tmp_path, fmu_dir):
    """The campaign's FMUs lie in a folder that the worker's own mount namespace covers with an empty
    tmpfs: it sees no FMU, and runs on the copies shipped to it (checked by SHA-256)."""
    if shutil.which("unshare") is None or subprocess.run(
            ["unshare", "--mount", "true"], capture_output=True).returncode != 0:
        pytest.skip("needs unshare --mount (root or user namespaces) to hide the FMUs from one process")
    fmus = tmp_path / "fmus"
    fmus.mkdir()
    for model in ("FlexibleSpacecraft", "PDController", "FAFEO", "AISMC", "FASMC"):
        shutil.copy2(fmu_dir / f"{model}.fmu", fmus / f"{model}.fmu")
    path = shortened(tmp_path, runs=1, stop=1.0, fmu_dir=fmus)
    cluster = Cluster(tmp_path / "cluster")
    try:
        cluster.worker("w1", wrap=["unshare", "--mount", "sh", "-c", f'mount -t tmpfs none "{fmus}" && exec "$0" "$@"'])
        cluster.wait_for_workers(1)
        from distributed import Client

        with Client(scheduler_file=str(cluster.file), set_as_default=False) as client:
            (seen,) = client.run(lambda: sorted(os.listdir(str(fmus)))).values()
        assert seen == []  # the worker has no FMU on its disk
        o = run_campaign(path, tmp_path / "out", scheduler_file=cluster.file)
    finally:
        cluster.close()
    df = pd.read_parquet(tmp_path / "out" / SUMMARY)
    assert (o.stored, o.failed) == (3, 0), list(df.error)
    assert set(df.status) == {"ok"} and df.final_attitude_error.notna().all()
