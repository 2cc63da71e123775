"""``ftcsim fdir calibrate``: a detector's threshold from fault-free Monte Carlo draws, for a stated
false-alarm rate per hour (issue 34 item 4; the rule in docs/fdir.md).

1. The campaign file (one scenario, no variants, no grid; its dispersions span the fault-free
   mission) runs like ``ftcsim campaign`` into ``draws`` (resumable). It must store, as trajectories
   at the detector's sample period, the signal that drives the detector's input ``r``: the rule
   replays the detector offline on it, so any threshold can be tried on the same draws.
2. Normalisation: mu0 and sigma per channel, the mean and standard deviation of that signal over
   every sample at or after the detector's ``t_enable`` of every run.
3. False alarms at a threshold h: the detector replayed on every run with its own test parameters
   (drift or window, persistence), restarting after each alarm (``diagnosis/calibration.py``); N(h)
   alarms over the exposure E (hours: samples x sample period). Rate N/E per hour.
4. Threshold: the smallest h at which no draw raises an alarm (just above the largest persisted
   peak), certified when -ln(1 - level) / E <= target (``diagnosis.calibration.certify``: the largest
   of n exchangeable peaks is a Wilks tolerance limit, so a new fault-free run of the same exposure
   alarms with probability at most 1 - (1 - level)^(1/n) at confidence ``level``, so at most
   -ln(1 - level) / E first false alarms per hour; approximate, as mu0 and sigma come from the same
   draws; a lower h chosen to allow N > 0 alarms would be chosen on the counts it bounds). With fewer
   hours than -ln(1 - level) / target the file is written with ``certified: false``, says how many
   hours would be needed, and the command exits 0 (a short campaign is not bad input; the file says
   what it is).
5. Written: the file ``out`` (strict JSON): ``parameter_set`` (h, mu0, sigma and the test's given
   parameters: what a scenario's ``parameter_set`` applies), ``fmu_parameters`` (the same as a gains
   file for ``ftcsim run --gains``), the target, the counts and exposure, the rate with its two-sided
   Garwood interval at ``level`` and, when there are 10 runs or more and an alarm, a bootstrap
   interval over runs (scipy.stats.bootstrap; alarms that cluster within runs make the Poisson
   interval too narrow: the stated interval is the union of both), the dispersion index of the
   per-run counts, the operating curve (h, alarms, rate, bound) below h, and the
   campaign's and base scenario's SHA-256.
"""
from __future__ import annotations

import hashlib
import logging
import math
import shlex
import time
from pathlib import Path

import numpy as np

from diagnosis.calibration import COUNTING, certify, exposure_hours, normalisation, rate_statistics, upper_bound
from diagnosis.detectors import ChangeDetector, Chi2Detector, CusumDetector, GlrDetector
from orchestrator.campaign.run import run_campaign
from orchestrator.campaign.spec import Campaign
from orchestrator.campaign.spec import load as load_campaign
from orchestrator.campaign.store import SUMMARY, TRAJECTORIES, run_file
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.interrupt import Interrupted
from orchestrator.common.jsonio import load_json_object, write_json_atomic
from orchestrator.common.outputs import OutputFile, check_target
from orchestrator.common.parquet import read_table
from orchestrator.scenario.physical import nominal_values
from orchestrator.scenario.refs import summary
from orchestrator.scenario.shipped import block_factory, campaign_file
from orchestrator.scenario.values import hint
from plant.block import split_name

__all__ = ["calibrate", "KIND", "written_by_calibrate"]

log = logging.getLogger("ftcsim.fdir")

KIND = "fdir-calibration"
TESTS = ((CusumDetector, "cusum", ("drift",)), (GlrDetector, "glr", ("window",)), (Chi2Detector, "chi2", ("window", "form")))
GIVEN = ("persistence", "sample_period", "t_enable")  # decision parameters the calibration assumes, written with it
MIN_BOOTSTRAP_RUNS = 10


def written_by_calibrate(path: Path) -> bool:
    try:
        return load_json_object(path, "calibration file").get("kind") == KIND
    except InputError:
        return False


def check_out(path, overwrite: bool, src: str, key: str) -> Path:
    """Refuse an ``out`` that cannot be written, or that exists and is not a calibration file this
    command wrote and ``overwrite`` allows it to replace."""
    p = Path(path)
    if p.is_symlink():
        raise InputError(src, key, f"{p} is a symbolic link; give the real file")
    if p.is_dir():
        raise InputError(src, key, f"{p} is a directory; give a file name (e.g. calibration.json)")
    if p.suffix != ".json":
        raise InputError(src, key, f"{p}: a calibration file ends in .json")
    if any(a.exists() and not a.is_dir() for a in p.absolute().parents):
        raise InputError(src, key, f"{p}: a parent of it is a file")
    if p.exists():
        if not written_by_calibrate(p):
            raise InputError(src, key, f"{p} exists and was not written by `ftcsim fdir calibrate`: nothing is touched; "
                                       "choose a new file")
        if not overwrite:
            raise InputError(src, key, f"{p} holds a previous calibration; pass --overwrite to replace it")
    check_target(p, src, key)  # the one publisher's checks: /proc, a name too long for the lock beside it, writable
    return p


def _number(src, key, x, lo, hi, what) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x) or not lo < x < hi:
        raise InputError(src, key, f"must be {what}, got {x!r}")
    return float(x)


def _campaign(campaign, runs, src, key) -> Campaign:
    if isinstance(campaign, Campaign):
        return campaign
    p = Path(campaign)
    try:
        return load_campaign(p if p.is_file() else campaign_file(str(campaign)), runs=runs)
    except InputError as e:
        if e.source == "command line" and e.key in ("--campaign", "--runs"):  # named as this command names them
            raise InputError(src, key if e.key == "--campaign" else "runs", e.problem) from None
        raise


def _detector(c: Campaign, name: str, src: str, key: str) -> tuple:
    """(scenario, the detector instance's block initialised with its nominal parameters, test name,
    the columns that drive r, in r's order)."""
    if len(c.variants) != 1 or c.grid:
        raise InputError(c.path, "variants" if len(c.variants) != 1 else "grid",
                         "a calibration campaign draws one fault-free scenario: no variants, no grid")
    sc = c.bases[0]
    if name not in sc.instances:
        raise InputError(src, key, f"no instance {name!r} in scenario {sc.name}{hint(name, sc.instances)} "
                                   f"(instances: {', '.join(sc.instances)})")
    inst = sc.instances[name]
    block = block_factory(inst.model_name, src, key, inst.model_name)()
    test = next((t for cls, t, _ in TESTS if isinstance(block, cls)), None)
    if not isinstance(block, ChangeDetector) or test is None:
        raise InputError(src, key, f"instance {name!r} is a {inst.model_name}, not a change detector "
                                   "(CusumDetector3, GlrDetector3, Chi2Detector3 or a block of diagnosis/detectors.py)")
    for d in c.dispersions:
        if d.inst == name:
            raise InputError(c.path, f"dispersions.{d.ref}", "the detector's parameters are fixed in a calibration "
                                                             "(they define the test whose threshold is set)")
    values = nominal_values(inst)
    try:
        block.set_parameters(values)
        block.initialize(sc.start)
    except (KeyError, ValueError) as e:  # from the campaign's [parameters], the scenario or its parameter set
        problem = str(e).strip("'\"")
        raise InputError(c.path, f"{name} parameters", f"{problem} (the values the campaign's scenario {sc.name} gives "
                                                       "the detector)") from None
    r_names = [v.name for v in block.inputs if split_name(v.name)[0] == "r"]
    feeds = {(b, vb): f"{a}.{va}" for a, va, b, vb in sc.connections}
    missing = [n for n in r_names if (name, n) not in feeds]
    if missing:
        raise InputError(sc.path, "connections", f"{name}.{summary(missing)} is not connected: the calibration replays "
                                                 "the detector on the signal that drives r")
    cols = [feeds[(name, n)] for n in r_names]
    absent = [col for col in cols if col not in c.trajectories]
    if absent:
        raise InputError(c.path, "campaign.trajectories", f"must store {summary(cols)} (the signal driving {name}.r): "
                                                          f"add it to trajectories")
    T = block.p("sample_period")
    spacing = c.trajectory_step or sc.step
    if abs(spacing - T) > 1e-9 * T:
        raise InputError(c.path, "campaign.trajectory_step", f"{spacing:g} s, but {name} samples every {T:g} s: set "
                                                             f"trajectory_step = {T:g}")
    return sc, block, test, cols


def _runs(folder: Path, cols: list, stop: float) -> tuple:
    """(run ids, [(t, r)]) of the stored fault-free runs; every run must have ended well."""
    df = read_table(folder / SUMMARY)  # the one reader: a folder of any name
    bad = df[df["status"] != "ok"]
    if len(bad):
        ids = ", ".join(str(i) for i in bad["run_id"].head(5))
        raise SimulationError(f"{len(bad)} of {len(df)} fault-free draws did not end well (run {ids}: "
                              f"{bad['error'].iloc[0]}); the calibration needs every draw (see {folder / SUMMARY})")
    runs = []
    for _, row in df.iterrows():
        traj = read_table(folder / TRAJECTORIES / run_file(row))
        t = traj["time"].to_numpy()
        keep = t < stop - 1e-9 * max(1.0, abs(stop))  # no sample is taken at the stop time
        runs.append((t[keep], traj[cols].to_numpy()[keep]))
    return df["run_id"].tolist(), runs


def _intervals(counts: np.ndarray, exposures: np.ndarray, level: float) -> dict:
    """Rate per hour, its Garwood interval, a bootstrap interval over runs, the dispersion index
    (``diagnosis.calibration.rate_statistics``: the arena states its rates with the same function)."""
    return rate_statistics(counts, exposures, level, MIN_BOOTSTRAP_RUNS)


def _sha256(path) -> str | None:
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def calibrate(campaign, *, detector: str, rate_per_hour: float, draws, out, level: float = 0.95, overwrite: bool = False,
              runs: int | None = None, workers: int | None = None, progress: bool = False, command: str | None = None,
              src: str = "api", keys: dict | None = None, **cluster) -> dict:
    """Calibrate ``detector`` (an instance of the campaign's scenario) for ``rate_per_hour`` false
    alarms per hour at confidence ``level`` from the campaign's fault-free draws (run into the
    campaign folder ``draws``, resumed if it holds them); write the calibration file ``out`` (.json).
    Returns what it wrote. ``keys`` names the arguments in messages (the command line passes its
    option names); ``cluster``: keywords of :func:`orchestrator.campaign.run.run_campaign`."""
    k = {"campaign": "campaign", "detector": "detector", "rate_per_hour": "rate_per_hour", "level": "level",
         "out": "out", "draws": "draws", "runs": "runs", **(keys or {})}
    rate = _number(src, k["rate_per_hour"], rate_per_hour, 0.0, math.inf, "a number of false alarms per hour > 0")
    level = _number(src, k["level"], level, 0.0, 1.0, "a confidence level in (0, 1)")
    if runs is not None and (isinstance(runs, bool) or not isinstance(runs, int) or runs < 1):
        raise InputError(src, k["runs"], f"must be an integer >= 1, got {runs!r}")
    target = check_out(out, overwrite, src, k["out"])
    if Path(draws).absolute() == target.absolute():
        raise InputError(src, k["draws"], "the campaign folder and the calibration file must differ")
    try:
        c = _campaign(campaign, runs, src, k["campaign"])
    except InputError as e:
        if e.key == "runs":
            raise InputError(src, k["runs"], e.problem) from None
        raise
    sc, block, test, cols = _detector(c, detector, src, k["detector"])
    T, t_enable = block.p("sample_period"), block.p("t_enable")
    planned = c.runs * max(0, math.floor((sc.stop - max(t_enable, sc.start)) / T - 1e-9) + 1) * T / 3600.0
    floor = -math.log1p(-level) / planned if planned > 0 else math.inf
    if floor > rate:
        log.warning("warning: %d draws give %.3g h of exposure: with no false alarm at all the %g bound is %.3g per hour "
                    "> %g; the threshold will not be certified (about %d draws would be needed)", c.runs, planned, level,
                    floor, rate, math.ceil(c.runs * floor / rate))

    try:
        o = run_campaign(c, draws, workers=workers, overwrite=overwrite, progress=progress, **cluster)
    except InputError as e:
        if e.source == "command line" and e.key == "--out":  # the campaign folder is this command's draws
            raise InputError(src, k["draws"], e.problem) from None
        raise
    if o.interrupted:
        raise Interrupted(f"stopped by a signal; {o.stored} of {o.total} draws stored in {o.folder}; rerun the same "
                          "command to compute the rest", 128 + o.interrupted)
    if o.lost:
        raise SimulationError(f"{o.lost} draws could not be computed; rerun the same command to retry them")
    ids, data = _runs(o.folder, cols, sc.stop)
    try:
        mu0, sigma = normalisation(data, t_enable)
    except ValueError as e:
        raise SimulationError(f"calibration of {detector}: {e}") from None
    n = block.n
    base = {f"mu0[{i + 1}]" if n > 1 else "mu0": float(mu0[i]) for i in range(n)}
    base.update({f"sigma[{i + 1}]" if n > 1 else "sigma": float(sigma[i]) for i in range(n)})
    block.set_parameters(base)
    block.initialize(sc.start)
    exposures = exposure_hours(data, T, t_enable)
    E = float(exposures.sum())
    if not E > 0:
        raise SimulationError(f"no sample at or after t_enable = {t_enable:g} s in the {len(data)} draws: nothing to count")

    def bound(N: int) -> float:
        return upper_bound(N, E, level)

    found = certify(block, data, exposures, rate, level)  # the one rule (diagnosis/calibration.py), as the arena's
    h, certified, curve = found["h"], found["certified"], found["curve"]
    counts = found["counts"]
    stats_at = _intervals(counts, exposures, level)
    given = {name: block.p(name) for name in next(g for cls, t, g in TESTS if t == test) + GIVEN}
    pset = {"h": h, "mu0": mu0.tolist() if n > 1 else float(mu0[0]), "sigma": sigma.tolist() if n > 1 else float(sigma[0]),
            **given}
    doc = {
        "tool": "ftcsim", "kind": KIND, "version": 1,
        "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "command": command or f"ftcsim.fdir_calibrate({shlex.quote(str(campaign))}, detector={detector!r}, "
                              f"rate_per_hour={rate:g}, level={level:g})",
        "detector": {"instance": detector, "model": sc.instances[detector].model_name, "test": test,
                     "input": cols},
        "parameter_set": pset,
        "fmu_parameters": {sc.instances[detector].model_name: pset},
        "target": {"false_alarms_per_hour": rate, "level": level},
        "certified": bool(certified),
        "counting": {**COUNTING, "persistence_samples": block.prm["persist"],
                     "rule": "detector replayed on each draw, restarting after each alarm decision; rate = alarms / exposure"},
        "statistics": {"runs": len(data), "run_ids": ids, **stats_at,
                       "hours_needed_for_target": -math.log1p(-level) / rate},
        "operating_curve": [{"h": hh, "false_alarms": nn, "rate_per_hour": nn / E, "upper_bound_per_hour": bound(nn)}
                            for hh, nn in curve],
        "campaign": {"file": str(c.path), "name": c.name, "sha256": c.digest, "draws": str(o.folder),
                     "scenario": str(sc.path), "scenario_sha256": _sha256(sc.path)},
    }
    check_out(target, overwrite, src, k["out"])  # again: the draws took a while, the file may have appeared
    # the one publisher: locked, written beside the target and renamed; a full disk is one line, nothing replaced
    OutputFile(target, "a calibration file", written_by_calibrate, overwrite=True, source=src, key=k["out"],
               foreign="was not written by `ftcsim fdir calibrate`").write(lambda tmp: write_json_atomic(tmp, doc))
    return doc
