"""An arena cell (one method on one plant, ideal or realistic hardware) as a scenario and a campaign.

The cell's scenario file wires the method's loop with the fault catalog as instance ``faults``
(``arena/scenarios``). :func:`cell_scenario` derives from it the scenario the arena runs:

* ideal hardware: the file as it is (the papers' perfect sensors and actuators), the allocation not
  told of a failed wheel (``alloc.failed_wheel = 0``: the faulty wheel is drawn);
* realistic hardware: the same loop with the plant table's data-sheet hardware inserted by a rewrite
  of the connections, the same for every cell of a plant family:

  - actuators: ``faults.u_f -> X`` becomes ``faults.u_f -> wheels.u_c``, ``wheels.<torque> -> X``:
    one ``ReactionWheel1`` on the pitch axis (``tau``), four ``ReactionWheels4`` (001's layout) where
    the catalog acts per wheel (``u_wheel``) and, where it acts on three body axes, an allocation
    ``ralloc`` (M^+, 001's layout) before the four wheels (``tau``); on three axes the plant carries the
    wheels' momentum as its states (``wheel_momentum`` = 1: the gyroscopic torque inside its integration,
    issue 32), so the wheels add none (``gyroscopic`` = 0);
  - controller sample rate: a ``ZeroOrderHold`` ``zoh`` on the controller's command (the signal that
    feeds ``faults.u``, or ``alloc.u`` when an allocation sits between): every consumer of the
    command (the estimator too) reads the held value;
  - sensors: every consumer of the plant's rate (``plant.omega`` / ``plant.theta_dot``, not the
    wheels) reads a gyro ``gyro``; of its attitude a star tracker ``st`` (``plant.q``, ``e2q.q``, or
    ``plant.sigma`` through ``st_e2q`` -> ``st`` -> ``st_q2e``) or the pitch sensor ``att``
    (``plant.theta``).
  - the sampled blocks (``zoh``, ``gyro``, ``st``, ``att``) step at their sample period (a multirate
    run, :func:`sampled_steps`) where it is a whole multiple of the communication step and divides
    the mission: they read their input at their sample instants only and hold their output in
    between, so every other block sees the same numbers as at the communication step (tested bit for
    bit), for a fraction of the calls.

:func:`campaign_doc` writes the cell as campaigns: one variant per fault class, ``draws`` runs, the
fault parameters (onset, loss, magnitude as a scale of the plant's ``fault_torque``, channel, Markov
seed) and the sensors' seeds dispersed with the arena's seed, so that draw k is the same random
numbers in every cell (paired comparisons), and the metric signals stored as trajectories. A fault
class whose runs no dispersed number can change (:func:`deterministic`: no fault and ideal hardware)
is one run, not ``draws`` identical ones.

Every cell flies its plant's mission (``[plants.NAME] mission``, or the arena's ``stop`` cut);
:func:`manoeuvres` are the instants its attitude command switches, from which (or from the fault
onset, the later) its time to band is measured.
"""
from __future__ import annotations

import copy

from orchestrator.api import read_toml

from .arenafile import FAULT_CLASSES, Arena, Cell

CATALOG_CHANNELS = {"FaultCatalog1": 1, "FaultCatalog3": 3, "FaultCatalog4": 4}
RATE = {"plant.omega": ("RateGyro3", 3), "plant.theta_dot": ("RateGyro1", 1)}


def read_scenario(cell: Cell) -> dict:
    return read_toml(cell.scenario, "scenario file")[1]


def channels(doc: dict) -> int:
    """Actuator channels of the cell's fault catalog (instance ``faults``)."""
    return CATALOG_CHANNELS[doc["instances"]["faults"]["fmu"]]


def family(doc: dict) -> str:
    return "pitch" if channels(doc) == 1 else "3-axis"


def _source(conns, dst):
    for a, b in conns:
        if b == dst:
            return a
    return None


def _redirect(conns, src, new, keep=lambda dst: True):
    """Every connection from ``src`` (to a destination ``keep`` accepts) reads ``new`` instead."""
    return [[new, b] if a == src and keep(b) else [a, b] for a, b in conns]


def _add(doc, name, fmu, parameter_set=None, parameters=None):
    inst = {"fmu": fmu}
    if parameter_set:
        inst["parameter_set"] = parameter_set
    if parameters:
        inst["parameters"] = dict(parameters)
    doc["instances"][name] = inst


def realistic(doc: dict, hw: dict) -> dict:
    """The rewrite of the module docstring; ``hw``: the plant table's parameter sets."""
    doc = copy.deepcopy(doc)
    conns = [list(c) for c in doc["connections"]]
    n = channels(doc)
    insts = doc["instances"]
    for taken in ("wheels", "ralloc", "zoh", "gyro", "st", "st_e2q", "st_q2e", "att"):
        if taken in insts:
            raise ValueError(f"instance name {taken!r} is taken by the cell's scenario")
    # controller sample rate: hold the command that feeds the catalog (through an allocation)
    cmd = _source(conns, "faults.u")
    width = n
    if cmd is not None and cmd.split(".")[0] == "alloc":
        cmd, width = _source(conns, "alloc.u"), 3
    if cmd is None:
        raise ValueError("no command reaches faults.u")
    _add(doc, "zoh", {1: "ZeroOrderHold1", 3: "ZeroOrderHold3", 4: "ZeroOrderHold4"}[width], hw["hold"])
    conns = _redirect(conns, cmd, "zoh.y") + [[cmd, "zoh.u"]]
    # actuators
    outs = [b for a, b in conns if a == "faults.u_f"]
    conns = [c for c in conns if c[0] != "faults.u_f"]
    if n == 1:
        _add(doc, "wheels", "ReactionWheel1", hw["wheels"])
        conns += [["faults.u_f", "wheels.u_c"]] + [["wheels.tau", b] for b in outs]
    elif n == 4:
        _add(doc, "wheels", "ReactionWheels4", hw["wheels"], {"gyroscopic": 0.0})
        insts["plant"].setdefault("parameters", {})["wheel_momentum"] = 1.0
        conns += [["faults.u_f", "wheels.u_c"], ["plant.omega", "wheels.omega"]] + [["wheels.u_wheel", b] for b in outs]
    else:
        _add(doc, "ralloc", "TorqueAllocation")
        _add(doc, "wheels", "ReactionWheels4", hw["wheels"], {"gyroscopic": 0.0})
        insts["plant"].setdefault("parameters", {})["wheel_momentum"] = 1.0
        conns += [["faults.u_f", "ralloc.u"], ["ralloc.u_c", "wheels.u_c"], ["plant.omega", "wheels.omega"]]
        conns += [["wheels.tau", b] for b in outs]
    # sensors: the rate
    for sig, (fmu, _) in RATE.items():
        if any(a == sig and not b.startswith("wheels.") for a, b in conns):
            _add(doc, "gyro", fmu, hw["gyro"], {"seed": 1})
            conns = _redirect(conns, sig, "gyro.omega_m", keep=lambda b: not b.startswith("wheels."))
            conns.append([sig, "gyro.omega"])
    # ... and the attitude
    if any(a == "plant.theta" for a, _ in conns):
        _add(doc, "att", "AngleSensor1", hw["attitude_sensor"], {"seed": 2})
        conns = _redirect(conns, "plant.theta", "att.theta_m") + [["plant.theta", "att.theta"]]
    else:
        for q in ("plant.q", "e2q.q"):
            if any(a == q for a, _ in conns):
                _add(doc, "st", "StarTracker", hw["attitude_sensor"], {"seed": 2})
                conns = _redirect(conns, q, "st.q_m") + [[q, "st.q"]]
                break
        else:
            if any(a == "plant.sigma" for a, _ in conns):
                _add(doc, "st_e2q", "Euler231ToQuaternion")
                _add(doc, "st", "StarTracker", hw["attitude_sensor"], {"seed": 2})
                _add(doc, "st_q2e", "QuaternionToEuler231")
                conns = _redirect(conns, "plant.sigma", "st_q2e.sigma")
                conns += [["plant.sigma", "st_e2q.sigma"], ["st_e2q.q", "st.q"], ["st.q_m", "st_q2e.q"]]
    doc["connections"] = conns
    doc["record"]["variables"] = list(dict.fromkeys(doc["record"]["variables"] + ["wheels.u_wheel", "wheels.h"]))
    sampled_steps(doc)
    return doc


def sampled_steps(doc: dict) -> dict:
    """Give the sampled hardware instances (``zoh``, ``gyro``, ``st``, ``att``) their sample period as
    their own communication step where the period is a whole multiple of the base step and the run
    (start to stop) a whole number of periods; the others keep the base step. In place; returns ``doc``."""
    from plant.hardware.datasheets import ALL

    timing = doc["timing"]
    h, span = float(timing["step"]), float(timing["stop"]) - float(timing.get("start", 0.0))

    def whole(x: float) -> bool:
        return x >= 1.0 - 1e-9 and abs(x - round(x)) <= 1e-9 * max(1.0, x)

    for name in ("zoh", "gyro", "st", "att"):
        inst = doc["instances"].get(name)
        if inst is None:
            continue
        T = float(inst.get("parameters", {}).get("sample_period", ALL.get(inst.get("parameter_set"), {}).get(
            "sample_period", 0.0)))
        if T > h and whole(T / h) and whole(span / T):
            inst["step"] = T
    return doc


def delivered(doc: dict) -> str:
    """The signal of the torque the ideal actuators deliver, per channel: the plant's ``tau_applied``
    where the plant applies them itself (000's craft: after its 5 N.m saturation, without u_d; the pitch
    axes: rho sat(u)); on 004's craft what enters the summing junction beside d(t) (``dsum.u``: the
    catalog's u_f, or the body torque of virtual wheels); on 001's craft the catalog's per-wheel u_f."""
    model = doc["instances"]["plant"]["fmu"]
    if model == "FlexibleSpacecraft" or family(doc) == "pitch":
        return "plant.tau_applied"
    if "dsum" in doc["instances"]:
        src = _source(doc["connections"], "dsum.u")
        if src is not None:
            return src
    return "faults.u_f"


def metric_signals(doc: dict, cell: Cell) -> dict:
    """The recorded signals the arena's metrics read, by role (instance.variable)."""
    insts = doc["instances"]
    s = {"fault": "faults.fault", "delivered": delivered(doc), "torque": "plant.tau_applied", "active": "faults.active"}
    if family(doc) == "pitch":
        s.update(attitude="plant.theta", rate="plant.theta_dot")
    else:
        s.update(attitude="plant.q" if "FlexibleSpacecraft" in insts["plant"]["fmu"] or
                 "Xu2024" in insts["plant"]["fmu"] else "plant.sigma", rate="plant.omega")
    if "wheels" in insts:
        s.update(wheel_torque="wheels.u_wheel", wheel_momentum="wheels.h")
    if cell.estimate:
        s.update(estimate=cell.estimate, truth=cell.truth)
    return s


def target(doc: dict) -> dict | None:
    """The attitude command (a piecewise-constant source to ``*.q_d``) as {times, values}; None:
    the identity (regulation)."""
    for src in doc.get("sources", {}).values():
        to = src.get("to")
        to = [to] if isinstance(to, str) else list(to or [])
        if any(t.endswith(".q_d") for t in to) and src.get("type") == "piecewise_constant":
            return {"times": list(src["times"]), "values": [list(v) for v in src["values"]]}
    return None


def manoeuvres(doc: dict) -> list:
    """Instants (s) after the start at which the cell's attitude command switches (its
    piecewise-constant ``q_d`` source), before the stop; [] for a constant command."""
    tg = target(doc)
    if tg is None:
        return []
    start, stop = float(doc["timing"].get("start", 0.0)), float(doc["timing"]["stop"])
    return [float(t) for t in tg["times"] if start < float(t) < stop]


def deterministic(hardware: str, fault: str) -> bool:
    """True when no dispersed number reaches the runs: no fault (its onset, size, channel and seed act
    on nothing) with ideal hardware (no sensor noise): one run stands for every draw."""
    return fault == "none" and hardware == "ideal"


def cell_scenario(arena: Arena, cell: Cell, hardware: str) -> dict:
    """The scenario the arena runs for ``cell`` with ``hardware`` (module docstring), recording
    every metric signal, flying the plant's mission."""
    doc = read_scenario(cell)
    doc.setdefault("timing", {})["stop"] = float(arena.mission(cell))
    insts = doc["instances"]
    if "faults" not in insts or insts["faults"].get("fmu") not in CATALOG_CHANNELS:
        raise ValueError("the cell's scenario has no fault catalog instance 'faults' (FaultCatalog1/3/4)")
    if "alloc" in insts:
        insts["alloc"].setdefault("parameters", {})["failed_wheel"] = 0
    if hardware == "realistic":
        doc = realistic(doc, arena.plants[cell.plant].hardware)
    sig = metric_signals(doc, cell)
    doc.setdefault("record", {}).setdefault("variables", [])
    doc["record"]["variables"] = list(dict.fromkeys(doc["record"]["variables"] + list(sig.values())))
    doc["scenario"]["name"] = f"arena_{cell.method}_on_{cell.plant}_{hardware}"
    doc.pop("metrics", None)  # the arena measures with arena/metrics.py
    return doc


def campaign_doc(arena: Arena, cell: Cell, hardware: str, scenario_file: str, doc: dict, faults: list,
                 runs: int, name: str, note: str = "") -> dict:
    """The campaign of one cell, hardware and the fault classes ``faults`` (module docstring) with
    ``runs`` draws; ``scenario_file`` relative to the campaign file; ``note`` goes into its
    description (the arena writes what decides the runs there: a changed input changes the file,
    and a campaign folder refuses to resume with another file)."""
    plant = arena.plants[cell.plant]
    n = channels(doc)
    meta = {"name": name, "description": note, "scenario": scenario_file, "runs": int(runs),
            "seed": arena.seed, "mode": arena.mode, "trajectory_step": arena.trajectory_step,
            "trajectories": sorted(set(metric_signals(doc, cell).values()))}
    if arena.fmu_dir is not None:
        meta["fmu_dir"] = str(arena.fmu_dir)
    d = arena.dispersions
    disp = {
        "faults.onset": {"distribution": "uniform", "low": d["onset"][0], "high": d["onset"][1]},
        "faults.loss": {"distribution": "uniform", "low": d["loss"][0], "high": d["loss"][1]},
        "faults.magnitude": {"distribution": "uniform", "low": d["magnitude"][0], "high": d["magnitude"][1],
                             "apply": "scale"},
        "faults.channel": {"distribution": "integer", "low": 1, "high": n + 1},
        "faults.seed": {"distribution": "integer", "low": 1, "high": 1_000_000},
    }
    for inst in ("gyro", "st", "att"):
        if inst in doc["instances"]:
            disp[f"{inst}.seed"] = {"distribution": "integer", "low": 1, "high": 1_000_000}
    variants = [{"name": f, "parameters": {"faults.fault_class": float(FAULT_CLASSES[f]),
                                           "faults.magnitude": plant.fault_torque}} for f in faults]
    out = {"campaign": meta, "variants": variants}
    if not all(deterministic(hardware, f) for f in faults):
        out["dispersions"] = disp
    return out
