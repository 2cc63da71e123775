"""Arena files (TOML): methods x plants x fault classes x hardware x draws, checked before anything
runs. Every problem is one ``InputError(file, key, problem)``; unknown keys are refused. Format::

    [arena]
    name = "ftc_arena"              # optional (default: the file's stem); names the leaderboard
    description = "..."
    draws = 20                      # draws per cell and fault class (>= 1)
    seed = 2026                     # one seed for every cell: draw k is the same random numbers for
                                    # every method (paired comparisons on common draws)
    mode = "inprocess"              # "inprocess" (default: the blocks in the workers' processes) or
                                    # "fmu" (the FMUs through fmpy; the same numbers, slower)
    fmu_dir = "fmus"                # optional FMU folder (inside this file's folder; default: build/fmus
                                    # of the installation, as ftcsim run)
    hardware = ["ideal", "realistic"]
    faults = ["none", "loe_step", "bias", "lost"]   # catalog classes (plant/fault_catalog.py);
                                    # "none" gives the fault-free draws of the detectors' calibration
    stop = 30.0                     # optional: cut every mission to this time (s): a slice, not the
                                    # papers' missions (the page says so)
    trajectory_step = 0.05          # s, spacing of the samples the metrics are computed from
    accuracy_tolerance = 2.0        # a method keeps its paper's accuracy with realistic hardware when its
                                    # median pointing error after settling on its own plant is within
                                    # this factor of the ideal-hardware median (and it settles as often)
    time_limit = 3600.0             # optional: s of wall time per run (a run over it is "failed")

    [statistics]
    bootstrap = 2000                # resamples of the bootstrap intervals (scipy.stats.bootstrap, percentile)
    confidence = 0.95               # of every interval
    alpha = 0.05                    # family-wise error rate of the paired comparisons (Holm)
    min_pairs = 10                  # fewer paired draws: a comparison is never "significant"

    [detection]                     # the arena's own detector (arena/detector.py), calibrated per cell
    false_alarms_per_hour = 5.0     # target rate over the fault-free draws (one the draws can support:
                                    # the largest of n peaks is exceeded with probability 1/(n + 1))
    persistence = 1.0               # s the statistic must stay above the threshold to raise an alarm
    margin = 0.2                    # threshold = (1 + margin) x the calibrated quantile

    [dispersions]                   # uniform ranges, drawn per draw index, common to every cell
    onset = [10.0, 30.0]            # s
    loss = [0.3, 0.7]               # fraction of effectiveness lost (LOE, intermittent)
    magnitude = [0.5, 1.5]          # x the plant's fault_torque (bias, time-varying)

    [plants.li2023]                 # one table per plant
    mission = 200.0                 # s: every cell on this plant flies this long (its paper's mission)
    band = 0.01                     # rad, pointing band of "time to band" (from the last manoeuvre of
                                    # the cell's attitude command or the fault onset, the later)
    fault_torque = 0.5              # N.m, nominal bias amplitude on this plant
    wheels = "wheels_hr12_12"       # realistic hardware (plant/hardware/datasheets.py parameter sets)
    gyro = "gyro_stim300"
    attitude_sensor = "st_small"    # StarTracker set (3-axis) or AngleSensor1 set (pitch axis)
    hold = "zoh_10hz"               # controller sample rate

    [methods.fasmc]
    label = "000 FAFEO + FASMC"
    paper = "000"
    claims = ["bias", "time_varying"]   # the fault classes its paper claims to handle (its fault model)
    claims_source = "000 (6), Assumption 1, (66)"   # where the paper says so

    [[cells]]                       # one method on one plant: its scenario file wires the loop with
    method = "fasmc"                # the fault catalog as instance "faults"
    plant = "xu2024"
    scenario = "scenarios/arena_fasmc_on_xu2024.toml"   # inside this file's folder
    gains = "redesigned"            # "own" (the paper's pair), "redesigned" (verified, arena/gains.py)
                                    # or "published" (the published gains as a robustness case)
    estimate = "est.f_hat"          # optional: the fault estimate, compared with ``truth``; its
                                    # detector's threshold is calibrated on the fault-free draws
    truth = "faults.fault"          # default faults.fault (the catalog's ground truth)
    nominal = 0.0                   # the estimate's fault-free value (1 for an effectiveness estimate)
    estimate_from = 5.0             # s: the estimator's start-up transient skipped by the detector

Paths never leave the arena file's folder. :func:`load` takes the command line's overrides (draws,
stop, faults, hardware, cells, mode), checked as the file is.
"""
from __future__ import annotations

import difflib
import hashlib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from orchestrator.api import InputError, read_toml, referenced

FAULT_CLASSES = {"none": 0, "loe_step": 1, "loe_ramp": 2, "bias": 3, "intermittent": 4, "time_varying": 5,
                 "stuck": 6, "lost": 7, "markov": 8}  # plant/fault_catalog.py
HARDWARE = ("ideal", "realistic")
GAINS = ("own", "redesigned", "published")
MODES = ("inprocess", "fmu")
ARENA_KEYS = ("name", "description", "draws", "seed", "mode", "fmu_dir", "hardware", "faults", "stop",
              "trajectory_step", "accuracy_tolerance", "time_limit")
TOP_KEYS = ("arena", "statistics", "detection", "dispersions", "plants", "methods", "cells")
STATISTICS_KEYS = ("bootstrap", "confidence", "alpha", "min_pairs")
DETECTION_KEYS = ("false_alarms_per_hour", "persistence", "margin")
DISPERSION_KEYS = ("onset", "loss", "magnitude")
PLANT_KEYS = ("mission", "band", "fault_torque", "wheels", "gyro", "attitude_sensor", "hold")
METHOD_KEYS = ("label", "paper", "claims", "claims_source")
CELL_KEYS = ("method", "plant", "scenario", "gains", "estimate", "truth", "nominal", "estimate_from")
MAX_DRAWS = 100_000


@dataclass
class Plant:
    name: str
    mission: float  # s
    band: float  # rad
    fault_torque: float  # N.m
    hardware: dict  # wheels / gyro / attitude_sensor / hold -> parameter set name


@dataclass
class Method:
    name: str
    label: str
    paper: str
    claims: tuple = ()  # fault classes its paper claims to handle ("none" is always within)
    claims_source: str = ""

    def claims_class(self, fault: str) -> bool:
        return fault == "none" or fault in self.claims


@dataclass
class Cell:
    method: str
    plant: str
    scenario: Path
    gains: str
    estimate: str | None = None
    truth: str = "faults.fault"
    nominal: float = 0.0
    estimate_from: float = 5.0

    @property
    def name(self) -> str:
        return f"{self.method}_on_{self.plant}"


@dataclass
class Statistics:
    bootstrap: int = 2000
    confidence: float = 0.95
    alpha: float = 0.05
    min_pairs: int = 10


@dataclass
class Detection:
    false_alarms_per_hour: float = 5.0
    persistence: float = 1.0  # s
    margin: float = 0.2


@dataclass
class Arena:
    path: Path
    text: str
    name: str
    description: str
    draws: int
    seed: int
    mode: str
    fmu_dir: Path | None
    hardware: list
    faults: list
    stop: float | None
    trajectory_step: float
    accuracy_tolerance: float
    time_limit: float | None
    dispersions: dict  # name -> (low, high)
    statistics: Statistics = field(default_factory=Statistics)
    detection: Detection = field(default_factory=Detection)
    plants: dict = field(default_factory=dict)
    methods: dict = field(default_factory=dict)
    cells: list = field(default_factory=list)
    overrides: dict = field(default_factory=dict)  # what the command line changed: {option: value}

    @property
    def digest(self) -> str:
        return hashlib.sha256(self.text.encode("utf-8")).hexdigest()

    @property
    def bootstrap(self) -> int:
        return self.statistics.bootstrap

    def mission(self, cell: Cell) -> float:
        """The stop time (s) the cell flies: its plant's mission, cut to the arena's ``stop`` if shorter."""
        mission = self.plants[cell.plant].mission
        return mission if self.stop is None else min(self.stop, mission)

    @property
    def n_runs(self) -> int:
        """Runs the arena stands for (cells x hardware x fault classes x draws); fewer are computed
        (the fault-free draws with ideal hardware are one deterministic run per cell)."""
        return len(self.cells) * len(self.hardware) * len(self.faults) * self.draws


# -- small checks ---------------------------------------------------------------------------------------------
def _keys(src, key, table, known):
    if not isinstance(table, dict):
        raise InputError(src, key, f"expected a table, got {type(table).__name__}")
    for k in table:
        if k not in known:
            close = difflib.get_close_matches(str(k), known, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else f" (known: {', '.join(known)})"
            raise InputError(src, f"{key}.{k}" if key else k, f"unknown key{hint}")
    return table


def _name(src, key, x) -> str:
    """A plant's or method's name: letters, digits, '_' and '-' (it names files)."""
    if not isinstance(x, str) or not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}", x):
        raise InputError(src, key, f"{x!r} is not a name: use letters, digits, '_' and '-' (at most 64)")
    return x


def _str(src, key, x) -> str:
    if not isinstance(x, str) or not x.strip():
        raise InputError(src, key, f"expected a non-empty string, got {x!r}")
    return x


def _num(src, key, x, positive=False, minimum=None) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
        raise InputError(src, key, f"expected a finite number, got {x!r}")
    if positive and x <= 0:
        raise InputError(src, key, f"must be > 0, got {x!r}")
    if minimum is not None and x < minimum:
        raise InputError(src, key, f"must be >= {minimum}, got {x!r}")
    return float(x)


def _int(src, key, x, minimum, maximum=None) -> int:
    if isinstance(x, bool) or not isinstance(x, int):
        raise InputError(src, key, f"expected a whole number, got {x!r}")
    if x < minimum and (maximum is None or maximum >= 2**62):
        raise InputError(src, key, f"must be >= {minimum}, got {x}")
    if x < minimum or (maximum is not None and x > maximum):
        raise InputError(src, key, f"must be in {minimum}..{maximum}, got {x}")
    return x


def _choices(src, key, x, known) -> list:
    if isinstance(x, str):
        x = [x]
    if not isinstance(x, list) or not x:
        raise InputError(src, key, f"expected a non-empty list of {', '.join(known)}")
    for j, v in enumerate(x):
        if v not in known:
            raise InputError(src, f"{key}[{j}]", f"unknown {v!r} (known: {', '.join(known)})")
    if len(set(x)) != len(x):
        raise InputError(src, key, "lists a value twice")
    return list(x)


def _range(src, key, x, lo=None, hi=None) -> tuple:
    if not isinstance(x, list) or len(x) != 2:
        raise InputError(src, key, f"expected [low, high], got {x!r}")
    a, b = (_num(src, key, v) for v in x)
    if b < a:
        raise InputError(src, key, f"high {b} < low {a}")
    if (lo is not None and a < lo) or (hi is not None and b > hi):
        raise InputError(src, key, f"must lie in [{lo}, {hi}], got [{a}, {b}]")
    return (a, b)


def inside(src, key, folder: Path, rel) -> Path:
    """``rel`` (a string) resolved against ``folder``; refused if it leaves the folder."""
    rel = _str(src, key, rel)
    try:
        p = referenced(folder, rel, src, key)  # symbolic links followed: they too must stay inside
    except InputError as e:
        raise InputError(src, key, f"{rel!r} leaves the arena file's folder ({e.problem})") from None
    if p == Path(folder).resolve():
        raise InputError(src, key, f"{rel!r} leaves the arena file's folder")
    return p


def _parameter_set(src, key, name, known) -> str:
    name = _str(src, key, name)
    if name not in known:
        close = difflib.get_close_matches(name, list(known), n=1)
        raise InputError(src, key, f"unknown parameter set {name!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
    return name


# -- the file -------------------------------------------------------------------------------------------------
def load(path, *, draws=None, stop=None, faults=None, hardware=None, only=None, mode=None) -> Arena:
    """Read and check an arena file (module docstring); the cells' scenario files must exist. The
    keywords are the command line's overrides (``--draws``, ``--stop``, ``--faults``, ``--hardware``,
    ``--only`` cell names, ``--fmu`` as ``mode="fmu"``): checked here, named as options."""
    from plant.hardware.datasheets import ANGLE_SENSORS, GYROS, HOLDS, STAR_TRACKERS, WHEELS

    path = Path(path)
    src = str(path)
    if path.suffix != ".toml":
        raise InputError(src, "file", "an arena file is a .toml file")
    if not path.exists() and not path.is_symlink():
        raise InputError(src, "file", "no such file")
    text, doc = read_toml(path, "arena file", src, "file")  # the one reader: regular, bounded, UTF-8, depth
    _keys(src, "", doc, TOP_KEYS)
    for k in ("arena", "plants", "methods", "cells"):
        if k not in doc:
            raise InputError(src, k, "missing")
    meta = _keys(src, "arena", doc["arena"], ARENA_KEYS)
    folder = path.parent
    a = Arena(
        path=path, text=text, name=_str(src, "arena.name", meta.get("name", path.stem)),
        description=str(meta.get("description", "")),
        draws=_int(src, "arena.draws", meta.get("draws", 20), 1, MAX_DRAWS),
        seed=_int(src, "arena.seed", meta.get("seed", 0), 0, 2**63 - 1),  # stored as int64 in every table
        mode=meta.get("mode", "inprocess"),
        fmu_dir=inside(src, "arena.fmu_dir", folder, meta["fmu_dir"]) if "fmu_dir" in meta else None,
        hardware=_choices(src, "arena.hardware", meta.get("hardware", ["ideal"]), HARDWARE),
        faults=_choices(src, "arena.faults", meta.get("faults", ["none", "loe_step", "bias"]), list(FAULT_CLASSES)),
        stop=_num(src, "arena.stop", meta["stop"], positive=True) if "stop" in meta else None,
        trajectory_step=_num(src, "arena.trajectory_step", meta.get("trajectory_step", 0.05), positive=True),
        accuracy_tolerance=_num(src, "arena.accuracy_tolerance", meta.get("accuracy_tolerance", 2.0), minimum=1.0),
        time_limit=_num(src, "arena.time_limit", meta["time_limit"], positive=True) if "time_limit" in meta else None,
        dispersions={})
    if a.mode not in MODES:
        raise InputError(src, "arena.mode", f"unknown mode {a.mode!r} (known: {', '.join(MODES)})")
    st = _keys(src, "statistics", doc.get("statistics", {}), STATISTICS_KEYS)
    a.statistics = Statistics(
        bootstrap=_int(src, "statistics.bootstrap", st.get("bootstrap", 2000), 100, 100_000),
        confidence=_fraction(src, "statistics.confidence", st.get("confidence", 0.95)),
        alpha=_fraction(src, "statistics.alpha", st.get("alpha", 0.05)),
        min_pairs=_int(src, "statistics.min_pairs", st.get("min_pairs", 10), 2, MAX_DRAWS))
    de = _keys(src, "detection", doc.get("detection", {}), DETECTION_KEYS)
    a.detection = Detection(
        false_alarms_per_hour=_num(src, "detection.false_alarms_per_hour", de.get("false_alarms_per_hour", 5.0),
                                   positive=True),
        persistence=_num(src, "detection.persistence", de.get("persistence", 1.0), minimum=0.0),
        margin=_num(src, "detection.margin", de.get("margin", 0.2), minimum=0.0))
    disp = _keys(src, "dispersions", doc.get("dispersions", {}), DISPERSION_KEYS)
    a.dispersions = {"onset": _range(src, "dispersions.onset", disp.get("onset", [10.0, 30.0]), lo=0.0),
                     "loss": _range(src, "dispersions.loss", disp.get("loss", [0.3, 0.7]), lo=0.0, hi=1.0),
                     "magnitude": _range(src, "dispersions.magnitude", disp.get("magnitude", [0.5, 1.5]))}

    plants = doc["plants"]
    if not isinstance(plants, dict) or not plants:
        raise InputError(src, "plants", "expected at least one [plants.NAME] table")
    for name, t in plants.items():
        key = f"plants.{name}"
        _name(src, key, name)
        _keys(src, key, t, PLANT_KEYS)
        for need in ("mission", "band", "fault_torque"):
            if need not in t:
                raise InputError(src, f"{key}.{need}", "missing")
        hw = {}
        for k, known in (("wheels", WHEELS), ("gyro", GYROS), ("attitude_sensor", {**STAR_TRACKERS, **ANGLE_SENSORS}),
                         ("hold", HOLDS)):
            if k in t:
                hw[k] = _parameter_set(src, f"{key}.{k}", t[k], known)
            elif "realistic" in a.hardware or (hardware and "realistic" in hardware):
                raise InputError(src, f"{key}.{k}", "missing (realistic hardware is flown)")
        a.plants[name] = Plant(name, _num(src, f"{key}.mission", t["mission"], positive=True),
                               _num(src, f"{key}.band", t["band"], positive=True),
                               _num(src, f"{key}.fault_torque", t["fault_torque"], positive=True), hw)

    methods = doc["methods"]
    if not isinstance(methods, dict) or not methods:
        raise InputError(src, "methods", "expected at least one [methods.NAME] table")
    for name, t in methods.items():
        key = f"methods.{name}"
        _name(src, key, name)
        _keys(src, key, t, METHOD_KEYS)
        for need in ("paper", "claims"):
            if need not in t:
                raise InputError(src, f"{key}.{need}", "missing" + (" (the fault classes its paper claims to handle: "
                                                                   "[] for none)" if need == "claims" else ""))
        claims = t["claims"]
        if not isinstance(claims, list):
            raise InputError(src, f"{key}.claims", "expected a list of fault classes")
        claims = _choices(src, f"{key}.claims", claims, list(FAULT_CLASSES)) if claims else []
        a.methods[name] = Method(name, str(t.get("label", name)), _str(src, f"{key}.paper", t["paper"]),
                                 tuple(claims), str(t.get("claims_source", "")))

    cells = doc["cells"]
    if not isinstance(cells, list) or not cells:
        raise InputError(src, "cells", "expected at least one [[cells]] table")
    seen = set()
    for j, t in enumerate(cells):
        key = f"cells[{j}]"
        _keys(src, key, t, CELL_KEYS)
        for need in ("method", "plant", "scenario", "gains"):
            if need not in t:
                raise InputError(src, f"{key}.{need}", "missing")
            _str(src, f"{key}.{need}", t[need])  # a name, never a list or a number
        for ref, table in (("method", a.methods), ("plant", a.plants)):
            if t[ref] not in table:
                raise InputError(src, f"{key}.{ref}", f"unknown {ref} {t[ref]!r} (known: {', '.join(table)})")
        if t["gains"] not in GAINS:
            raise InputError(src, f"{key}.gains", f"unknown {t['gains']!r} (known: {', '.join(GAINS)})")
        scenario = inside(src, f"{key}.scenario", folder, t["scenario"])
        if scenario.suffix != ".toml":
            raise InputError(src, f"{key}.scenario", "a cell's scenario is a .toml file")
        if not scenario.is_file():
            raise InputError(src, f"{key}.scenario", f"no such file {t['scenario']!r}")
        c = Cell(t["method"], t["plant"], scenario, t["gains"])
        if c.name in seen:
            raise InputError(src, key, f"cell {c.name} listed twice")
        seen.add(c.name)
        if "estimate" in t:
            c.estimate = _str(src, f"{key}.estimate", t["estimate"])
            c.truth = _str(src, f"{key}.truth", t.get("truth", "faults.fault"))
            c.nominal = _num(src, f"{key}.nominal", t.get("nominal", 0.0))
            c.estimate_from = _num(src, f"{key}.estimate_from", t.get("estimate_from", 5.0), minimum=0.0)
        else:
            for k in ("truth", "nominal", "estimate_from"):
                if k in t:
                    raise InputError(src, f"{key}.{k}", "applies only with an estimate")
        a.cells.append(c)
    _override(a, draws=draws, stop=stop, faults=faults, hardware=hardware, only=only, mode=mode)
    longest = max((a.plants[c.plant].mission for c in a.cells), default=None)
    if a.stop is not None and longest is not None and a.stop > longest:
        where = ("command line", "--stop") if "stop" in a.overrides else (src, "arena.stop")
        raise InputError(*where, f"{a.stop:g} s is longer than every mission (the longest is {longest:g} s): stop cuts "
                                 "missions, it does not extend them")
    return a


def _fraction(src, key, x) -> float:
    v = _num(src, key, x)
    if not 0.0 < v < 1.0:
        raise InputError(src, key, f"must lie strictly between 0 and 1, got {x!r}")
    return v


def _option_list(key, x) -> list:
    """A command-line list: several values, each possibly comma-separated."""
    if isinstance(x, str):
        x = [x]
    if not isinstance(x, (list, tuple)) or not all(isinstance(v, str) for v in x):
        raise InputError("command line", key, f"expected names, got {x!r}")
    out = [v.strip() for item in x for v in item.split(",") if v.strip()]
    if not out:
        raise InputError("command line", key, "expected at least one name")
    return out


def _override(a: Arena, *, draws, stop, faults, hardware, only, mode) -> None:
    """The command line's overrides (checked as the file's values are, named by their option)."""
    src = "command line"
    if draws is not None:
        a.draws = _int(src, "--draws", draws, 1, MAX_DRAWS)
        a.overrides["draws"] = a.draws
    if stop is not None:
        a.stop = _num(src, "--stop", stop, positive=True)
        a.overrides["stop"] = a.stop
    if faults is not None:
        a.faults = _choices(src, "--faults", _option_list("--faults", faults), list(FAULT_CLASSES))
        a.overrides["faults"] = list(a.faults)
    if hardware is not None:
        a.hardware = _choices(src, "--hardware", _option_list("--hardware", hardware), HARDWARE)
        a.overrides["hardware"] = list(a.hardware)
        if "realistic" in a.hardware:
            for p in a.plants.values():
                missing = [k for k in ("wheels", "gyro", "attitude_sensor", "hold") if k not in p.hardware]
                if missing:
                    raise InputError(a.path, f"plants.{p.name}.{missing[0]}", "missing (--hardware lists 'realistic')")
    if only is not None:
        names = _option_list("--only", only)
        known = [c.name for c in a.cells]
        for n in names:
            if n not in known:
                close = difflib.get_close_matches(n, known, n=1)
                raise InputError(src, "--only", f"no cell {n!r} in {a.path.name}" + (
                    f" (did you mean {close[0]!r}?)" if close else f" (cells: {', '.join(known)})"))
        if len(set(names)) != len(names):
            raise InputError(src, "--only", "names a cell twice")
        a.cells = [c for c in a.cells if c.name in names]
        a.overrides["only"] = names
    if mode is not None:
        if mode not in MODES:
            raise InputError(src, "--mode", f"unknown mode {mode!r} (known: {', '.join(MODES)})")
        a.mode = mode
        a.overrides["mode"] = mode
