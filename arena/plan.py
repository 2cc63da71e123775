"""The arena as one plan: every cell (a method on a plant) with each hardware set, its derived
scenario, its campaigns and the digest of everything that decides its runs.

A cell and hardware set is one folder ``cells/<method>_on_<plant>.<hardware>/`` holding its
``scenario.toml``, ``cell.json`` (the digest and its parts) and its campaigns: ``draws`` (the
actuator classes whose runs the draws change, ``draws`` runs each), ``single`` (the deterministic
classes, :func:`arena.cells.deterministic`: one run stands for every draw), ``sensors`` (the
sensor-fault classes on ``scenario_sensors.toml``, realistic hardware, ``sensor_draws`` runs) and,
for a cell that flies its wheel loss with the decision chain closed (:func:`arena.cells.reconfigures`),
``fdir`` on ``scenario_fdir.toml``, written after the first pass (``arena/fdir.py``: its thresholds
come from the cell's stored fault-free draws).

The digest of a cell (:func:`digest_parts`) covers its derived scenario (the cell's file, the
plant's mission, the realistic-hardware rewrite), its campaigns (draws, seed, dispersions, fault
classes, trajectories), and its models: the FMUs' SHA-256 in FMU mode, the source files of the
model packages in process (``plant``, ``estimator``, ``controller``, ``papers``' declarations and
the arena's blocks and parameter sets: what the blocks run), and for a cell that closes its chain the
decision layer's design (``[detection]``). A folder whose cell has another digest is never mixed in: it
is refused, or recomputed with ``--overwrite``.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import tomli_w

from orchestrator import api

from . import cells as C
from .arenafile import Arena, Cell

ARENA_MODULES = ("blocks.py", "catalog.py", "parameters.py", "gains.py")
PAPER_MODULES = ("paper.py", "parameters.py", "blocks.py", "gains.py", "designed_gains.py", "registry.py",
                 "shared_blocks.py")


@dataclass
class Group:
    """One campaign of a cell: ``kind`` ``draws`` (``runs`` = the arena's draws), ``single`` (1 run),
    ``sensors`` (the sensor classes) or ``fdir`` (the chain closed); ``scenario`` its scenario file."""

    kind: str
    faults: list
    runs: int
    scenario: str = "scenario.toml"


@dataclass
class CellPlan:
    cell: Cell
    hardware: str
    scenario: dict  # the derived scenario document
    groups: list  # Group
    campaigns: dict = field(default_factory=dict)  # kind -> campaign document
    parts: dict = field(default_factory=dict)  # digest parts: scenario, campaigns, models
    manoeuvres: list = field(default_factory=list)  # s
    scenarios: dict = field(default_factory=dict)  # file name -> derived scenario document (beyond scenario.toml)
    reconfigures: bool = False  # flies its wheel loss with the chain closed (group fdir, after the first pass)
    fdir_stale: bool = False  # its stored closed-chain runs came from another design (recomputed: --overwrite)
    step: float = 0.0  # s, the loop's communication step

    @property
    def name(self) -> str:
        return f"{self.cell.name}.{self.hardware}"

    @property
    def digest(self) -> str:
        return _sha(self.parts)


def _sha(x) -> str:
    return hashlib.sha256(json.dumps(x, sort_keys=True, allow_nan=False, default=str).encode()).hexdigest()


_CODE: dict = {}


def model_sources_digest() -> str:
    """SHA-256 over the source files the in-process blocks run (module docstring), by relative path."""
    if "digest" not in _CODE:
        import arena
        import controller
        import diagnosis
        import estimator
        import papers
        import plant

        h = hashlib.sha256()
        files = []
        for pkg in (plant, estimator, controller, diagnosis):
            root = Path(pkg.__file__).parent
            files += [(root.parent, f) for f in sorted(root.rglob("*.py"))]
        proot = Path(papers.__file__).parent
        files += [(proot.parent, f) for f in sorted(proot.rglob("*.py")) if f.name in PAPER_MODULES]
        aroot = Path(arena.__file__).parent
        files += [(aroot.parent, aroot / n) for n in ARENA_MODULES]
        for base, f in files:
            h.update(f.relative_to(base).as_posix().encode() + b"\0" + hashlib.sha256(f.read_bytes()).digest())
        _CODE["digest"] = h.hexdigest()
    return _CODE["digest"]


def _fmu_digests(sc) -> dict:
    from orchestrator.results.files import fmu_digests

    return {name: d["sha256"] for name, d in sorted(fmu_digests(sc).items())}


def groups(arena: Arena, hardware: str, sensor_classes=()) -> list:
    """The campaigns of a cell with ``hardware``: the actuator classes the draws change, the deterministic
    ones, and the sensor classes its realistic loop has the sensors for (``sensor_classes``)."""
    act = arena.actuator_faults
    det = [f for f in act if C.deterministic(hardware, f)]
    rnd = [f for f in act if not C.deterministic(hardware, f)]
    out = []
    if rnd:
        out.append(Group("draws", rnd, arena.draws))
    if det:
        out.append(Group("single", det, 1))
    if hardware == "realistic" and sensor_classes:
        out.append(Group("sensors", list(sensor_classes), arena.draws_of(sensor_classes[0]), "scenario_sensors.toml"))
    return out


def build(arena: Arena) -> list:
    """Every cell and hardware set of the arena as a :class:`CellPlan`, each derived scenario loaded
    and checked (``orchestrator.api.load``) before anything is written; problems name the arena
    file and the cell."""
    try:
        return _build(arena)
    except OSError as e:  # the checks' temporary files (TMPDIR full, a size limit): one line
        raise api.InputError(tempfile.gettempdir(), "-", f"cannot write the arena's check files there: "
                             f"{e.strerror or e}") from None


# the campaign keys the arena file decides (a problem there is named in the arena file)
CAMPAIGN_KEYS = {"campaign.stop": "arena.stop", "campaign.seed": "arena.seed", "campaign.runs": "arena.draws",
                 "campaign.trajectory_step": "arena.trajectory_step", "campaign.mode": "arena.mode"}


def _build(arena: Arena) -> list:
    out = []
    with tempfile.TemporaryDirectory(prefix="ftcsim-arena-check-") as tmp:
        for j, cell in enumerate(arena.cells):
            key = f"cells[{j}]"
            for hw in arena.hardware:
                try:
                    doc = C.cell_scenario(arena, cell, hw)
                    scenarios = {"scenario.toml": doc}
                    sensors = C.sensor_classes(doc, arena.sensor_classes) if hw == "realistic" else []
                    if sensors:
                        scenarios["scenario_sensors.toml"] = C.sensor_scenario(doc, sensors)
                except (ValueError, KeyError) as e:
                    raise api.InputError(arena.path, f"{key}.scenario", f"{cell.name} ({hw}): {e}") from None
                d = Path(tmp) / f"{cell.name}.{hw}"
                d.mkdir()
                for fname, sdoc in scenarios.items():
                    f = d / fname
                    f.write_text(tomli_w.dumps(sdoc), encoding="utf-8")
                    try:
                        sc = api.load(str(f), mode=arena.mode, fmu_dir=str(arena.fmu_dir) if arena.fmu_dir else None)
                    except api.InputError as e:
                        raise api.InputError(arena.path, f"{key}.scenario", f"{cell.name} ({hw}): {e.key}: {e.problem}") from None
                    if fname == "scenario.toml":
                        models = model_sources_digest() if arena.mode == "inprocess" else _fmu_digests(sc)
                        step = sc.step
                _check_detection(arena, cell, step, key)
                p = CellPlan(cell, hw, doc, groups(arena, hw, sensors), manoeuvres=C.manoeuvres(doc),
                             scenarios={k: v for k, v in scenarios.items() if k != "scenario.toml"}, step=step,
                             reconfigures=C.reconfigures(doc, cell) and "lost" in arena.faults and "none" in arena.faults)
                for g in p.groups:
                    sdoc = scenarios[g.scenario]
                    if g.kind == "sensors":
                        p.campaigns[g.kind] = C.sensor_campaign_doc(arena, cell, g.scenario, sdoc, g.faults, g.runs,
                                                                    f"{p.name}.{g.kind}")
                    else:
                        p.campaigns[g.kind] = C.campaign_doc(arena, cell, hw, g.scenario, sdoc, g.faults, g.runs,
                                                             f"{p.name}.{g.kind}")
                for g in p.groups:  # each campaign as `ftcsim campaign` will run it (stop, seed, draws): before anything is written
                    (d / f"{g.kind}.toml").write_text(tomli_w.dumps(p.campaigns[g.kind]), encoding="utf-8")
                    try:
                        api.plan_campaign(d / f"{g.kind}.toml")
                    except api.InputError as e:
                        where = CAMPAIGN_KEYS.get(e.key, f"{key}.campaign")
                        raise api.InputError(arena.path, where, f"{cell.name} ({hw}): {e.key}: {e.problem}") from None
                p.parts = {"scenario": _sha(scenarios), "campaigns": _sha(p.campaigns), "mode": arena.mode,
                           "models": models}
                if p.reconfigures:  # the closed chain's design decides the fdir group's runs
                    p.parts["fdir"] = _sha(dataclasses.asdict(arena.detection))
                note = f"Arena cell {p.name}: its runs' inputs have the digest {p.digest} (scenario, campaigns, models)"
                for g in p.groups:
                    p.campaigns[g.kind]["campaign"]["description"] = f"{note}; fault classes {', '.join(g.faults)}"
                out.append(p)
    return out


def sample_period(arena: Arena, step: float) -> float:
    """The decision layer's sample period in a cell of communication step ``step`` (s): the spacing of
    the stored trajectory rows (every round(trajectory_step / step) steps), so that the offline replay
    and a detector in the loop sample the same instants."""
    return max(1, int(round(arena.trajectory_step / step))) * step


def _check_detection(arena: Arena, cell, step: float, key: str) -> None:
    """The detectors' window must be a whole number of the cell's sample periods (checked before anything runs)."""
    if not cell.estimate or not ({"glr", "chi2"} & set(arena.detection.detectors)):
        return
    T = sample_period(arena, step)
    W = arena.detection.window / T
    if round(W) < 1 or abs(W - round(W)) > 1e-6 * max(1.0, W):
        raise api.InputError(arena.path, "detection.window", f"{arena.detection.window:g} s is not a whole multiple of "
                                                             f"{cell.name}'s sample period {T:g} s (trajectory_step "
                                                             f"{arena.trajectory_step:g} s on its {step:g} s step)")


def cell_record(arena: Arena, p: CellPlan) -> dict:
    """``cell.json`` of a cell folder."""
    return {"cell": p.cell.name, "hardware": p.hardware, "method": p.cell.method, "plant": p.cell.plant,
            "digest": p.digest, "parts": p.parts, "groups": [{"kind": g.kind, "faults": g.faults, "runs": g.runs,
                                                              "scenario": g.scenario} for g in p.groups],
            "scenario_file": str(p.cell.scenario), "arena": arena.name}


FDIR_CHANGED = "the design of its closed decision chain ([detection])"


def changed(old: dict, p: CellPlan) -> list:
    """What differs between a stored ``cell.json`` and the plan: names of the digest parts."""
    parts = old.get("parts") if isinstance(old, dict) else None
    if not isinstance(parts, dict):
        return ["its record (cell.json unreadable or from another version)"]
    names = {"scenario": "its scenario", "campaigns": "its draws, seed, dispersions or fault classes",
             "mode": "the mode (in process / FMU)", "models": "the models (FMUs or model code)",
             "fdir": FDIR_CHANGED}
    return [names[k] for k in names if parts.get(k) != p.parts.get(k)]
