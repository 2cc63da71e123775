"""Bad cluster input (issue 20): malformed scheduler addresses and files, conflicting options, a
silent TCP peer, a scheduler without workers, too many local workers, a run that kills its worker:
one line naming the option and the problem, exit 2, no traceback, nothing written."""
import json
import os
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

import ftcsim
from orchestrator.campaign.cluster import cores
from orchestrator.cli.main import main
from orchestrator.common.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
CAMPAIGN = """
[campaign]
scenario = "li2023_pd"
mode = "inprocess"
runs = {runs}
seed = 5
stop = {stop}

[dispersions."plant.fault_scale"]
distribution = "uniform"
low = 0.2
high = 1.5
"""


@pytest.fixture
def campaign(tmp_path):
    p = tmp_path / "c.toml"
    p.write_text(CAMPAIGN.format(runs=2, stop=0.1), encoding="utf-8")
    return p


def _scheduler_file(tmp_path, content):
    p = tmp_path / "scheduler.json"
    p.write_text(content, encoding="utf-8")
    return str(p)


CASES = {
    "empty address": (lambda t: ["--scheduler", ""], "--scheduler", "expected a scheduler address"),
    "no host": (lambda t: ["--scheduler", "tcp://"], "--scheduler", "expected tcp://host:port"),
    "no port": (lambda t: ["--scheduler", "tcp://127.0.0.1"], "--scheduler", "expected tcp://host:port"),
    "port not a number": (lambda t: ["--scheduler", "tcp://127.0.0.1:http"], "--scheduler", "port must be a number"),
    "port out of range": (lambda t: ["--scheduler", "tcp://127.0.0.1:99999"], "--scheduler", "port must be a number"),
    "unknown protocol": (lambda t: ["--scheduler", "udp://127.0.0.1:8786"], "--scheduler", "unknown protocol 'udp'"),
    "space in address": (lambda t: ["--scheduler", "tcp://127.0.0.1 :8786"], "--scheduler", "expected a scheduler"),
    "control character": (lambda t: ["--scheduler", "tcp://127.0.0.1:87\x0086"], "--scheduler", "expected a scheduler"),
    "path in address": (lambda t: ["--scheduler", "tcp://127.0.0.1:8786/x"], "--scheduler", "expected tcp://host:port"),
    "scheduler file missing": (lambda t: ["--scheduler-file", str(t / "none.json")], "--scheduler-file",
                               "scheduler file not found"),
    "scheduler file not JSON": (lambda t: ["--scheduler-file", _scheduler_file(t, "address: x")], "--scheduler-file",
                                "not a Dask scheduler file"),
    "scheduler file without address": (lambda t: ["--scheduler-file", _scheduler_file(t, json.dumps({"id": 1}))],
                                       "--scheduler-file", "no \"address\""),
    "scheduler file with a bad address": (
        lambda t: ["--scheduler-file", _scheduler_file(t, json.dumps({"address": "tcp://host:0"}))],
        "--scheduler-file", "port must be a number"),
    "scheduler file is a folder": (lambda t: ["--scheduler-file", str(t)], "--scheduler-file",
                                   "not a Dask scheduler file"),
    "scheduler and scheduler file": (lambda t: ["--scheduler", "tcp://127.0.0.1:9", "--scheduler-file", "f.json"],
                                     "--scheduler-file", "not both"),
    "workers and scheduler": (lambda t: ["--workers", "2", "--scheduler", "tcp://127.0.0.1:9"], "--workers",
                              "not both"),
    "negative workers": (lambda t: ["--workers", "-1"], "--workers", "must be >= 0"),
    "more workers than cores": (lambda t: ["--workers", str(cores() + 5)], "--workers", "--force-workers"),
    "zero connect timeout": (lambda t: ["--scheduler", "tcp://127.0.0.1:9", "--connect-timeout", "0"],
                             "--connect-timeout", "must be > 0"),
    "NaN connect timeout": (lambda t: ["--scheduler", "tcp://127.0.0.1:9", "--connect-timeout", "nan"],
                            "--connect-timeout", "must be > 0"),
    "negative worker wait": (lambda t: ["--wait-workers", "-1"], "--wait-workers", "must be > 0"),
    "zero batch": (lambda t: ["--batch", "0"], "--batch", "must be 1..10000"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_bad_cluster_option_is_one_line_exit_2_and_nothing_written(name, campaign, tmp_path, capsys):
    args, key, problem = CASES[name]
    out = tmp_path / "out"
    status = main(["campaign", str(campaign), "--out", str(out), "--quiet", *args(tmp_path)])
    err = capsys.readouterr().err
    lines = [x for x in err.strip().splitlines() if x]
    assert status == 2, err
    assert len(lines) == 1 and f"{key}: " in lines[0] and problem in lines[0], err
    assert "Traceback" not in err and not out.exists()


@pytest.mark.parametrize("args", [["--scheduler", "tcp://"], ["--scheduler-file", "missing.json"],
                                  ["--workers", "2", "--scheduler", "tcp://127.0.0.1:9"]])
def test_compare_takes_the_same_cluster_options(args, tmp_path, capsys):
    out = tmp_path / "out"
    status = main(["compare", str(tmp_path / "mine.fmu"), "--out", str(out), "--quiet", *args])
    err = capsys.readouterr().err
    assert status == 2 and len(err.strip().splitlines()) == 1 and ("--scheduler" in err or "--workers" in err), err
    assert not out.exists()


@pytest.mark.parametrize("kw, key", [({"client": "tcp://127.0.0.1:9"}, "client"), ({"cluster": object()}, "cluster"),
                                     ({"client": None, "cluster": None, "scheduler": "tcp://127.0.0.1:9",
                                       "scheduler_file": "f.json"}, "scheduler_file")])
def test_the_api_refuses_what_is_not_a_cluster(kw, key, campaign, tmp_path):
    with pytest.raises(InputError) as e:
        ftcsim.campaign(campaign, tmp_path / "out", **kw)
    assert e.value.key == key
    assert not (tmp_path / "out").exists()


def _silent_server():
    """A TCP server that accepts connections and never sends a byte."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    held = []

    def accept():
        while True:
            try:
                held.append(srv.accept()[0])
            except OSError:
                return

    threading.Thread(target=accept, daemon=True).start()
    return srv, held


def test_a_silent_peer_is_given_up_after_the_connect_timeout(campaign, tmp_path, capsys):
    srv, held = _silent_server()
    try:
        t = time.monotonic()
        status = main(["campaign", str(campaign), "--out", str(tmp_path / "out"), "--quiet",
                       "--scheduler", f"tcp://127.0.0.1:{srv.getsockname()[1]}", "--connect-timeout", "1.5"])
        elapsed = time.monotonic() - t
    finally:
        srv.close()
        for c in held:
            c.close()
    err = capsys.readouterr().err
    assert status == 2 and held, err  # it did connect, and then waited for the scheduler's greeting
    assert elapsed < 30, elapsed  # 1.5 s, generous under load (Dask's own connect waited forever)
    assert "accepted the connection but did not answer within 1.5 s" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def _dask(*args, cwd):
    return subprocess.Popen([str(Path(sys.executable).parent / "dask"), *args], cwd=cwd, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)


def _wait_for(path: Path, timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.is_file() and path.stat().st_size:
            try:
                return json.loads(path.read_text())["address"]
            except (ValueError, KeyError):
                pass
        time.sleep(0.1)
    raise AssertionError(f"no scheduler file {path} after {timeout} s")


def test_a_scheduler_without_workers_is_a_warning_then_exit_2(campaign, tmp_path):
    here = tmp_path / "cluster"
    here.mkdir()
    sched = _dask("scheduler", "--scheduler-file", "s.json", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                  cwd=here)
    try:
        _wait_for(here / "s.json")
        t = time.monotonic()
        r = subprocess.run([sys.executable, "-m", "orchestrator.cli", "campaign", str(campaign), "--out",
                            str(tmp_path / "out"), "--scheduler-file", str(here / "s.json"), "--wait-workers", "2"],
                           cwd=ROOT, capture_output=True, text=True, timeout=300)
        elapsed = time.monotonic() - t
    finally:
        sched.kill()
        sched.wait()
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 2, r.stderr
    assert "has no workers; waiting up to 2 s" in lines[0]
    assert "--scheduler: no worker joined the scheduler" in lines[1] and "within 2 s" in lines[1]
    assert elapsed < 120 and "Traceback" not in r.stderr
    assert not (tmp_path / "out").exists()


def _crash_on_run_1(specs):
    from orchestrator.campaign.worker import execute_batch

    if any(s.run_id == 1 for s in specs):
        os._exit(3)  # as a segfaulting FMU does: the worker process dies
    return execute_batch(specs)


def test_a_run_that_kills_its_worker_is_stored_failed_after_bounded_tries(tmp_path, monkeypatch):
    """Batched with run 0 and 2, run 1 kills every worker that tries it: the batch is split, runs
    0 and 2 are stored ok, run 1 failed with its reason (KilledWorker after 2 tries here), no run lost.
    As in the full suite, this process has run an FMU before: its extracted resources/ (partial copies
    of our packages) are on sys.path, and the workers the nanny restarts must not import them."""
    import cloudpickle

    import papers.p000_li2023.paper  # noqa: F401 - imported here before, as before an FMU runs

    fake = tmp_path / "fmu" / "resources"
    (fake / "papers" / "p000_li2023").mkdir(parents=True)
    (fake / "papers" / "__init__.py").write_text("")
    (fake / "papers" / "p000_li2023" / "__init__.py").write_text("")
    (fake / "slavemodule.txt").write_text("ftcsim_fake\n")
    monkeypatch.syspath_prepend(str(fake))

    from orchestrator.campaign import cluster as cl
    from orchestrator.campaign.expand import expand
    from orchestrator.campaign.schema import run_columns
    from orchestrator.campaign.spec import load
    from orchestrator.campaign.store import SUMMARY, combine, store

    p = tmp_path / "c.toml"
    p.write_text(CAMPAIGN.format(runs=3, stop=0.1), encoding="utf-8")
    c = load(p)
    plan = expand(c)
    columns = run_columns(c, list(plan[0].requested))
    (tmp_path / "out" / "runs").mkdir(parents=True)
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    try:
        with cl.dask_settings(connect_timeout=10, allowed_failures=1):  # 2 tries per task: fewer restarts
            conn = cl.open_connection(1, dashboard=False)
            scratch = conn.scratch
            try:
                got = []
                lost = cl.run_dask(conn.client, plan, got.append, [], batch=3, task=_crash_on_run_1)
            finally:
                conn.close()
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])
    assert lost == 0 and sorted(r["row"]["run_id"] for r in got) == [0, 1, 2]
    for r in got:
        store(tmp_path / "out", r, columns)
    combine(tmp_path / "out", plan, columns)
    df = pd.read_parquet(tmp_path / "out" / SUMMARY)
    assert list(df.status) == ["ok", "failed", "ok"], list(df.error)
    assert "killed its worker 2 times" in df.error[1] and df["requested:plant.fault_scale"].notna().all()
    assert scratch is not None and not scratch.exists()  # the LocalCluster's dask-scratch-space went with it
