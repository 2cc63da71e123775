"""Campaign files and their runs (orchestrator/campaign/)
without Dask: bad input, seeds and draws, keys, read-back, resume, run k alone, the report.
In-process blocks and short runs (the engine is the point here; FMUs and Dask are in
test_campaign_dask.py)."""
import json
import math

import numpy as np
import pandas as pd
import pytest

from orchestrator.campaign import expand as E
from orchestrator.campaign import spec as S
from orchestrator.campaign.report import make_report, mean_ci, wilson
from orchestrator.campaign.run import run_campaign
from orchestrator.campaign.store import EXECUTION_COLUMNS, SUMMARY
from orchestrator.campaign.worker import execute
from orchestrator.cli.main import main
from orchestrator.common.errors import InputError
from orchestrator.cosim.master import RunResult
from orchestrator.results.metrics import settling_time

BASE = """
[campaign]
scenario = "li2023_pd"
mode = "inprocess"
runs = {runs}
seed = 11
stop = {stop}
trajectories = ["ctrl.q_e"]
trajectory_step = 0.1

[dispersions."plant.fault_scale"]
distribution = "uniform"
low = 0.2
high = 1.5

[dispersions."plant.J[2,2]"]
distribution = "normal"
mean = 1.0
std = 0.05
apply = "scale"

[dispersions."plant.omega_init"]
distribution = "normal"
mean = 0.0
std = [0.01, 0.02, 0.03]
apply = "offset"

[dispersions."ctrl.k_p"]
distribution = "choice"
values = [10.0, 20.0, 40.0]
weights = [1, 2, 1]
"""


def write(tmp_path, text, name="c.toml"):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


@pytest.fixture
def small(tmp_path):
    return write(tmp_path, BASE.format(runs=3, stop=0.3))


# -- bad input -------------------------------------------------------------------------------------
BAD = [
    ('[dispersions."plant.fault_scal"]\ndistribution = "uniform"\nlow = 0\nhigh = 1\n',
     "dispersions.plant.fault_scal", "has no parameter 'fault_scal' (did you mean 'fault_scale'?)"),
    ('[dispersions."plant.fault_scale"]\ndistribution = "normal"\nmean = 1\nstd = -0.1\n',
     "dispersions.plant.fault_scale.std", "standard deviation must be >= 0"),
    ('[dispersions."plant.omega_init"]\ndistribution = "normal"\nmean = 0\nstd = [0.1, -0.1, 0.1]\n',
     "dispersions.plant.omega_init.std", "standard deviation must be >= 0"),
    ('[dispersions."plant.fault_scale"]\ndistribution = "gauss"\nmean = 1\nstd = 1\n',
     "dispersions.plant.fault_scale.distribution", "unknown distribution 'gauss'"),
    ('[dispersions."plant.fault_scale"]\ndistribution = "normal"\nmean = 1\nsigma = 1\n',
     "dispersions.plant.fault_scale.sigma", "unknown key"),
    ('[dispersions."plnt.fault_scale"]\ndistribution = "uniform"\nlow = 0\nhigh = 1\n',
     "dispersions.plnt.fault_scale", "unknown instance 'plnt' (did you mean 'plant'?)"),
    ('[dispersions."plant.omega_init"]\ndistribution = "uniform"\nlow = [0, 0]\nhigh = 1\n',
     "dispersions.plant.omega_init.low", "shape (3,)"),
    ('[dispersions."plant.fault_scale"]\ndistribution = "uniform"\nlow = 1\nhigh = 0\n',
     "dispersions.plant.fault_scale.high", "must be >= low"),
    ('[dispersions."ctrl.k_p"]\ndistribution = "choice"\nvalues = [1, 2]\nweights = [1]\n',
     "dispersions.ctrl.k_p.weights", "expected 2 weights"),
    ('[grid]\n"ctrl.k_p" = []\n', "grid.ctrl.k_p", "non-empty list"),
    ('[settling]\nsignal = "plant.u_d"\nlevel = 0.1\n', "settling.signal", "not recorded"),
]


@pytest.mark.parametrize("extra,key,problem", BAD, ids=[b[1] for b in BAD])
def test_bad_campaign_files_get_one_clear_message(tmp_path, capsys, extra, key, problem):
    text = '[campaign]\nscenario = "li2023_pd"\nmode = "inprocess"\nruns = 2\nstop = 0.1\n' + extra
    path = write(tmp_path, text)
    out = tmp_path / "out"
    assert main(["campaign", str(path), "--out", str(out), "--workers", "0", "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert f"{path}: {key}: " in err and problem in err, err
    assert not out.exists()


@pytest.mark.parametrize("runs", ["0", "-3", "2.5", "true"])
def test_runs_must_be_a_whole_number_at_least_one(tmp_path, runs):
    path = write(tmp_path, f'[campaign]\nscenario = "li2023_pd"\nmode = "inprocess"\nruns = {runs}\n')
    with pytest.raises(InputError) as e:
        S.load(path)
    assert e.value.key == "campaign.runs"


def test_unknown_campaign_key_suggests_the_known_one(tmp_path):
    path = write(tmp_path, '[campaign]\nscenario = "li2023_pd"\nmode = "inprocess"\nrun = 2\n')
    with pytest.raises(InputError, match="did you mean 'runs'"):
        S.load(path)


# -- seeds, draws, keys ----------------------------------------------------------------------------
def test_run_seed_is_the_spawned_child():
    for k in (0, 3, 17):
        assert np.array_equal(E.run_seed(5, k).generate_state(4),
                              np.random.SeedSequence(5).spawn(20)[k].generate_state(4))


def test_draws_are_the_same_for_every_variant_and_follow_their_distributions(tmp_path):
    text = BASE.format(runs=400, stop=0.3) + '\n[[variants]]\nname = "a"\n[[variants]]\nname = "b"\n' \
        '[variants.parameters]\n"ctrl.k_d" = 30.0\n'
    c = S.load(write(tmp_path, text))
    plan = E.expand(c)
    assert len(plan) == 800 and [s.run_id for s in plan] == list(range(800))
    a, b = plan[:400], plan[400:]
    assert all(x.requested == y.requested and x.draw == y.draw for x, y in zip(a, b))
    assert len({s.key for s in plan}) == 800
    fs = np.array([s.requested["plant.fault_scale"] for s in a])
    assert fs.min() >= 0.2 and fs.max() < 1.5 and abs(fs.mean() - 0.85) < 4 * 1.3 / math.sqrt(12 * 400)
    J22 = np.array([s.requested["plant.J[2,2]"] for s in a])  # 270 kg m^2 (li2023) scaled by N(1, 0.05)
    assert abs(J22.mean() / 270.0 - 1) < 4 * 0.05 / 20 and 0.85 < J22.std() / (270 * 0.05) < 1.15
    w3 = np.array([s.requested["plant.omega_init[3]"] for s in a]) - 0.01  # nominal omega(0)_3 = 0.01 rad/s
    assert abs(w3.mean()) < 4 * 0.03 / 20 and 0.85 < w3.std() / 0.03 < 1.15
    kp = np.array([s.requested["ctrl.k_p"] for s in a])
    assert set(kp) <= {10.0, 20.0, 40.0} and abs((kp == 20.0).mean() - 0.5) < 4 * 0.5 / 20


def test_adding_a_dispersion_keeps_the_other_draws_and_changes_the_keys(tmp_path):
    c1 = S.load(write(tmp_path, BASE.format(runs=5, stop=0.3), "a.toml"))
    extra = '\n[dispersions."plant.fault_onset"]\ndistribution = "uniform"\nlow = 20\nhigh = 60\n'
    c2 = S.load(write(tmp_path, BASE.format(runs=5, stop=0.3) + extra, "b.toml"))
    p1, p2 = E.expand(c1), E.expand(c2)
    for x, y in zip(p1, p2):
        assert all(y.requested[k] == v for k, v in x.requested.items())
        assert x.key != y.key
    assert [s.key for s in p1] == [s.key for s in E.expand(S.load(tmp_path / "a.toml"))]


def test_grid_points_times_draws(tmp_path):
    text = BASE.format(runs=2, stop=0.3) + '\n[grid]\n"ctrl.k_d" = [30.0, 60.0, 90.0]\n"plant.u_max" = [4.0, 5.0]\n'
    plan = E.expand(S.load(write(tmp_path, text)))
    assert len(plan) == 12
    assert [(s.point, s.draw) for s in plan[:4]] == [(0, 0), (0, 1), (1, 0), (1, 1)]
    assert [s.requested["ctrl.k_d"] for s in plan[::2]] == [30.0, 30.0, 60.0, 60.0, 90.0, 90.0]
    assert plan[0].requested["plant.fault_scale"] == plan[2].requested["plant.fault_scale"]  # same draw 0


def test_settling_time_of_a_known_signal():
    t = np.linspace(0.0, 10.0, 101)
    e = np.exp(-t)  # below 0.01 from ln(100) = 4.605 s on
    q = np.column_stack([np.sqrt(1 - e**2), e, 0 * t, 0 * t])
    r = RunResult(["c.q[0]", "c.q[1]", "c.q[2]", "c.q[3]"], t, q, True)
    cfg = {"columns": r.columns, "level": 0.01, "from": 1.0}
    assert settling_time(r, cfg) == pytest.approx(4.7 - 1.0)
    assert settling_time(r, {**cfg, "level": 1e-6}) is None  # still outside at the end


def test_confidence_intervals():
    lo, hi = wilson(8, 10)
    assert (round(lo, 3), round(hi, 3)) == (0.49, 0.943)
    m, h = mean_ci([1.0, 2.0, 3.0])
    assert m == 2.0 and h == pytest.approx(4.302652729911275 * 1.0 / math.sqrt(3))


# -- execution without Dask ------------------------------------------------------------------------
def test_serial_campaign_reads_back_resumes_and_reruns_one_run_alone(tmp_path, small):
    out = tmp_path / "out"
    o = run_campaign(small, out, workers=0)
    assert (o.total, o.stored, o.computed, o.failed) == (3, 3, 3, 0)
    df = pd.read_parquet(out / SUMMARY)
    assert list(df.run_id) == [0, 1, 2] and set(df.status) == {"ok"}
    for ref in ("plant.fault_scale", "plant.J[2,2]", "plant.omega_init[2]", "ctrl.k_p"):
        assert np.array_equal(df[ref].to_numpy(float), df[f"requested:{ref}"].to_numpy(float)), ref
    assert df["plant.J[2,2]"].nunique() == 3
    # the dispersion reached the dynamics: runs differ in their metrics
    assert df["control_energy"].nunique() == 3 and np.isfinite(df["control_energy"]).all()
    tr = pd.read_parquet(out / "trajectories")
    assert sorted(tr.run_id.astype(int).unique()) == [0, 1, 2] and len(tr) == 3 * 4  # 0, 0.1, 0.2, 0.3 s
    man = json.loads((out / "manifest.json").read_text())
    assert man["status"] == "complete" and man["versions"]["numpy"] == np.__version__
    files = {p.name: p.stat().st_mtime_ns for p in (out / "runs").iterdir()}

    again = run_campaign(small, out, workers=0)  # resume: nothing left to compute
    assert (again.computed, again.skipped) == (0, 3)
    assert {p.name: p.stat().st_mtime_ns for p in (out / "runs").iterdir()} == files
    assert pd.read_parquet(out / SUMMARY).equals(df)

    import ftcsim

    one = ftcsim.campaign(small, tmp_path / "alone", workers=0, only=[1])
    cols = [c for c in df.columns if c not in EXECUTION_COLUMNS]
    assert len(one) == 1 and one[cols].iloc[0].equals(df[cols].iloc[1])

    small.write_text(small.read_text().replace("seed = 11", "seed = 12"))
    with pytest.raises(InputError, match="holds another campaign"):
        run_campaign(small, out, workers=0)
    o2 = run_campaign(small, out, workers=0, overwrite=True)
    assert o2.computed == 3 and not pd.read_parquet(out / SUMMARY)["plant.fault_scale"].equals(df["plant.fault_scale"])


def test_a_run_that_fails_is_stored_with_its_error_and_the_campaign_goes_on(tmp_path):
    # a zero attitude quaternion is refused by the block's initialize: in a grid point (known when the
    # campaign is planned) before anything is written (issue 35); drawn for some runs, those runs are
    # stored failed with the block's words and the campaign goes on
    grid = BASE.format(runs=2, stop=0.3) + '\n[grid]\n"plant.q_init" = [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]]\n'
    with pytest.raises(InputError, match="q_init must not be zero"):
        run_campaign(write(tmp_path, grid), tmp_path / "refused", workers=0)
    assert not (tmp_path / "refused").exists()
    text = BASE.format(runs=6, stop=0.3) + ('\n[dispersions."plant.q_init"]\ndistribution = "choice"\n'
                                           'values = [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]]\n')
    out = tmp_path / "out"
    o = run_campaign(write(tmp_path, text), out, workers=0)
    df = pd.read_parquet(out / SUMMARY)
    first = sorted(c for c in df.columns if c.startswith("requested:plant.q_init"))[0]  # the scalar part q_0
    zero = [q == 0.0 for q in df[first]]
    assert o.stored == 6 and 0 < sum(zero) < 6
    assert list(df.status) == ["failed" if z else "ok" for z in zero]
    assert all("q_init must not be zero" in e for e, z in zip(df.error, zero) if z)


def test_report_tables_match_the_summary(tmp_path):
    text = BASE.format(runs=6, stop=0.3) + '\n[[variants]]\nname = "kd30"\n[variants.parameters]\n"ctrl.k_d" = 30.0\n' \
        '[[variants]]\nname = "kd90"\n[variants.parameters]\n"ctrl.k_d" = 90.0\n' \
        '\n[requirements]\nfinal_attitude_error = { max = 0.0001 }\ncontrol_energy = { max = 1e9 }\n'
    out = tmp_path / "out"
    run_campaign(write(tmp_path, text), out, workers=0)
    df = pd.read_parquet(out / SUMMARY)
    rep = tmp_path / "rep"
    rep.mkdir()
    data = make_report(out, rep)
    row = next(r for r in data["statistics"] if r["metric"] == "control_energy" and r["variant"] == "kd90")
    x = df[df.variant == "kd90"].control_energy.to_numpy(float)
    assert row["n"] == 6 and row["mean"] == pytest.approx(x.mean()) and row["max"] == x.max()
    pair = next(r for r in data["paired"] if r["metric"] == "control_energy")
    d = x - df[df.variant == "kd30"].control_energy.to_numpy(float)
    assert pair["pairs"] == 6 and pair["mean_difference"] == pytest.approx(d.mean())
    req = {(r["requirement"], r["variant"]): r["passed"] for r in data["requirements"]}
    fae = df.final_attitude_error.to_numpy(float)
    assert req[("final_attitude_error", "kd30")] == int((fae[:6] <= 1e-4).sum())
    assert req[("control_energy", "kd90")] == 6
    assert data["worst"]["final_attitude_error"][0] == int(df.run_id[np.argmax(fae)])
    assert (rep / "report.md").is_file() and "metrics.png" in data["plots"] and "envelopes.png" in data["plots"]


def test_execute_reports_a_changed_fmu_instead_of_running_it(tmp_path, small):
    (spec,) = E.expand(S.load(small), only=[0])
    fake = tmp_path / "X.fmu"
    fake.write_bytes(b"not the planned FMU")
    spec.fmu_digests = {str(fake): "0" * 64}
    row = execute(spec)["row"]
    assert row["status"] == "failed" and "not the FMU the campaign was planned with" in row["error"]


def test_a_run_stopped_by_a_signal_is_not_a_result(small):
    import signal

    from orchestrator.common.interrupt import REQUEST

    (spec,) = E.expand(S.load(small), only=[0])
    REQUEST.signum = signal.SIGINT  # as the handler sets it when Ctrl-C arrives during the run
    try:
        r = execute(spec)
    finally:
        REQUEST.signum = 0
    assert r["interrupted"] == signal.SIGINT and r["row"] is None
    assert execute(spec)["row"]["status"] == "ok"


class _ScriptedFuture:
    """A dask future whose status follows a script: done() is True on every poll (as just before
    its worker dies), status is read once per poll."""

    def __init__(self, key, statuses, value):
        self.key, self._statuses, self._value = key, list(statuses), value

    def done(self):
        return True

    @property
    def status(self):
        return self._statuses.pop(0) if len(self._statuses) > 1 else self._statuses[0]

    def result(self):
        if isinstance(self._value, BaseException):
            raise self._value
        if self._statuses[0] == "error":
            raise self.exception()
        return self._value

    def exception(self):
        return RuntimeError("every worker that tried it died") if self._statuses[0] == "error" else None


class _ScriptedClient:
    def __init__(self, scripts):
        self.scripts, self.cancelled = scripts, []

    def submit(self, fn, group, key, pure, retries):  # one run per task (batch=1): its results as a list
        (spec,) = group
        return _ScriptedFuture(key, self.scripts[spec.run_id], [{"run_id": spec.run_id}])

    def cancel(self, futures, force):
        self.cancelled += futures


def test_a_result_lost_between_done_and_status_is_waited_for_not_counted_lost():
    # dask: a finished task whose worker dies goes 'lost' (then 'pending', recomputed elsewhere)
    # even after done() said True: such a run is still coming, not lost to the campaign
    from types import SimpleNamespace

    from orchestrator.campaign.cluster import run_dask

    specs = [SimpleNamespace(run_id=i, key=f"k{i}") for i in range(3)]
    client = _ScriptedClient([["finished"], ["lost", "pending", "finished"], ["error"]])
    got = []
    lost = run_dask(client, specs, lambda row: got.append(row["run_id"]), request=[])
    assert sorted(got) == [0, 1] and lost == 1 and client.cancelled == []


def test_a_result_lost_after_finished_whose_recomputation_fails_counts_as_one_lost_run(caplog):
    # status 'finished', then the data is lost and its recomputation killed: result() raises;
    # that run is lost (a rerun retries it), the campaign goes on with the others
    from types import SimpleNamespace

    from orchestrator.campaign.cluster import run_dask

    specs = [SimpleNamespace(run_id=i, key=f"k{i}") for i in range(2)]
    client = _ScriptedClient([["finished"], ["finished"]])
    futures = {}
    submit = client.submit

    def scripted(fn, group, key, pure, retries):
        futures[group[0].run_id] = f = submit(fn, group, key, pure, retries)
        if group[0].run_id == 0:
            f._value = RuntimeError("every worker that tried it died")
        return f

    client.submit = scripted
    got = []
    with caplog.at_level("WARNING", logger="ftcsim.campaign"):
        lost = run_dask(client, specs, lambda row: got.append(row["run_id"]), request=[])
    assert got == [1] and lost == 1
    assert f"runs {futures[0].key} could not be computed (RuntimeError: every worker" in caplog.text
