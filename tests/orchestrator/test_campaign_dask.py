"""Campaigns on dask.distributed and FMUs: dispersions read back from the FMUs, determinism across
executors, a worker killed part-way, SIGINT and resume, an unreachable scheduler, the memory
of a worker over many runs. One 2-worker LocalCluster for the module; short runs."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import dask
import numpy as np
import pandas as pd
import pytest

from orchestrator.campaign.cluster import LOCAL_WORKER_SATURATION, close, connect
from orchestrator.campaign.run import run_campaign
from orchestrator.campaign.store import EXECUTION_COLUMNS, SUMMARY

ROOT = Path(__file__).resolve().parents[2]

FMU_CAMPAIGN = """
[campaign]
scenario = "li2023_fasmc"
runs = 2
seed = 3
stop = 0.05

[dispersions."plant.fault_onset"]
distribution = "uniform"
low = 20.0
high = 60.0

[dispersions."plant.J"]
distribution = "normal"
mean = 1.0
std = 0.02
apply = "scale"
shared = true

[dispersions."plant.omega_init"]
distribution = "normal"
mean = 0.0
std = 0.01
apply = "offset"

[dispersions."est.h_max"]
distribution = "choice"
values = [0.001, 0.005]

[grid]
"ctrl.u_max" = [4.0, 5.0]
"""

ENGINE_CAMPAIGN = """
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

[dispersions."plant.J[3,3]"]
distribution = "normal"
mean = 1.0
std = 0.05
apply = "scale"
"""

EXECUTION = list(EXECUTION_COLUMNS)


@pytest.fixture(scope="module")
def client():
    c = connect(2, None)
    yield c
    close(c)


def write(tmp_path, text, name="c.toml"):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


@pytest.mark.fmu
def test_dispersed_values_read_back_from_the_fmus_equal_the_requested_ones(tmp_path, fmu_dir, client):
    # two processes of one thread each (no oversubscription of 2 cores), BLAS single-threaded in each
    assert sorted(client.nthreads().values()) == [1, 1]
    assert set(client.run(lambda: os.environ.get("OPENBLAS_NUM_THREADS")).values()) == {"1"}
    # our local scheduler hands each worker a task ahead; the caller's configuration keeps Dask's default
    assert client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.WORKER_SATURATION) == LOCAL_WORKER_SATURATION
    assert dask.config.get("distributed.scheduler.worker-saturation") != LOCAL_WORKER_SATURATION
    path = write(tmp_path, FMU_CAMPAIGN)
    o = run_campaign(path, tmp_path / "dask", client=client)
    df = pd.read_parquet(tmp_path / "dask" / SUMMARY)
    assert (o.stored, o.failed, o.lost) == (4, 0, 0), list(df.error)
    assert len(set(df.worker)) == 2  # both workers ran runs
    names = ["plant.fault_onset", "plant.J[1,1]", "plant.J[2,3]", "plant.J[3,3]", "plant.omega_init[1]",
             "plant.omega_init[3]", "est.h_max", "ctrl.u_max"]
    for ref in names:
        assert np.array_equal(df[ref].to_numpy(float), df[f"requested:{ref}"].to_numpy(float)), ref
    # one shared factor scales every element of J (li2023: J[1,1] = 350, J[2,3] = 10 kg m^2)
    assert np.allclose(df["plant.J[2,3]"] / 10.0, df["plant.J[1,1]"] / 350.0, rtol=1e-12, atol=0)
    assert df["plant.J[1,1]"].nunique() == 2 and list(df["ctrl.u_max"]) == [4.0, 4.0, 5.0, 5.0]
    assert set(df["est.h_max"]) <= {0.001, 0.005}
    # the same campaign in this process without Dask gives the same table
    run_campaign(path, tmp_path / "serial", workers=0)
    serial = pd.read_parquet(tmp_path / "serial" / SUMMARY)
    assert serial.drop(columns=EXECUTION).equals(df.drop(columns=EXECUTION))


def test_killing_a_worker_part_way_loses_no_run(tmp_path, client):
    path = write(tmp_path, ENGINE_CAMPAIGN.format(runs=10, stop=2.0))
    killed = []

    def kill_one(outcome):
        if not killed:
            pid = sorted(client.run(os.getpid).values())[0]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    o = run_campaign(path, tmp_path / "out", client=client, on_result=kill_one)
    assert killed and (o.stored, o.lost, o.computed) == (10, 0, 10)
    df = pd.read_parquet(tmp_path / "out" / SUMMARY)
    assert list(df.run_id) == list(range(10)) and set(df.status) == {"ok"}, list(df.error)
    assert len(list((tmp_path / "out" / "runs").iterdir())) == 10
    # results do not depend on which worker computed them
    run_campaign(path, tmp_path / "serial", workers=0, only=[0, 9])
    serial = pd.read_parquet(tmp_path / "serial" / SUMMARY)
    assert serial.drop(columns=EXECUTION).equals(df.iloc[[0, 9]].reset_index(drop=True).drop(columns=EXECUTION))


def _cli(args, **kw):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    return subprocess.Popen([sys.executable, "-m", "orchestrator.cli", *args], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


@pytest.mark.slow
def test_sigint_stops_cleanly_and_the_rerun_computes_only_what_is_missing(tmp_path):
    # 20 runs of 300 s at 10 ms (about 0.2 s each in-process with the compiled kernels; runs of
    # 40 s took 30 ms and could all finish between two polls of a loaded test process): the
    # signal comes part way, seconds before the last run
    runs = 20
    path = write(tmp_path, ENGINE_CAMPAIGN.format(runs=runs, stop=300.0))
    out = tmp_path / "out"
    p = _cli(["campaign", str(path), "--out", str(out), "--workers", "1", "--quiet"], start_new_session=True)
    def n_stored():
        return len(list((out / "runs").glob("*.parquet"))) if (out / "runs").is_dir() else 0

    deadline = time.time() + 120
    while p.poll() is None and time.time() < deadline and n_stored() < 2:
        time.sleep(0.05)
    os.killpg(p.pid, signal.SIGINT)  # as a Ctrl-C does: to the whole process group, workers included
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, err
    assert "stopped" in err and "Traceback" not in err
    before = {f.name: (f.stat().st_mtime_ns, f.read_bytes()) for f in (out / "runs").iterdir()}
    summary = pd.read_parquet(out / SUMMARY)
    assert 2 <= len(before) < runs and len(summary) == len(before)

    o = run_campaign(path, out, workers=0)
    assert (o.skipped, o.computed, o.stored) == (len(before), runs - len(before), runs)  # no recomputation
    assert {f.name: (f.stat().st_mtime_ns, f.read_bytes()) for f in (out / "runs").iterdir() if f.name in before} \
        == before
    full = pd.read_parquet(out / SUMMARY)
    assert list(full.run_id) == list(range(runs)) and set(full.status) == {"ok"}


def test_an_unreachable_scheduler_is_one_clear_message_within_seconds(tmp_path):
    path = write(tmp_path, ENGINE_CAMPAIGN.format(runs=2, stop=0.1))
    t = time.monotonic()
    p = _cli(["campaign", str(path), "--out", str(tmp_path / "out"), "--scheduler", "tcp://127.0.0.1:9",
              "--connect-timeout", "2"])
    _, err = p.communicate(timeout=60)
    elapsed = time.monotonic() - t
    assert p.returncode == 2 and elapsed < 60, (elapsed, err)  # 2 s to connect; generous for start-up under load
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "--scheduler: no Dask scheduler reachable at 'tcp://127.0.0.1:9' within 2 s" in lines[0]
    assert not (tmp_path / "out").exists()


def test_an_out_folder_holding_another_campaign_is_refused(tmp_path, capsys):
    from orchestrator.cli.main import main

    a = write(tmp_path, ENGINE_CAMPAIGN.format(runs=1, stop=0.1), "a.toml")
    b = write(tmp_path, ENGINE_CAMPAIGN.format(runs=2, stop=0.1), "b.toml")
    out = tmp_path / "out"
    assert main(["campaign", str(a), "--out", str(out), "--workers", "0", "--quiet"]) == 0
    before = sorted(p.name for p in (out / "runs").iterdir())
    assert main(["campaign", str(b), "--out", str(out), "--workers", "0", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"--out: {out} holds another campaign (a, from a different campaign file): pass --overwrite" in err
    assert sorted(p.name for p in (out / "runs").iterdir()) == before
    (tmp_path / "plain").mkdir()
    (tmp_path / "plain" / "notes.txt").write_text("mine")
    assert main(["campaign", str(a), "--out", str(tmp_path / "plain"), "--workers", "0", "--quiet"]) == 2
    assert "was not written by ftcsim" in capsys.readouterr().err
    assert (tmp_path / "plain" / "notes.txt").read_text() == "mine"


MEMORY = """
[campaign]
scenario = "li2023_fasmc"
runs = 40
stop = 0.02

[dispersions."plant.fault_scale"]
distribution = "uniform"
low = 0.2
high = 1.5
"""


@pytest.mark.fmu
@pytest.mark.slow
def test_a_worker_running_many_fmu_runs_keeps_its_memory(tmp_path, fmu_dir):
    """RSS growth of one worker process over runs 25 to 40 of three FMI 2.0 FMUs: an FMU extracted
    (and its library loaded) per instance grew it by ~1 MB per run (~15 MB here). The first runs
    grow it by 7-9 MB while the allocator and the caches warm up, flat from about run 20 (measured
    over 70 runs); the 200-run figure is in benchmarks/bench_campaigns.py."""
    code = (
        "import sys, psutil\n"
        "from orchestrator.campaign.expand import expand\nfrom orchestrator.campaign.spec import load\n"
        "from orchestrator.campaign.worker import execute\n"
        "plan = expand(load(sys.argv[1]))\n"
        "rss = []\n"
        "for k, s in enumerate(plan):\n"
        "    assert execute(s)['row']['status'] == 'ok'\n"
        "    rss.append(psutil.Process().memory_info().rss)\n"
        "print((rss[-1] - rss[24]) / 2**20, len(sys.path), flush=True)\n"
        "import os\n"
        "os._exit(0)  # pythonfmu's exit-time teardown may abort the process (known; not what is tested here)\n"
    )
    path = write(tmp_path, MEMORY)
    env = dict(os.environ, FTCSIM_FMU_DIR=str(fmu_dir))
    r = subprocess.run([sys.executable, "-c", code, str(path)], cwd=ROOT, env=env, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    growth, path_entries = (float(x) for x in r.stdout.split())
    assert growth < 5.0, growth  # MB over 15 runs
    assert path_entries < len(sys.path) + 10


@pytest.mark.fmu
def test_the_shipped_campaigns_expand_with_the_same_draws_for_every_method(fmu_dir):
    from orchestrator.campaign.expand import expand
    from orchestrator.campaign.spec import load

    c = load(ROOT / "campaigns" / "li2023_methods.toml")
    plan = expand(c)
    assert [v.name for v in c.variants] == ["pd", "aismc", "fasmc"] and len(plan) == 600
    models = [{i.model_name for i in sc.instances.values()} for sc in c.bases]
    assert models == [{"FlexibleSpacecraft", "PDController"}, {"FlexibleSpacecraft", "FAFEO", "AISMC"},
                      {"FlexibleSpacecraft", "FAFEO", "FASMC"}]
    for k in (0, 57, 199):
        assert plan[k].requested == plan[200 + k].requested == plan[400 + k].requested
    assert len({s.requested["plant.fault_onset"] for s in plan[:200]}) == 200
    assert c.bases[0].stop == 200.0 and c.bases[0].step == 0.01  # the paper's set-up, unchanged
    xu = load(ROOT / "campaigns" / "xu2024_seeds.toml")
    seeds = [s.requested["faults.seed"] for s in expand(xu)]
    assert len(seeds) == 50 and all(float(x).is_integer() and 0 <= x < 1e6 for x in seeds)


def test_workers_do_not_inherit_an_fmus_partial_packages(tmp_path, monkeypatch):
    """An FMU run in this process puts its extracted resources/ on sys.path, with partial copies of
    our packages (papers/ without paper.py): workers started afterwards must import the project's.
    (This process has imported them before, as it does before it runs an FMU.)"""
    import papers.p000_li2023.paper  # noqa: F401

    fake = tmp_path / "fmu" / "resources"
    (fake / "papers" / "p000_li2023").mkdir(parents=True)
    (fake / "papers" / "__init__.py").write_text("")
    (fake / "papers" / "p000_li2023" / "__init__.py").write_text("")
    (fake / "slavemodule.txt").write_text("ftcsim_fake\n")
    monkeypatch.syspath_prepend(str(fake))
    c = connect(1, None)
    try:
        o = run_campaign(write(tmp_path, ENGINE_CAMPAIGN.format(runs=1, stop=0.1)), tmp_path / "out", client=c)
    finally:
        close(c)
    df = pd.read_parquet(tmp_path / "out" / SUMMARY)
    assert (o.stored, o.failed) == (1, 0), list(df.error)
