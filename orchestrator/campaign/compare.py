"""``ftcsim compare CONTROLLER.fmu --out DIR``: a user's controller against the shipped methods on
the same fault draws, as one more variant of a campaign (``orchestrator/campaign/spec.py``).

The comparison is the campaign ``--campaign`` (default: the shipped ``li2023_methods``: PD,
AISMC and FASMC with FAFEO on paper 000's spacecraft, dispersed faults and inertias) with one
variant added: the scenario of ``--scenario`` (default: the campaign's last variant's, FASMC's
li2023_fasmc for li2023_methods) with instance ``--instance`` (default ``ctrl``) replaced by
the user's FMU. ``--runs`` (default 50) and ``--stop`` override the campaign's; draw *k* is
the same in every variant and in the campaign itself (``SeedSequence(seed)``'s child *k*,
independent of the number of runs), so the first 50 draws are li2023_methods' first 50. Then
the campaign report (``orchestrator/campaign/report.py``: statistics per variant, differences
paired by draw, requirements, worst runs, histograms and envelopes) is written to ``DIR/report``.

The derived campaign file (every path in it absolute) is what the campaign folder keeps as
``DIR/campaign.toml``: ``ftcsim campaign DIR/campaign.toml --replay K --out RUN`` replays one run,
and rerunning the same ``ftcsim compare`` command resumes (only the runs not stored are computed).
An FMU whose interface does not fit the scenario (FASMC's d2_hat connected, a unit that does not
match) is refused before anything runs, naming the variable and suggesting ``--scenario``.
"""
from __future__ import annotations

import re
import tempfile
from pathlib import Path

from orchestrator.campaign.spec import _resolve_path, load
from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import parse_toml, read_utf8

DEFAULT_CAMPAIGN = "li2023_methods"
DEFAULT_RUNS = 50


def _absolute(here: Path, arg):
    """A scenario / gains / FMU / folder argument of a campaign file, made absolute (names kept)."""
    return _resolve_path(here, arg) if isinstance(arg, str) else arg


def derive(base: Path, controller: Path, *, scenario: str | None = None, instance: str = "ctrl",
           name: str | None = None, runs: int | None = DEFAULT_RUNS, stop: float | None = None) -> tuple[dict, str]:
    """The campaign document of the comparison, and the name of the user's variant."""
    doc = parse_toml(str(base), read_utf8(base, "campaign file"))
    here = base.parent.resolve()
    meta = doc.get("campaign")
    if not isinstance(meta, dict) or not isinstance(meta.get("scenario"), str):
        raise InputError(str(base), "campaign.scenario", "missing: the campaign to compare in must name its scenario")
    variants = doc.get("variants", [{"name": "base"}])
    if not isinstance(variants, list) or not all(isinstance(v, dict) for v in variants):
        raise InputError(str(base), "variants", "expected [[variants]] tables")
    # every path absolute: the derived file lives elsewhere (the campaign folder keeps it)
    meta["scenario"] = _absolute(here, meta["scenario"])
    if isinstance(meta.get("fmu_dir"), str):
        meta["fmu_dir"] = str((here / meta["fmu_dir"]).resolve())
    if isinstance(meta.get("gains"), list):
        meta["gains"] = [_absolute(here, g) for g in meta["gains"]]
    for v in variants:
        if "scenario" in v:
            v["scenario"] = _absolute(here, v["scenario"])
        if isinstance(v.get("gains"), list):
            v["gains"] = [_absolute(here, g) for g in v["gains"]]
        if isinstance(v.get("fmu"), dict):
            v["fmu"] = {i: _absolute(here, f) for i, f in v["fmu"].items()}
    variant = name or re.sub(r"[^A-Za-z0-9_]", "_", controller.stem).lower()
    if any(v.get("name") == variant for v in variants):
        raise InputError("command line", "--name", f"variant {variant!r} is already one of the campaign's "
                                                   f"({', '.join(str(v.get('name')) for v in variants)}): choose another")
    mine = {"name": variant, "scenario": str(Path(scenario).resolve()) if scenario else
            variants[-1].get("scenario", meta["scenario"]), "fmu": {instance: str(controller.resolve())}}
    doc["variants"] = variants + [mine]
    meta["name"] = f"{meta.get('name', base.stem)}_vs_{variant}"
    if runs is not None:
        meta["runs"] = runs
    others = ", ".join(str(v.get("name")) for v in variants)
    meta["description"] = (f"{controller.name} (variant {variant}: instance {instance} of {Path(mine['scenario']).name}) "
                           f"against {others} of campaign {base.stem}, on its first {meta.get('runs', 1)} draws")
    if stop is not None:
        meta["stop"] = stop
    return doc, variant


def load_comparison(base: Path, controller: Path, **kw):
    """The loaded :class:`orchestrator.campaign.Campaign` of the comparison (everything checked:
    the user's FMU must fit the scenario). Problems of the added variant name the command line."""
    import tomli_w  # only for `ftcsim compare`

    if not controller.is_file():
        raise InputError("command line", "CONTROLLER", f"FMU file not found: {controller}")
    if kw.get("scenario") and not Path(kw["scenario"]).is_file():
        raise InputError("command line", "--scenario", f"scenario file not found: {kw['scenario']}")
    doc, variant = derive(base, controller, **kw)
    j = len(doc["variants"]) - 1
    with tempfile.TemporaryDirectory(prefix="ftcsim_compare_") as tmp:
        path = Path(tmp) / f"{doc['campaign']['name']}.toml"
        path.write_text(f"# ftcsim compare {controller.name} in {base.name}: campaign {base} with variant "
                        f"{variant} added (orchestrator/campaign/compare.py)\n" + tomli_w.dumps(doc), encoding="utf-8")
        try:
            return load(path), variant
        except InputError as e:
            if e.source != str(path):
                raise
            if e.key.startswith(f"variants[{j}]"):
                raise InputError("command line", "CONTROLLER", f"{controller.name} in place of {kw.get('instance', 'ctrl')} "
                                 f"of {Path(doc['variants'][j]['scenario']).name}: {e.problem} (give a scenario that "
                                 "wires this controller with --scenario)") from None
            raise InputError(str(base), e.key, e.problem) from None
