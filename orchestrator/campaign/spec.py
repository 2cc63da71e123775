"""Campaign files (TOML): Monte Carlo dispersions, sweeps and method comparisons over a scenario.

A campaign names a base scenario and expands into runs; each run is exactly an ``ftcsim run``
of that scenario with overrides (``orchestrator.api.load``: parameters as
``{"instance.parameter": value}``, design files as gains, start/stop/step). Everything is checked
here, before anything runs: every problem is one ``InputError(file, key, problem)``, unknown keys
are refused with the closest known one suggested. Format::

    [campaign]
    extends = "base.toml"          # optional: a campaign file in this folder or below, merged under this
                                   # one table by table (arrays replace); its paths relative to it
    name = "li2023_methods"        # optional (default: the file's stem); names the summary
    description = "..."
    scenario = "li2023_pd"         # base scenario: a shipped name, or a .toml / .ssp path
                                   # relative to this file
    runs = 200                     # number of draws (>= 1); default 1
    seed = 2023                    # campaign seed (integer >= 0); default 0
    mode = "fmu"                   # "fmu" (default: FMI 2.0 FMUs of the FMU folder) or "inprocess"
    fmu_dir = "build/fmus"         # optional FMU folder (relative to this file; default as `ftcsim run`)
    start = 0.0                    # optional overrides of the scenario's [timing], s
    stop = 60.0
    step = 0.01
    gains = ["design.json"]        # optional design files (as `ftcsim run --gains`), relative to this file
    trajectories = ["ctrl.q_e"]    # optional: recorded signals stored per run (Parquet, by run)
    trajectory_step = 0.5          # s, spacing of the stored trajectory samples (default: the step)

    [parameters]                   # fixed overrides for every run
    "plant.disturbance_scale" = 1.0

    [dispersions."plant.fault_scale"]      # one table per dispersed parameter
    distribution = "uniform"       # normal (mean, std) | uniform (low, high) | choice (values,
                                   # weights) | integer (low, high: uniform on low..high-1)
    low = 0.2
    high = 1.5
    apply = "value"                # value: the draw is the value (default); scale: nominal x draw;
                                   # offset: nominal + draw (nominal: the run's value before dispersion)
    shared = false                 # vector/matrix parameter: one draw for every element

    [dispersions."plant.J[1,1]"]   # one element of a matrix parameter ...
    distribution = "normal"
    mean = 1.0
    std = 0.05
    apply = "scale"

    [dispersions."plant.q_init"]   # ... or the whole parameter: numbers broadcast, arrays of its shape
    distribution = "normal"
    mean = [0.84, 0.3, 0.2, -0.4]
    std = 0.01

    [grid]                         # sweep: every combination of these values (outer loop)
    "ctrl.k_p" = [10.0, 20.0, 40.0]

    [[variants]]                   # methods to compare on the same draws (outermost loop)
    name = "pd"
    scenario = "li2023_pd"         # optional: another base scenario for this variant
    gains = ["pd.json"]            # optional design files for this variant
    [variants.fmu]                 # optional: another FMU (model name or .fmu path) for an instance
    ctrl = "PDController"
    [variants.parameters]          # optional fixed overrides for this variant
    "ctrl.k_p" = 20.0

    [settling]                     # optional settling-time metric (column settling_time, s)
    signal = "ctrl.q_e"            # quaternion (elements 0..3): the vector part's norm is used
    level = 0.01                   # band the norm must stay in until the end of the run
    from = 80.0                    # s, time it is measured from (default: start)

    [requirements]                 # pass/fail in `ftcsim campaign-report`: metric = {max = .., min = ..}
    final_attitude_error = { max = 1e-3 }
                                   # (a run metric, settling_time, or the paper's own: misspelt ones refused)

Runs. ``run_id = (variant * grid_points + point) * runs + draw``. Draw ``k`` takes its random
numbers from ``numpy.random.SeedSequence(seed).spawn(runs)[k]`` (one child per dispersed
parameter, keyed by the CRC-32 of its name, so adding a dispersion leaves the others' draws
unchanged), the same for every variant and grid point: the variants are compared on the same
draws, and any run can be redone alone, bit-identical. Values are applied in the order base
scenario < campaign ``gains`` and ``[parameters]`` < variant < grid point < dispersions. Each run
has a key: a hash of its resolved inputs (its id, the FMUs' SHA-256, every parameter value,
timing, wiring, metrics), under which its result is stored; a rerun computes only the keys not
yet stored.

Variant FMU swaps keep the instance's parameter values that the new FMU declares and drop the
others (listed in :attr:`Variant.dropped`); the new FMU must have every variable the scenario
connects, drives or records.
"""
from __future__ import annotations

import dataclasses
import difflib
import functools
import hashlib
import itertools
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import tomli_w

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import parse_toml, read_utf8
from orchestrator.common.reading import check_regular, referenced
from orchestrator.scenario import declared as d
from orchestrator.scenario.interfaces import block_interface, fmu_interface
from orchestrator.scenario.loading import load_scenario
from orchestrator.scenario.model import Instance
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.refs import expand as expand_names
from orchestrator.scenario.refs import resolve_ref, shape_of
from orchestrator.scenario.shipped import block_factory, fmu_folder, paper_metrics_of
from orchestrator.scenario.toml import merge_tables
from orchestrator.scenario.values import hint

DISTRIBUTIONS = {"normal": ("mean", "std"), "uniform": ("low", "high"), "choice": ("values", "weights"),
                 "integer": ("low", "high")}
APPLY = ("value", "scale", "offset")
MAX_RUNS = 1_000_000
MAX_EXTENDS = 8
# what every run's metrics.json holds ([metrics] signals of the scenario; orchestrator/results/metrics.py)
RUN_METRICS = ("final_attitude_error", "max_attitude_error_last_10s", "final_q_ev_norm", "max_q_ev_norm_last_10s",
               "final_rate_error", "control_energy", "max_abs_u", "saturation_respected", "t_end", "steps", "wall_time_s",
               "real_time_factor")
MAX_SEED = 2**63 - 1  # stored as int64 (summary.parquet)
DEFAULT_TIME_LIMIT = 3600.0  # s of wall time per run in a campaign; a run over it is stored with status "timeout"


ELSEWHERE = (
    "every 'instance.parameter' (parameters, grid, dispersions) names a parameter of every base scenario, its arrays "
    "have the parameter's shape, and no parameter is dispersed twice or both dispersed and swept",
    "trajectories and the settling signal are recorded by every base scenario; a requirement names a run metric, "
    "settling_time (with [settling]) or a metric of the scenario's paper",
    "a uniform high is at least its low; an integer's low and high are whole numbers, high > low; choice weights "
    "are one per value, with a positive sum; shared = true takes one number; a normal std is >= 0",
    "the base scenarios load and accept the overrides (start, stop, step, gains, FMU swaps); variant names are "
    "unique; variants x grid points x runs is at most 1000000",
    "extends names a campaign file in this file's folder or below it (no cycle, at most 8 deep)",
)


@functools.cache
def campaign_format() -> d.Format:
    """The declaration of campaign files (the module docstring): their checks and their JSON Schema."""
    def files(description):
        return d.ListOf(d.Text(), description, what="a list of strings", single=True, default=[])

    ref = d.Text(pattern=r"[A-Za-z_][A-Za-z0-9_]*\..+", rule_text="is not of the form 'instance.parameter'")
    values = d.Values("a number, or an array of the parameter's shape (numbers broadcast)")
    parameters = d.Table(extra=values, names=ref, description="'instance.parameter' = value (arrays for vectors and "
                         "matrices, 'plant.J[1,1]' for one element)")
    common = {"apply": d.Choice(APPLY, default="value", description="value: the draw is the value; scale: nominal x "
                                "draw; offset: nominal + draw"),
              "shared": d.Flag("vector/matrix parameter: one draw for every element", default=False)}

    def distribution(kind, a, b, **fields):
        return d.Table({"distribution": d.Choice((kind,)), **common, **fields}, required=(a, b) if a != "values" else (a,))

    def pair(kind, a, b, what_a, what_b):
        need = f" ({kind} needs {a} and {b})"
        return distribution(kind, a, b, **{a: d.Values(what_a, missing=need), b: d.Values(what_b, missing=need)})

    dispersion = d.Union("distribution", {
        "normal": pair("normal", "mean", "std", "mean", "standard deviation (>= 0)"),
        "uniform": pair("uniform", "low", "high", "low end", "high end (>= low)"),
        "choice": distribution("choice", "values", "weights",
                               values=d.ListOf(values, "candidate values, one drawn per run", min_items=1,
                                               what="a non-empty list of candidate values"),
                               weights=d.ListOf(d.Number(lower=0.0), "relative weights, one per value", index=False)),
        "integer": pair("integer", "low", "high", "low end (a whole number)", "high end (draws are low..high-1)"),
    }, what="distribution", description="one table per dispersed 'instance.parameter' (or one element of it)")
    campaign = d.Table({
        "extends": d.Text("a base campaign file (.toml) in this file's folder or below, merged under this one",
                          pattern=r".*\.toml", rule_text="is not a campaign file name (.toml)"),
        "name": d.Name("names the summary (default: the file's stem)"),
        "description": d.Text(empty=True, default=""),
        "scenario": d.Text("base scenario: a shipped name, or a .toml / .ssp file relative to this file",
                           missing=": name the base scenario (shipped name or .toml file)"),
        "runs": d.Whole("number of draws", 1, MAX_RUNS, default=1),
        "seed": d.Whole("campaign seed", 0, MAX_SEED, default=0),
        "mode": d.Choice(("fmu", "inprocess"), default="fmu", description="fmu: the FMI 2.0 FMUs of the FMU folder; "
                         "inprocess: the blocks"),
        "fmu_dir": d.Text("FMU folder, relative to this file (default as `ftcsim run`)"),
        "start": d.Number("s, start time instead of the scenario's"),
        "stop": d.Number("s, stop time instead of the scenario's"),
        "step": d.Number("s, communication step instead of the scenario's", positive=True),
        "gains": files("design files (as `ftcsim run --gains`), "
                                                                       "relative to this file"),
        "trajectories": files("recorded signals stored per run "
                                                                              "('instance.output')"),
        "trajectory_step": d.Number("s, spacing of the stored trajectory samples (default: the step)", positive=True),
        "time_limit": d.Seconds("s of wall time per run; a run over it is stored with status timeout",
                                default=DEFAULT_TIME_LIMIT),
    }, complete=("scenario",))
    variant = d.Table({
        "name": d.Name("the variant's name (default: variantJ)"),
        "scenario": d.Text("another base scenario for this variant"),
        "fmu": d.Table(extra=d.Text("an FMU model name or a .fmu file"), description="instance = another FMU"),
        "gains": files("design files for this variant"),
        "parameters": parameters})
    root = d.Table({
        "campaign": campaign,
        "parameters": parameters,
        "dispersions": d.Table(extra=dispersion, names=ref),
        "grid": d.Table(extra=d.ListOf(values, min_items=1, what="a non-empty list of values"), names=ref,
                        description="sweep: every combination of these values"),
        "variants": d.ListOf(variant, "methods compared on the same draws", what="[[variants]] tables", min_items=1),
        "settling": d.Table({"signal": d.Text("a recorded signal ('instance.output'); a quaternion's vector part's norm "
                                              "is used"),
                             "level": d.Number("band the signal must stay in until the end of the run", positive=True),
                             "from": d.Number("s, time it is measured from (default: start)")},
                            required=("signal", "level"), description="the settling-time metric (settling_time, s)"),
        "requirements": d.Table(extra=d.Table({"max": d.Number(), "min": d.Number()}, min_items=1,
                                              empty="give max and/or min"),
                                description="pass/fail in `ftcsim campaign-report`: metric = {max = .., min = ..}"),
    }, required=("campaign",))
    return d.Format("campaign", "ftcsim campaign file", root, "A campaign: Monte Carlo dispersions, sweeps and method "
                    "comparisons over a scenario (`ftcsim campaign`, docs/campaigns.md).", extends=("campaign", "extends"),
                    elsewhere=ELSEWHERE)


@dataclass
class Dispersion:
    ref: str  # "inst.param" as written
    inst: str
    names: list  # structured scalar names, index order
    shape: tuple  # () for a scalar, else the parameter's shape
    distribution: str
    args: dict  # mean/std, low/high (arrays of ``shape`` or scalars), values (list of arrays), weights
    apply: str = "value"
    shared: bool = False

    def draw(self, rng: np.random.Generator) -> np.ndarray:
        """One draw: an array of len(names)."""
        n = len(self.names)
        size = 1 if self.shared else n
        a = self.args
        if self.distribution == "normal":
            x = a["mean"] + a["std"] * rng.standard_normal(size)
        elif self.distribution == "uniform":
            x = a["low"] + (a["high"] - a["low"]) * rng.random(size)
        elif self.distribution == "integer":
            x = np.floor(a["low"] + (a["high"] - a["low"]) * rng.random(size))
        else:  # choice: one candidate (a whole value) per draw
            k = int(rng.choice(len(a["values"]), p=a["weights"]))
            x = a["values"][k]
        return np.broadcast_to(np.asarray(x, dtype=float).ravel(), (n,)).copy()


@dataclass
class Variant:
    name: str
    scenario: str  # the scenario argument (shipped name or path) as given to orchestrator.api.load
    fmus: dict  # instance -> FMU (model name or path)
    gains: list  # design file paths
    parameters: dict  # "inst.param" -> value
    dropped: dict = field(default_factory=dict)  # instance -> parameters dropped by an FMU swap


@dataclass
class Campaign:
    path: Path
    text: str  # the file as read (hashed into the manifest; a rerun on another text is refused)
    name: str
    description: str
    runs: int
    seed: int
    mode: str
    fmu_dir: Path | None
    timing: dict  # start/stop/step overrides
    variants: list  # Variant (one named "base" if the file has none)
    dispersions: list  # Dispersion
    grid: list  # [(ref, [values...])]
    trajectories: list  # 'inst.var' references
    trajectory_step: float | None
    settling: dict | None
    requirements: dict  # metric -> {"max": x, "min": y}
    bases: list = field(default_factory=list)  # loaded Scenario per variant (validated)
    time_limit: float | None = DEFAULT_TIME_LIMIT  # s of wall time per run (orchestrator/common/watchdog.py)

    @property
    def digest(self) -> str:
        return hashlib.sha256(self.text.encode("utf-8")).hexdigest()

    @property
    def points(self) -> list:
        """Grid points: a list of {ref: value} (one empty point without a grid)."""
        if not self.grid:
            return [{}]
        refs = [r for r, _ in self.grid]
        return [dict(zip(refs, combo)) for combo in itertools.product(*[v for _, v in self.grid])]

    @property
    def n_points(self) -> int:
        """Number of grid points (counted without building them)."""
        return math.prod(len(v) for _, v in self.grid)

    @property
    def n_runs(self) -> int:
        return len(self.variants) * self.n_points * self.runs


@dataclass
class RunSpec:
    """Everything a worker needs for one run (plain data: it travels to Dask workers)."""

    run_id: int
    key: str
    variant: int
    variant_name: str
    point: int
    draw: int
    seed: int  # the campaign seed; the run's generator is SeedSequence(seed).spawn(runs)[draw]
    recipe: dict  # how to load the variant's base scenario (orchestrator.api.load arguments + FMU swaps)
    parameters: dict  # inst -> {structured name: value}: the grid point and the draws
    requested: dict  # "inst.name" -> value drawn for the dispersed parameters (read back after set-up)
    fmu_digests: dict  # FMU path -> SHA-256 the run was planned with
    trajectories: list  # [(inst, var)]
    trajectory_step: float | None
    settling: dict | None
    time_limit: float | None = None  # s of wall time per run (None: unbounded)


# -- small checks --------------------------------------------------------------------------------
def _array(src, key, x, shape) -> np.ndarray:
    """A number or an array of ``shape`` (or of one element per structured name); its numbers were
    checked by the declaration."""
    a = np.asarray(x, dtype=object)
    if a.ndim and a.shape != shape and not (len(shape) == 0 and a.shape == (1,)):
        raise InputError(src, key, f"expected a number or an array of shape {shape}, got shape {a.shape}")
    return np.array(a.ravel().tolist(), dtype=float) if a.ndim else np.array(float(x))


def _resolve_path(base: Path, arg: str) -> str:
    """A scenario / gains / FMU argument: paths relative to the campaign file, names as given."""
    p = Path(arg)
    if p.suffix in (".toml", ".ssp", ".json", ".fmu") or "/" in arg:
        return str(p if p.is_absolute() else (base / p).resolve())
    return arg


# -- parameters of a loaded scenario ---------------------------------------------------------------
def parameter_names(sc, src, key, ref) -> tuple[str, list, tuple]:
    """'inst.param' -> (inst, structured names, shape) for a parameter of scenario ``sc``;
    unknown instances and parameters are refused with the closest names suggested."""
    if not isinstance(ref, str) or "." not in ref:
        raise InputError(src, key, f"expected 'instance.parameter', got {ref!r}")
    inst, _, name = ref.partition(".")
    if inst not in sc.instances:
        raise InputError(src, key, f"unknown instance {inst!r}{hint(inst, sc.instances)} (instances of {sc.name}: "
                                   f"{', '.join(sc.instances)})")
    itf = sc.instances[inst].interface
    names = expand_names(itf, name, "parameter")
    if not names:
        params = itf.names("parameter")
        bases = sorted({n.split("[")[0] for n in params})
        raise InputError(src, key, f"{itf.model_name} (instance {inst!r} of {sc.name}) has no parameter {name!r}"
                         + hint(name, bases + params))
    shape = () if names == [name] else shape_of(names)
    return inst, names, (shape if len(shape) > 1 else ((len(names),) if names != [name] else ()))


# -- loading --------------------------------------------------------------------------------------
def read_document(path: Path, _seen=()) -> dict:
    """A campaign file as a document, with ``[campaign] extends = "base.toml"`` resolved: the base (a
    file in this file's folder or below it; at most ``MAX_EXTENDS`` deep, no cycles) under this
    file's tables, merged table by table (:func:`orchestrator.scenario.toml.merge_tables`; arrays
    such as ``[[variants]]`` replace the base's). Every path in a resolved document is absolute (each
    file's paths are relative to that file)."""
    src = str(path)
    doc = parse_toml(src, read_utf8(path, "campaign file"))
    meta = doc.get("campaign")
    base = meta.get("extends") if isinstance(meta, dict) else None
    if base is None:
        return doc
    if not isinstance(base, str) or not base.endswith(".toml"):
        raise InputError(src, "campaign.extends", f"expected a campaign file name (.toml), got {base!r}")
    folder = path.parent.resolve()
    base_path = referenced(folder, base, src, "campaign.extends", "base campaign", whose="campaign's")  # links too stay inside
    here = Path(os.path.realpath(path))
    if base_path in _seen or base_path == here:
        raise InputError(src, "campaign.extends", f"circular extends through {base}")
    if len(_seen) >= MAX_EXTENDS:
        raise InputError(src, "campaign.extends", f"extends chain deeper than {MAX_EXTENDS}")
    check_regular(base_path, "base campaign", src, "campaign.extends")
    merged = merge_tables(absolute_paths(read_document(base_path, _seen + (here,)), base_path.parent),
                          absolute_paths(doc, folder))
    merged["campaign"].pop("extends", None)
    return merged


def absolute_paths(doc: dict, here: Path) -> dict:
    """``doc`` with its file arguments (scenario, gains, FMU files, fmu_dir) made absolute against
    ``here`` (shipped names kept); malformed values are left for :func:`load` to name."""
    doc = {**doc}
    meta = doc.get("campaign")
    if isinstance(meta, dict):
        meta = doc["campaign"] = dict(meta)
        if isinstance(meta.get("scenario"), str):
            meta["scenario"] = _resolve_path(here, meta["scenario"])
        if isinstance(meta.get("fmu_dir"), str) and meta["fmu_dir"]:
            meta["fmu_dir"] = str((here / meta["fmu_dir"]).resolve())
        if isinstance(meta.get("gains"), list):
            meta["gains"] = [_resolve_path(here, g) if isinstance(g, str) else g for g in meta["gains"]]
    if isinstance(doc.get("variants"), list):
        doc["variants"] = [_variant_paths(v, here) if isinstance(v, dict) else v for v in doc["variants"]]
    return doc


def _variant_paths(v: dict, here: Path) -> dict:
    v = dict(v)
    if isinstance(v.get("scenario"), str):
        v["scenario"] = _resolve_path(here, v["scenario"])
    if isinstance(v.get("gains"), list):
        v["gains"] = [_resolve_path(here, g) if isinstance(g, str) else g for g in v["gains"]]
    if isinstance(v.get("fmu"), dict):
        v["fmu"] = {i: _resolve_path(here, f) if isinstance(f, str) else f for i, f in v["fmu"].items()}
    return v


def load(path, *, runs: int | None = None, stop: float | None = None) -> Campaign:
    """Read and validate a campaign file (the base scenarios are loaded and checked too); ``runs``
    and ``stop`` (s) override ``[campaign] runs`` and ``stop`` (``ftcsim campaign --runs/--stop``).
    With ``extends`` or an override, the campaign's text (hashed into the folder's manifest, kept
    as its ``campaign.toml``) is the resolved document, every path absolute."""
    path = Path(path)
    src = str(path)
    text = read_utf8(path, "campaign file")
    doc = parse_toml(src, text)
    meta = doc.get("campaign")
    if (isinstance(meta, dict) and "extends" in meta) or runs is not None or stop is not None:
        doc = absolute_paths(read_document(path), path.parent.resolve())
        doc.setdefault("campaign", {})
        if isinstance(doc["campaign"], dict):
            doc["campaign"] = {**doc["campaign"], **({"runs": runs} if runs is not None else {}),
                               **({"stop": stop} if stop is not None else {})}
        text = (f"# {path.name} as ftcsim ran it: extends resolved, command-line overrides applied, paths absolute\n"
                + tomli_w.dumps(doc))
    doc = campaign_format().check(src, doc)  # every key, type and range; below, what needs the base scenarios
    meta, here = doc["campaign"], path.parent.resolve()
    fmu_dir = Path(_resolve_path(here, meta["fmu_dir"] + ("/" if "/" not in meta["fmu_dir"] else ""))) \
        if "fmu_dir" in meta else None
    gains = [_resolve_path(here, g) for g in meta["gains"]]
    fixed = doc.get("parameters", {})
    variants = []
    for j, v in enumerate(doc.get("variants", [{"name": "base"}])):
        vname = v.get("name", f"variant{j}")
        if any(x.name == vname for x in variants):
            raise InputError(src, f"variants[{j}].name", f"variant {vname!r} named twice")
        variants.append(Variant(
            name=vname, scenario=_resolve_path(here, v.get("scenario", meta["scenario"])),
            fmus={i: _resolve_path(here, f) for i, f in v.get("fmu", {}).items()},
            gains=gains + [_resolve_path(here, g) for g in v.get("gains", [])],
            parameters={**fixed, **v.get("parameters", {})}))

    c = Campaign(path=path, text=text, name=meta.get("name", path.stem), description=meta["description"],
                 runs=meta["runs"], seed=meta["seed"], mode=meta["mode"], fmu_dir=fmu_dir,
                 timing={k: meta[k] for k in ("start", "stop", "step") if k in meta}, variants=variants,
                 dispersions=[], grid=[], trajectories=[], trajectory_step=meta.get("trajectory_step"), settling=None,
                 requirements=doc.get("requirements", {}), time_limit=meta["time_limit"])
    c.bases = [_load_variant(c, j, v, src) for j, v in enumerate(variants)]

    for ref, values in doc.get("grid", {}).items():
        key = f"grid.{ref}"
        for sc in c.bases:
            _, _, shape = parameter_names(sc, src, key, ref)
        c.grid.append((ref, [_array(src, key, x, shape).tolist() for x in values]))
    if c.n_runs > MAX_RUNS:  # counted, not built: a grid of 1e9 points is refused before any point exists
        raise InputError(src, "grid", f"{c.n_runs} runs: more than {MAX_RUNS}")

    seen = {}
    for ref, spec in doc.get("dispersions", {}).items():
        key = f"dispersions.{ref}"
        kind = spec["distribution"]
        for sc in c.bases:
            inst, names, shape = parameter_names(sc, src, key, ref)
        for n in names:
            if (inst, n) in seen:
                raise InputError(src, key, f"{inst}.{n} is dispersed twice (also by {seen[(inst, n)]})")
            seen[(inst, n)] = key
        if any(ref == g or ref.split("[")[0] == g.split("[")[0] for g, _ in c.grid):
            raise InputError(src, key, f"{ref} is also swept in [grid]; disperse or sweep it, not both")
        c.dispersions.append(Dispersion(ref, inst, names, shape, kind, _arguments(src, key, spec, shape), spec["apply"],
                                        spec["shared"]))

    for j, ref in enumerate(meta["trajectories"]):
        for sc in c.bases:
            cols = _signal(sc, src, f"campaign.trajectories[{j}]", ref)
        c.trajectories.extend(cols)
    c.trajectories = list(dict.fromkeys(c.trajectories))
    if "settling" in doc:
        st = doc["settling"]
        for sc in c.bases:
            cols = _signal(sc, src, "settling.signal", st["signal"])
        c.settling = {"signal": st["signal"], "columns": cols, "level": st["level"],
                      "from": st.get("from", c.bases[0].start)}
    for metric in c.requirements:
        _check_metric_name(src, f"requirements.{metric}", metric, c)
    return c


def _arguments(src, key, spec: dict, shape) -> dict:
    """The arguments of a dispersion's distribution (arrays of the parameter's ``shape`` or numbers),
    checked against each other."""
    kind, args = spec["distribution"], {}
    if kind == "choice":
        values = spec["values"]
        args["values"] = [_array(src, f"{key}.values[{i}]", x, shape) for i, x in enumerate(values)]
        w = spec.get("weights")
        if w is not None:
            if len(w) != len(values):
                raise InputError(src, f"{key}.weights", f"expected {len(values)} weights, one per value")
            w = np.array(w)
            if not w.max() > 0:
                raise InputError(src, f"{key}.weights", "weights must be >= 0 with a positive sum")
            w = w / w.max()  # relative weights: no overflow in the sum (1e308 + 1e308)
            w = w / w.sum()
        args["weights"] = w
        return args
    a, b = DISTRIBUTIONS[kind]
    for k in (a, b):
        args[k] = _array(src, f"{key}.{k}", spec[k], shape).ravel()
        if spec["shared"] and args[k].size > 1:
            raise InputError(src, f"{key}.{k}", "shared = true takes one number (one draw for every element)")
    if kind == "normal" and np.any(args["std"] < 0):
        raise InputError(src, f"{key}.std", f"standard deviation must be >= 0, got {args['std'].min():g}")
    if kind == "uniform" and np.any(args["high"] < args["low"]):
        raise InputError(src, f"{key}.high", "must be >= low")
    if kind == "integer":
        if np.any(args["low"] != np.floor(args["low"])) or np.any(args["high"] != np.floor(args["high"])):
            raise InputError(src, key, "integer: low and high must be whole numbers")
        if np.any(args["high"] <= args["low"]):
            raise InputError(src, f"{key}.high", "must be > low (draws are low..high-1)")
    return args


def _check_metric_name(src, key, metric, c: Campaign) -> None:
    """A ``[requirements]`` metric: one ``ftcsim run`` computes for every scenario (``RUN_METRICS``),
    ``settling_time`` with ``[settling]``, or one of the base scenarios' papers' own metrics. Those
    have names built at run time (``fault_rms_2``, ``theta_at_30s``), so a name outside
    ``RUN_METRICS`` is refused when it is within a typo of one of them (difflib ratio >= 0.8: a
    misspelt name would never be computed and every run would fail the requirement) or when no base
    scenario has paper metrics."""
    known = RUN_METRICS + (("settling_time",) if c.settling else ())
    if metric in known:
        return
    if metric == "settling_time":
        raise InputError(src, key, "settling_time is computed only with a [settling] table (signal, level, from)")
    close = difflib.get_close_matches(metric, known, n=1, cutoff=0.8)
    papers = any(sc.paper and paper_metrics_of(sc.paper) for sc in c.bases)
    if close or not papers:
        raise InputError(src, key, f"unknown metric {metric!r}{hint(metric, known)} (known: {', '.join(known)}"
                                   + (", or a metric of the scenario's paper" if papers else "") + ")")


def _signal(sc, src, key, ref) -> list:
    """'inst.var' -> recorded column names (the signal must be recorded by the scenario)."""
    inst, names = resolve_ref(src, key, ref, sc.instances)
    missing = [n for n in names if (inst, n) not in sc.record]
    if missing:
        raise InputError(src, key, f"{inst}.{missing[0]} is not recorded by scenario {sc.name} "
                                   "(add it to its [record] variables)")
    return [f"{inst}.{n}" for n in names]


def recipe(c: Campaign, v: Variant) -> dict:
    """The arguments that load a variant's base scenario (used identically here and on workers)."""
    fmu_dir = fmu_folder(c.fmu_dir)  # resolved here, not on the workers
    return {"scenario": v.scenario, "mode": c.mode, "fmu_dir": str(Path(fmu_dir).resolve()),
            "timing": dict(c.timing), "gains": list(v.gains), "parameters": dict(v.parameters),
            "fmus": dict(v.fmus)}


def load_base(r: dict, src="campaign", key="variants"):
    """Load a variant's base scenario from its :func:`recipe`: the scenario with the timing and gains
    overrides (:func:`orchestrator.scenario.loading.load_scenario`, as ``ftcsim run``), then the FMU swaps,
    then the parameters. Returns (scenario, dropped parameters per instance)."""
    sc = load_scenario(r["scenario"], mode=r["mode"], fmu_dir=r["fmu_dir"], gains=r["gains"], src="campaign",
                       **r["timing"])
    dropped = {}
    if r["fmus"]:
        instances = dict(sc.instances)
        for inst, fmu in r["fmus"].items():
            instances[inst], dropped[inst] = _swap_fmu(sc, inst, fmu, r["mode"], r["fmu_dir"], src, f"{key}.fmu.{inst}")
        sc = dataclasses.replace(sc, instances=instances)
    return with_overrides(sc, parameters=r["parameters"], src=src), dropped


def _swap_fmu(sc, inst, fmu, mode, fmu_dir, src, key) -> tuple:
    """Instance ``inst`` with another FMU, keeping the parameters the new one declares; returns
    (the new instance, the parameters dropped)."""
    if inst not in sc.instances:
        raise InputError(src, key, f"unknown instance {inst!r}{hint(inst, sc.instances)} (instances of {sc.name}: "
                                   f"{', '.join(sc.instances)})")
    old = sc.instances[inst]
    if mode == "inprocess":
        model = fmu if not fmu.endswith(".fmu") else fmu_interface(src, key, Path(fmu))[0].model_name
        factory, md, path = block_factory(model, src, key, fmu), None, None
        itf = block_interface(model, factory)
    else:
        path = Path(fmu) if fmu.endswith(".fmu") else fmu_folder(fmu_dir) / f"{fmu}.fmu"
        if not path.is_file():
            raise InputError(src, key, f"FMU file not found: {path} (run `ftcsim build` first)")
        itf, md = fmu_interface(src, key, path)
        factory = None
    for a, va, b, vb in sc.connections:
        for i, v, want in ((a, va, "output"), (b, vb, "input")):
            if i == inst and itf.causality.get(v) != want:
                raise InputError(src, key, f"{itf.model_name} has no {want} {v!r}, which scenario {sc.name} connects")
    for s in sc.sources:
        for i, v in s.targets:
            if i == inst and itf.causality.get(v) != "input":
                raise InputError(src, key, f"{itf.model_name} has no input {v!r}, which source {s.name} drives")
    for i, v in sc.record:
        if i == inst and itf.causality.get(v) not in ("input", "output"):
            raise InputError(src, key, f"{itf.model_name} has no variable {v!r}, which scenario {sc.name} records")
    kept = {n: x for n, x in old.parameters.items() if itf.causality.get(n) == "parameter"}
    return (Instance(inst, path, itf.model_name, itf, kept, model_description=md, factory=factory),
            sorted(set(old.parameters) - set(kept)))


def _load_variant(c: Campaign, j: int, v: Variant, src):
    r = recipe(c, v)
    try:
        sc, dropped = load_base(r, src, f"variants[{j}]")
    except InputError as e:
        timing = e.key.rpartition(".")[2]
        if e.source in ("api", "campaign") and e.key in ("run.start", "run.stop", "step", "start", "stop") \
                and timing in c.timing:  # [campaign] start / stop / step, the same for every variant
            raise InputError(src, f"campaign.{timing}", f"{e.problem} (variant {v.name}, scenario {v.scenario})") from None
        if e.source == "api" or e.source == "campaign":  # overrides named in the campaign file
            raise InputError(src, f"variants[{j}] ({v.name}): {e.key}", e.problem) from None
        raise
    v.dropped = {k: d for k, d in dropped.items() if d}
    return sc


