"""The arena as one plan: every cell (a method on a plant) with each hardware set, its derived
scenario, its campaigns and the digest of everything that decides its runs.

A cell and hardware set is one folder ``cells/<method>_on_<plant>.<hardware>/`` holding its
``scenario.toml``, ``cell.json`` (the digest and its parts) and one or two campaigns: ``draws``
(the fault classes whose runs the draws change, ``draws`` runs each) and ``single`` (the
deterministic classes, :func:`arena.cells.deterministic`: one run stands for every draw).

The digest of a cell (:func:`digest_parts`) covers its derived scenario (the cell's file, the
plant's mission, the realistic-hardware rewrite), its campaigns (draws, seed, dispersions, fault
classes, trajectories), and its models: the FMUs' SHA-256 in FMU mode, the source files of the
model packages in process (``plant``, ``estimator``, ``controller``, ``papers``' declarations and
the arena's blocks and parameter sets: what the blocks run). A folder whose cell has another digest
is never mixed in: it is refused, or recomputed with ``--overwrite``.
"""
from __future__ import annotations

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
    """One campaign of a cell: ``kind`` ``draws`` (``runs`` = the arena's draws) or ``single`` (1 run)."""

    kind: str
    faults: list
    runs: int


@dataclass
class CellPlan:
    cell: Cell
    hardware: str
    scenario: dict  # the derived scenario document
    groups: list  # Group
    campaigns: dict = field(default_factory=dict)  # kind -> campaign document
    parts: dict = field(default_factory=dict)  # digest parts: scenario, campaigns, models
    manoeuvres: list = field(default_factory=list)  # s

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
        import estimator
        import papers
        import plant

        h = hashlib.sha256()
        files = []
        for pkg in (plant, estimator, controller):
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


def groups(arena: Arena, hardware: str) -> list:
    """The campaigns of a cell with ``hardware``: the fault classes the draws change, and the deterministic ones."""
    det = [f for f in arena.faults if C.deterministic(hardware, f)]
    rnd = [f for f in arena.faults if not C.deterministic(hardware, f)]
    out = []
    if rnd:
        out.append(Group("draws", rnd, arena.draws))
    if det:
        out.append(Group("single", det, 1))
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
                except (ValueError, KeyError) as e:
                    raise api.InputError(arena.path, f"{key}.scenario", f"{cell.name} ({hw}): {e}") from None
                f = Path(tmp) / f"{cell.name}.{hw}.toml"
                f.write_text(tomli_w.dumps(doc), encoding="utf-8")
                try:
                    sc = api.load(str(f), mode=arena.mode, fmu_dir=str(arena.fmu_dir) if arena.fmu_dir else None)
                except api.InputError as e:
                    raise api.InputError(arena.path, f"{key}.scenario", f"{cell.name} ({hw}): {e.key}: {e.problem}") from None
                p = CellPlan(cell, hw, doc, groups(arena, hw), manoeuvres=C.manoeuvres(doc))
                models = model_sources_digest() if arena.mode == "inprocess" else _fmu_digests(sc)
                for g in p.groups:
                    p.campaigns[g.kind] = C.campaign_doc(arena, cell, hw, "scenario.toml", doc, g.faults, g.runs,
                                                         f"{p.name}.{g.kind}")
                d = Path(tmp) / f"{cell.name}.{hw}"
                d.mkdir()
                (d / "scenario.toml").write_text(tomli_w.dumps(doc), encoding="utf-8")
                for g in p.groups:  # each campaign as `ftcsim campaign` will run it (stop, seed, draws): before anything is written
                    (d / f"{g.kind}.toml").write_text(tomli_w.dumps(p.campaigns[g.kind]), encoding="utf-8")
                    try:
                        api.plan_campaign(d / f"{g.kind}.toml")
                    except api.InputError as e:
                        where = CAMPAIGN_KEYS.get(e.key, f"{key}.campaign")
                        raise api.InputError(arena.path, where, f"{cell.name} ({hw}): {e.key}: {e.problem}") from None
                p.parts = {"scenario": _sha(doc), "campaigns": _sha(p.campaigns), "mode": arena.mode, "models": models}
                note = f"Arena cell {p.name}: its runs' inputs have the digest {p.digest} (scenario, campaigns, models)"
                for g in p.groups:
                    p.campaigns[g.kind]["campaign"]["description"] = f"{note}; fault classes {', '.join(g.faults)}"
                out.append(p)
    return out


def cell_record(arena: Arena, p: CellPlan) -> dict:
    """``cell.json`` of a cell folder."""
    return {"cell": p.cell.name, "hardware": p.hardware, "method": p.cell.method, "plant": p.cell.plant,
            "digest": p.digest, "parts": p.parts, "groups": [{"kind": g.kind, "faults": g.faults, "runs": g.runs}
                                                             for g in p.groups],
            "scenario_file": str(p.cell.scenario), "arena": arena.name}


def changed(old: dict, p: CellPlan) -> list:
    """What differs between a stored ``cell.json`` and the plan: names of the digest parts."""
    parts = old.get("parts") if isinstance(old, dict) else None
    if not isinstance(parts, dict):
        return ["its record (cell.json unreadable or from another version)"]
    names = {"scenario": "its scenario", "campaigns": "its draws, seed, dispersions or fault classes",
             "mode": "the mode (in process / FMU)", "models": "the models (FMUs or model code)"}
    return [names[k] for k in names if parts.get(k) != p.parts.get(k)]
