"""Arena files (TOML): methods x plants x fault classes x hardware x draws, checked before anything
runs. Every problem is one ``InputError(file, key, problem)``; unknown keys are refused. Format::

    [arena]
    name = "ftc_arena"              # optional (default: the file's stem); names the leaderboard
    description = "..."
    draws = 20                      # draws per cell and fault class (>= 1)
    sensor_draws = 5                # optional: draws of each sensor-fault class (default: draws)
    seed = 2026                     # one seed for every cell: draw k is the same random numbers for
                                    # every method (paired comparisons on common draws)
    mode = "inprocess"              # "inprocess" (default: the blocks in the workers' processes) or
                                    # "fmu" (the FMUs through fmpy; the same numbers, slower)
    fmu_dir = "fmus"                # optional FMU folder (inside this file's folder; default: build/fmus
                                    # of the installation, as ftcsim run)
    hardware = ["ideal", "realistic"]
    faults = ["none", "loe_step", "bias", "lost", "gyro_bias"]   # actuator classes (plant/fault_catalog.py)
                                    # and sensor classes (plant/sensor_faults.py: gyro_bias, gyro_drift,
                                    # gyro_stuck, st_outage, st_frozen; realistic hardware only, where the
                                    # sensor exists); "none" gives the fault-free draws of the calibration
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

    [detection]                     # every estimator's decision chain (diagnosis/, arena/fdir.py)
    detectors = ["cusum", "glr", "chi2"]   # change detectors of diagnosis/detectors.py; the first is the one
                                    # closed in the loop where a reconfiguration is flown
    false_alarms_per_hour = 10.0    # target rate: each chain's threshold is the smallest whose one-sided
    level = 0.95                    # Poisson bound at this level on its fault-free draws meets it
    persistence = 0.2               # s the statistic must stay at or above the threshold
    drift = 0.5                     # CUSUM drift (sigma): half the smallest mean change it is built for
    window = 1.0                    # s: GLR and chi-square (mean form) window
    isolation_window = 0.5          # s from the alarm to the isolation's decision

    [sensor_faults]                 # sizes of the sensor classes (scaled by dispersions.magnitude)
    gyro_bias = 0.002               # rad/s, a bias step on one drawn axis
    gyro_drift = 0.0002             # rad/s^2, a drift ramp on one drawn axis
    st_outage = 10.0                # s: how long the star tracker delivers nothing (a stale attitude)

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
                                    # decision chain is calibrated on the cell's fault-free draws
    truth = "faults.fault"          # default faults.fault (the catalog's ground truth)
    estimate_from = 5.0             # s: the estimator's start-up transient the detector ignores

Paths never leave the arena file's folder. :func:`load` takes the command line's overrides (draws,
stop, faults, hardware, cells, mode), checked as the file is.
"""
from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass, field
from pathlib import Path

from orchestrator.api import InputError, declared, read_toml, referenced

FAULT_CLASSES = {"none": 0, "loe_step": 1, "loe_ramp": 2, "bias": 3, "intermittent": 4, "time_varying": 5,
                 "stuck": 6, "lost": 7, "markov": 8}  # plant/fault_catalog.py
# sensor classes (plant/sensor_faults.py): name -> (the fault block's instance, its fault_class); realistic
# hardware only, on the cells whose loop has that sensor (a gyro: every cell; a star tracker: the 3-axis craft)
SENSOR_FAULTS = {"gyro_bias": ("gf", 1), "gyro_drift": ("gf", 2), "gyro_stuck": ("gf", 3), "st_outage": ("stf", 1),
                 "st_frozen": ("stf", 2)}
CLASSES = [*FAULT_CLASSES, *SENSOR_FAULTS]
DETECTORS = ("cusum", "glr", "chi2")
HARDWARE = ("ideal", "realistic")
GAINS = ("own", "redesigned", "published")
MODES = ("inprocess", "fmu")
HARDWARE_KEYS = ("wheels", "gyro", "attitude_sensor", "hold")
MAX_DRAWS = 100_000
ELSEWHERE = (
    "a cell's method and plant are tables of this file; its scenario lies inside this file's folder (symbolic links "
    "followed) and exists; a method_on_plant cell is listed once",
    "every plant gives wheels, gyro, attitude_sensor and hold when realistic hardware is flown (arena.hardware or "
    "--hardware)",
    "a dispersion range's high is at least its low",
    "a sensor-fault class flies with realistic hardware only; detection.window is a whole number of every estimator "
    "cell's sample periods (trajectory_step rounded to whole communication steps)",
    "arena.stop is at most the longest mission; the command line's overrides (--draws, --stop, --faults, --hardware, "
    "--only, --fmu) are checked as the file's values",
    "arena.fmu_dir lies inside this file's folder",
)


@functools.cache
def arena_format() -> declared.Format:
    """The declaration of arena files (the module docstring): their checks and their JSON Schema."""
    from plant.hardware.datasheets import ANGLE_SENSORS, GYROS, HOLDS, STAR_TRACKERS, WHEELS

    d = declared
    name = d.Text(pattern=r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}", rule_text="is not a name: use letters, digits, '_' and '-' "
                                                                       "(at most 64)")
    fault = d.Choice(tuple(CLASSES), what="", description="a fault class: the actuators' catalog (plant/fault_catalog.py) "
                     "or a sensor fault (plant/sensor_faults.py; realistic hardware only)")

    def choices(rule, default, what):
        return d.ListOf(rule, what=f"a non-empty list of {what}", min_items=1, single=True, unique=True, default=default)

    def hardware_set(known, what):
        return d.Choice(tuple(known), what="parameter set", description=f"{what} (plant/hardware/datasheets.py)")

    arena = d.Table({
        "name": d.Text("names the leaderboard (default: the file's stem)"),
        "description": d.Text(empty=True, default=""),
        "draws": d.Whole("draws per cell and fault class", 1, MAX_DRAWS, default=20),
        "sensor_draws": d.Whole("draws of each sensor-fault class (default: draws)", 1, MAX_DRAWS),
        "seed": d.Whole("one seed for every cell: draw k is the same random numbers for every method", 0,
                        declared.INT64_MAX, default=0),
        "mode": d.Choice(MODES, what="mode", default="inprocess", description="inprocess: the blocks in the workers' "
                         "processes; fmu: the FMUs through fmpy (the same numbers, slower)"),
        "fmu_dir": d.Text("FMU folder inside this file's folder (default: build/fmus of the installation)"),
        "hardware": choices(d.Choice(HARDWARE, what=""), ["ideal"], ", ".join(HARDWARE)),
        "faults": choices(fault, ["none", "loe_step", "bias"], ", ".join(CLASSES)),
        "stop": d.Number("s: cut every mission to this time (a slice, not the papers' missions)", positive=True),
        "trajectory_step": d.Number("s, spacing of the samples the metrics are computed from", positive=True,
                                    default=0.05),
        "accuracy_tolerance": d.Number("factor of the ideal-hardware median pointing error a method may reach with "
                                       "realistic hardware", lower=1.0, default=2.0),
        "time_limit": d.Seconds("s of wall time per run (a run over it is failed)"),
    })
    plant = d.Table({
        "mission": d.Number("s: every cell on this plant flies this long", positive=True),
        "band": d.Number("rad, pointing band of the time to band", positive=True),
        "fault_torque": d.Number("N.m, nominal bias amplitude on this plant", positive=True),
        "wheels": hardware_set(WHEELS, "reaction wheels"), "gyro": hardware_set(GYROS, "gyro"),
        "attitude_sensor": hardware_set({**STAR_TRACKERS, **ANGLE_SENSORS}, "star tracker (3-axis) or angle sensor "
                                        "(pitch axis)"),
        "hold": hardware_set(HOLDS, "controller sample rate")}, required=("mission", "band", "fault_torque"))
    method = d.Table({
        "label": d.Text("as the leaderboard shows it (default: the method's name)"),
        "paper": d.Text("the paper's id (000 ...)"),
        "claims": d.ListOf(fault, "the fault classes its paper claims to handle", what="a list of fault classes",
                           unique=True, missing=" (the fault classes its paper claims to handle: [] for none)"),
        "claims_source": d.Text("where the paper says so", empty=True, default="")}, required=("paper", "claims"))
    cell = d.Table({
        "method": d.Text("a [methods] table of this file"), "plant": d.Text("a [plants] table of this file"),
        "scenario": d.Text("the cell's scenario file (.toml), inside this file's folder"),
        "gains": d.Choice(GAINS, what="", description="own: the paper's pair; redesigned: verified (arena/gains.py); "
                          "published: the published gains as a robustness case"),
        "estimate": d.Text("the fault estimate ('instance.output'), compared with truth"),
        "truth": d.Text("the ground truth ('instance.output')", default="faults.fault"),
        "estimate_from": d.Number("s: the estimator's start-up transient the decision chain ignores", lower=0.0,
                                  default=5.0)},
        required=("method", "plant", "scenario", "gains"),
        only_with={"truth": "estimate", "estimate_from": "estimate"})
    root = d.Table({
        "arena": arena,
        "statistics": d.Table({
            "bootstrap": d.Whole("resamples of the bootstrap intervals", 100, 100_000, default=2000),
            "confidence": d.Number("of every interval", positive=True, below=1.0, default=0.95),
            "alpha": d.Number("family-wise error rate of the paired comparisons (Holm)", positive=True, below=1.0,
                              default=0.05),
            "min_pairs": d.Whole("fewer paired draws: a comparison is never significant", 2, MAX_DRAWS, default=10)},
            default={}),
        "detection": d.Table({
            "detectors": d.ListOf(d.Choice(DETECTORS, what=""), "change detectors of diagnosis/; the first is closed "
                                  "in the loop where a reconfiguration is flown", what="a non-empty list of "
                                  + ", ".join(DETECTORS), min_items=1, single=True, unique=True, default=list(DETECTORS)),
            "false_alarms_per_hour": d.Number("target rate: the one-sided Poisson bound on each chain's fault-free "
                                              "draws meets it", positive=True, default=10.0),
            "level": d.Number("confidence level of that bound", positive=True, below=1.0, default=0.95),
            "persistence": d.Number("s the statistic must stay at or above the threshold", lower=0.0, default=0.2),
            "drift": d.Number("CUSUM drift (sigma)", lower=0.0, default=0.5),
            "window": d.Number("s: GLR and chi-square window (a whole number of sample periods)", positive=True,
                               default=1.0),
            "isolation_window": d.Number("s from the alarm to the isolation's decision", lower=0.0, default=0.5)},
            default={}),
        "sensor_faults": d.Table({
            "gyro_bias": d.Number("rad/s, the gyro bias step (x dispersions.magnitude)", positive=True, default=0.002),
            "gyro_drift": d.Number("rad/s^2, the gyro drift rate (x dispersions.magnitude)", positive=True,
                                   default=0.0002),
            "st_outage": d.Number("s the star tracker delivers no attitude", positive=True, default=10.0)},
            default={}),
        "dispersions": d.Table({
            "onset": d.Interval("s, fault onset", lower=0.0, default=[10.0, 30.0]),
            "loss": d.Interval("fraction of effectiveness lost", lower=0.0, upper=1.0, default=[0.3, 0.7]),
            "magnitude": d.Interval("x the plant's fault_torque", default=[0.5, 1.5])}, default={}),
        "plants": d.Table(extra=plant, names=name, min_items=1, empty="expected at least one [plants.NAME] table"),
        "methods": d.Table(extra=method, names=name, min_items=1, empty="expected at least one [methods.NAME] table"),
        "cells": d.ListOf(cell, what="at least one [[cells]] table", min_items=1),
    }, required=("arena", "plants", "methods", "cells"))
    return d.Format("arena", "ftcsim arena file", root, "An arena: methods x plants x fault classes x hardware x draws "
                    "(`ftcsim arena`, docs/arena-design.md).", elsewhere=ELSEWHERE)


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


def is_sensor(fault: str) -> bool:
    """A sensor-fault class (realistic hardware only)."""
    return fault in SENSOR_FAULTS


@dataclass
class Cell:
    method: str
    plant: str
    scenario: Path
    gains: str
    estimate: str | None = None
    truth: str = "faults.fault"
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
    detectors: tuple = DETECTORS
    false_alarms_per_hour: float = 10.0
    level: float = 0.95
    persistence: float = 0.2  # s
    drift: float = 0.5  # sigma
    window: float = 1.0  # s
    isolation_window: float = 0.5  # s


@dataclass
class SensorFaults:
    gyro_bias: float = 0.002  # rad/s
    gyro_drift: float = 0.0002  # rad/s^2
    st_outage: float = 10.0  # s


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
    sensor_faults: SensorFaults = field(default_factory=SensorFaults)
    sensor_draws: int | None = None
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

    def draws_of(self, fault: str) -> int:
        """Draws of a fault class: ``sensor_draws`` for a sensor class (default: ``draws``)."""
        return self.sensor_draws if is_sensor(fault) and self.sensor_draws is not None else self.draws

    @property
    def actuator_faults(self) -> list:
        return [f for f in self.faults if not is_sensor(f)]

    @property
    def sensor_classes(self) -> list:
        return [f for f in self.faults if is_sensor(f)]

    @property
    def n_runs(self) -> int:
        """Runs the arena stands for with the actuator classes (cells x hardware x classes x draws); fewer
        are computed (the fault-free draws with ideal hardware are one deterministic run per cell), and
        the sensor classes add their draws on the realistic cells that have the sensor."""
        return len(self.cells) * len(self.hardware) * len(self.actuator_faults) * self.draws


# -- the file -------------------------------------------------------------------------------------------------
def inside(src, key, folder: Path, rel: str) -> Path:
    """``rel`` resolved against ``folder``; refused if it leaves the folder (symbolic links followed)."""
    try:
        p = referenced(folder, rel, src, key)
    except InputError as e:
        raise InputError(src, key, f"{rel!r} leaves the arena file's folder ({e.problem})") from None
    if p == Path(folder).resolve():
        raise InputError(src, key, f"{rel!r} leaves the arena file's folder")
    return p


def load(path, *, draws=None, stop=None, faults=None, hardware=None, only=None, mode=None) -> Arena:
    """Read and check an arena file (module docstring, :func:`arena_format`); the cells' scenario files must
    exist. The keywords are the command line's overrides (``--draws``, ``--stop``, ``--faults``,
    ``--hardware``, ``--only`` cell names, ``--fmu`` as ``mode="fmu"``): checked here, named as options."""
    path = Path(path)
    src = str(path)
    if path.suffix != ".toml":
        raise InputError(src, "file", "an arena file is a .toml file")
    if not path.exists() and not path.is_symlink():
        raise InputError(src, "file", "no such file")
    text, doc = read_toml(path, "arena file", src, "file")  # the one reader: regular, bounded, UTF-8, depth
    doc = arena_format().check(src, doc)
    meta, folder = doc["arena"], path.parent
    a = Arena(path=path, text=text, name=meta.get("name", path.stem), description=meta["description"],
              draws=meta["draws"], seed=meta["seed"], mode=meta["mode"],
              fmu_dir=inside(src, "arena.fmu_dir", folder, meta["fmu_dir"]) if "fmu_dir" in meta else None,
              hardware=meta["hardware"], faults=meta["faults"], stop=meta.get("stop"),
              trajectory_step=meta["trajectory_step"], accuracy_tolerance=meta["accuracy_tolerance"],
              time_limit=meta.get("time_limit"), dispersions={k: tuple(v) for k, v in doc["dispersions"].items()},
              statistics=Statistics(**doc["statistics"]),
              detection=Detection(**{**doc["detection"], "detectors": tuple(doc["detection"]["detectors"])}),
              sensor_faults=SensorFaults(**doc["sensor_faults"]), sensor_draws=meta.get("sensor_draws"))
    realistic = "realistic" in a.hardware or (hardware and "realistic" in hardware)
    for name, t in doc["plants"].items():
        missing = [k for k in HARDWARE_KEYS if k not in t]
        if missing and realistic:
            raise InputError(src, f"plants.{name}.{missing[0]}", "missing (realistic hardware is flown)")
        a.plants[name] = Plant(name, t["mission"], t["band"], t["fault_torque"], {k: t[k] for k in HARDWARE_KEYS if k in t})
    for name, t in doc["methods"].items():
        a.methods[name] = Method(name, t.get("label", name), t["paper"], tuple(t["claims"]), t["claims_source"])
    for j, t in enumerate(doc["cells"]):
        key = f"cells[{j}]"
        for ref, table in (("method", a.methods), ("plant", a.plants)):
            if t[ref] not in table:
                raise InputError(src, f"{key}.{ref}", f"unknown {ref} {t[ref]!r}{declared.hint(t[ref], table)} "
                                                      f"(known: {', '.join(table)})")
        scenario = inside(src, f"{key}.scenario", folder, t["scenario"])
        if scenario.suffix != ".toml":
            raise InputError(src, f"{key}.scenario", "a cell's scenario is a .toml file")
        if not scenario.is_file():
            raise InputError(src, f"{key}.scenario", f"no such file {t['scenario']!r}")
        c = Cell(t["method"], t["plant"], scenario, t["gains"], t.get("estimate"), t["truth"], t["estimate_from"])
        if any(c.name == other.name for other in a.cells):
            raise InputError(src, key, f"cell {c.name} listed twice")
        a.cells.append(c)
    _override(a, draws=draws, stop=stop, faults=faults, hardware=hardware, only=only, mode=mode)
    sensors = a.sensor_classes
    if sensors and "realistic" not in a.hardware:
        where = ("command line", "--faults" if "faults" in a.overrides else "--hardware") if (
            "faults" in a.overrides or "hardware" in a.overrides) else (src, "arena.faults")
        raise InputError(*where, f"{sensors[0]} is a sensor-fault class: it flies with realistic hardware only (where the "
                                 f"sensors are), and the arena flies {', '.join(a.hardware)}")
    longest = max((a.plants[c.plant].mission for c in a.cells), default=None)
    if a.stop is not None and longest is not None and a.stop > longest:
        where = ("command line", "--stop") if "stop" in a.overrides else (src, "arena.stop")
        raise InputError(*where, f"{a.stop:g} s is longer than every mission (the longest is {longest:g} s): stop cuts "
                                 "missions, it does not extend them")
    return a


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
    """The command line's overrides, checked by the file's own rules and named by their option."""
    src, rules = "command line", arena_format().root.fields["arena"].fields
    for option, value in (("draws", draws), ("stop", stop), ("faults", faults), ("hardware", hardware), ("mode", mode)):
        if value is None:
            continue
        given = _option_list(f"--{option}", value) if option in ("faults", "hardware") else value
        setattr(a, option, rules[option].check(src, f"--{option}", given))
        a.overrides[option] = getattr(a, option)
        if option == "draws":  # every class's draws, the sensor classes' too
            a.sensor_draws = None
    if hardware is not None and "realistic" in a.hardware:
        for p in a.plants.values():
            missing = [k for k in HARDWARE_KEYS if k not in p.hardware]
            if missing:
                raise InputError(a.path, f"plants.{p.name}.{missing[0]}", "missing (--hardware lists 'realistic')")
    if only is not None:
        names = _option_list("--only", only)
        known = [c.name for c in a.cells]
        for n in names:
            if n not in known:
                raise InputError(src, "--only", f"no cell {n!r} in {a.path.name}" + (
                    declared.hint(n, known) or f" (cells: {', '.join(known)})"))
        if len(set(names)) != len(names):
            raise InputError(src, "--only", "names a cell twice")
        a.cells = [c for c in a.cells if c.name in names]
        a.overrides["only"] = names
