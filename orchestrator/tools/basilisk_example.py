"""ftcsim's fault estimators and FTC laws flying a Basilisk spacecraft with Honeywell wheels, faults
injected, and the same loop in ftcsim (``python -m orchestrator.tools.basilisk_example``; needs the
optional extra ftcsim[basilisk] and the built FMUs, ``make fmus``).

Two missions (``--mission``), each flown twice:

* in Basilisk: a spacecraft with Honeywell HR16 wheels from ``simIncludeRW`` (50 N.m.s, 0.2 N.m,
  6000 rpm), the FMUs as Basilisk modules (orchestrator/interop/basilisk/module.py), the faults by
  ftcsim's fault-catalog FMUs between the law and the wheels;
* in ftcsim: the same FMUs with ftcsim's plant, once with the wheel momenta as plant states and the
  wheels' torque limit (``wheel_momentum`` = 1, ``u_max`` = 0.2 N.m), once with the paper's equation
  (no wheel momentum).

``001``: 001's ASMFEO + FONTSM on a rigid craft with four HR16 wheels in 001's layout. Not 001's: the
inertia (001's J breaks the triangle inequality and Basilisk refuses it: a rigid body's of the same
size is used), the initial state (a tenth of 001's attitude and a hundredth of its tumble: 001's asks
173 N.m of 0.2 N.m wheels), FONTSM's switching gains eps_1, eps_2 divided by 200 (the printed ones ask
tens of N.m), the variant settings of zhang2019_fontsm_accurate (boundary layer 0.005 rad/s, 2 s
fractional memory, fast observer), a 10 ms step. Faults of 001 from 20 s: 0.04 N.m bias on wheel 1,
40 % loss on wheel 2.

``000``: 000's FAFEO + FASMC on 000's flexible craft: a hub with one hinged panel per flexible mode
(massless panels that are exactly 000's modal model, conventions.panels_from_modes) and three HR16
wheels on the body axes. Not 000's: the wheels' 0.2 N.m (FASMC saturates at it, per axis), no
misalignment, no disturbance, the fault (50 % loss on wheel 1 from 40 s, through the fault catalog),
a tenth of 000's initial rate (000's asks minutes of 0.2 N.m), the target held at 000's first attitude
(the initial rate is nulled and the attitude brought back), 120 s.

Writes ``summary.json`` (per mission: the largest differences Basilisk - ftcsim over the run, with and
without wheel momentum, and the wheel speeds against their limit), ``<mission>.png`` and the ftcsim
scenarios it ran (``<mission>_ftcsim.toml``) into ``--out``.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

RPM = 2.0 * math.pi / 60.0
S3 = 1.0 / math.sqrt(3.0)


@dataclass
class Mission:
    name: str
    title: str
    J: np.ndarray
    G: np.ndarray
    q0: np.ndarray
    omega0: np.ndarray
    stop: float
    step: float
    plant: str  # ftcsim's plant FMU
    plant_params: dict
    fmus: list  # (instance, model, parameters, inputs {base: port}, outputs {base: port}, priority, held inputs,
    #              priority of the late call of a split module or None)
    links: list  # (instance, input, source instance, output)
    modes: dict | None = None
    dyn_step: float = 0.001
    record: dict = field(default_factory=dict)  # key -> (instance, output base)


def fmu_defaults(model: str) -> dict:
    """The start values of one of ftcsim's built FMUs (its paper's numbers), by base name, as arrays:
    the examples take the papers' values from the FMUs they fly (the orchestrator reads no paper)."""
    from fmpy import read_model_description

    from orchestrator.interop.basilisk.module import resolve_fmu
    from plant.naming import split_name

    groups = {}
    for v in read_model_description(str(resolve_fmu(model))).modelVariables:
        if v.start is not None and v.type in ("Real", "Float64"):
            base, idx = split_name(v.name)
            groups.setdefault(base, []).append((idx, float(v.start)))
    out = {}
    for base, items in groups.items():
        if items[0][0] == ():
            out[base] = np.array(items[0][1])
            continue
        lo = np.min([i for i, _ in items], axis=0)
        a = np.zeros(tuple(np.max([i for i, _ in items], axis=0) - lo + 1))
        for i, x in items:
            a[tuple(np.array(i) - lo)] = x
        out[base] = a
    return out


def mission_001() -> Mission:
    from orchestrator.interop.basilisk import conventions as cv

    plant, ctrl0 = fmu_defaults("RigidSpacecraftWheels"), fmu_defaults("FONTSM")
    SIGMA0, OMEGA0, M = plant["sigma_init"], plant["omega_init"], plant["M"]  # 001 section 5
    J = np.array([[30.0, 1.3, 1.4], [1.3, 27.0, 2.0], [1.4, 2.0, 19.0]])
    sigma0, omega0 = 0.1 * SIGMA0, 0.01 * OMEGA0
    common = {"J": J, "M": M}
    ctrl = {**common, "eps_1": ctrl0["eps_1"] / 200.0, "eps_2": ctrl0["eps_2"] / 200.0, "boundary_layer": 0.005,
            "fo_memory": 2.0,
            "fo_step": 0.01}
    est = {**common, "lambda_1": 2000.0, "lambda_2": 2000.0, "command_pairing": 1, "omega_hat_init": omega0}
    return Mission(
        "001", "001's ASMFEO + FONTSM, 4 x HR16, bias 0.04 N.m on wheel 1 and 40 % loss on wheel 2 from 20 s",
        J, M, cv.quaternion_from_mrp(cv.mrp_from_euler231(sigma0)), omega0, 60.0, 0.01, "RigidSpacecraftWheels",
        {"J": J, "M": M, "sigma_init": sigma0, "omega_init": omega0, "dJ_amp": np.zeros(3), "Td_amp": np.zeros(3),
         "effectiveness": np.ones(4), "bias": np.zeros(4), "u_max": 0.2},
        [("ctrl", "FONTSM", ctrl, {"sigma": "sc.sigma231", "omega": "sc.omega"}, {}, 90, {}, None),
         ("bias", "FaultCatalog4", {"fault_class": 3, "channel": 1, "onset": 20.0, "magnitude": 0.04}, {}, {}, 80, {}, None),
         ("loss", "FaultCatalog4", {"fault_class": 1, "channel": 2, "onset": 20.0, "loss": 0.4}, {},
          {"u_f": "rw.torque"}, 70, {}, None),
         ("est", "ASMFEO", est, {"omega": "sc.omega"}, {}, 60, {}, None)],
        [("ctrl", "e_hat", "est", "e_hat"), ("ctrl", "uf_hat", "est", "uf_hat"), ("est", "u_c", "ctrl", "u_c"),
         ("bias", "u", "ctrl", "u_c"), ("loss", "u", "bias", "u_f")],
        record={"u": ("ctrl", "u_c"), "u_applied": ("loss", "u_f"), "e_hat": ("est", "e_hat")})


def mission_000() -> Mission:
    plant = fmu_defaults("FlexibleSpacecraft")  # 000 section 5's J, delta, modes
    LI2023 = {k: plant[k] for k in ("J", "delta", "omega_n", "zeta")}
    q0 = np.array([np.sqrt(1 - 0.29), 0.3, 0.2, -0.4])  # 000 Table 1: q(0) = the 0-80 s target
    omega0 = 0.1 * np.array([0.02, -0.03, 0.01])  # a tenth of 000 section 5.2's omega(0), rad/s
    return Mission(
        "000", "000's FAFEO + FASMC, flexible craft (4 hinged panels), 3 x HR16, 50 % loss on wheel 1 from 40 s",
        LI2023["J"], np.eye(3), q0, omega0, 120.0, 0.01, "FlexibleSpacecraft",
        {**LI2023, "q_init": q0, "omega_init": omega0, "u_max": 0.2, "saturation_mode": 0},
        [("est", "FAFEO", {}, {"omega": "sc.omega"}, {}, 95, {}, 60),  # f_hat needs omega(t), est.u needs ctrl.u
         ("ctrl", "FASMC", {"u_max": 0.2, "saturation_mode": 0}, {"q": "sc.q", "omega": "sc.omega"}, {}, 90,
          {"q_d": q0}, None),
         ("loss", "FaultCatalog3", {"fault_class": 1, "channel": 1, "onset": 40.0, "loss": 0.5}, {},
          {"u_f": "rw.torque"}, 80, {}, None)],
        [("ctrl", "f_hat", "est", "f_hat"), ("ctrl", "d2_hat", "est", "d2_hat"), ("est", "u", "ctrl", "u"),
         ("loss", "u", "ctrl", "u")],
        modes={"delta": LI2023["delta"], "omega_n": LI2023["omega_n"], "zeta": LI2023["zeta"]},
        record={"u": ("ctrl", "u"), "u_applied": ("loss", "u_f"), "f_hat": ("est", "f_hat")})


MISSIONS = {"001": mission_001, "000": mission_000}


def fly_basilisk(m: Mission, stop: float):
    """The mission in Basilisk: (Flight, craft)."""
    from orchestrator.interop.basilisk import conventions as cv
    from orchestrator.interop.basilisk.mission import add_module, build_craft, fly
    from orchestrator.interop.basilisk.module import FMUModule

    craft = build_craft(m.J, m.step, dyn_step=m.dyn_step, sigma_BN=cv.mrp_from_quaternion(m.q0), omega=m.omega0, G=m.G,
                        wheel="Honeywell_HR16", max_momentum=50.0, modes=m.modes)
    modules = {}
    for name, model, params, inputs, outputs, _, held, late in m.fmus:
        mod = FMUModule(model, m.step, params, inputs=inputs, outputs=outputs, name=name, split=late is not None)
        if held:
            mod.hold(held)
        if mod.inputs:
            mod.scStateInMsg.subscribeTo(craft.sc.scStateOutMsg)
        modules[name] = mod
    for dst, inp, src, out in m.links:
        modules[dst].link(inp, modules[src], out)
    for name, _, _, _, outputs, priority, _, late in m.fmus:
        if "rw.torque" in outputs.values():
            craft.rw.rwMotorCmdInMsg.subscribeTo(modules[name].rwMotorTorqueOutMsg)
        add_module(craft, name, modules[name], priority)
        if late is not None:
            craft.sim.AddModelToTask(craft.task, modules[name].late, late)
    flight = fly(craft, stop, {k: (modules[i], b) for k, (i, b) in m.record.items()})
    return flight, craft


def _toml(value) -> str:
    a = np.asarray(value, dtype=float)
    return repr(float(a)) if a.ndim == 0 else json.dumps(a.tolist())


PLANT_PORTS = {"sc.sigma231": "sigma", "sc.q": "q", "sc.omega": "omega"}


def scenario_text(m: Mission, momentum: bool, stop: float) -> str:
    """The ftcsim scenario of the same loop (same FMUs and values; ftcsim's plant)."""
    torque_in = "u_c" if m.plant == "RigidSpacecraftWheels" else "u"
    conns = []
    for name, _, _, inputs, outputs, _, _, _ in m.fmus:
        conns += [f'["plant.{PLANT_PORTS[p]}", "{name}.{b}"]' for b, p in inputs.items()]
        conns += [f'["{name}.{b}", "plant.{torque_in}"]' for b, p in outputs.items() if p == "rw.torque"]
    conns += [f'["{src}.{out}", "{dst}.{inp}"]' for dst, inp, src, out in m.links]
    lines = ["connections = [", *(f"  {c}," for c in conns), "]", "", "[scenario]", f'name = "basilisk_example_{m.name}"',
             f'description = "{m.title} (ftcsim side; wheel_momentum = {int(momentum)})"', "", "[timing]",
             "start = 0.0", f"stop = {stop!r}", f"step = {m.step!r}", 'exchange = "ordered"', "", "[instances.plant]",
             f'fmu = "{m.plant}"', "", "[instances.plant.parameters]"]
    plant = {**m.plant_params, "wheel_momentum": 1.0 if momentum else 0.0, "h_max": m.dyn_step}
    if m.plant == "FlexibleSpacecraft":
        plant.pop("q_init")
        plant.update({f"q_init[{i}]": x for i, x in enumerate(m.q0)})
    lines += [f'"{k}" = {_toml(v)}' if "[" in k else f"{k} = {_toml(v)}" for k, v in plant.items()]
    for name, model, params, _, _, _, held, _ in m.fmus:
        lines += ["", f"[instances.{name}]", f'fmu = "{model}"']
        if params:
            lines += ["", f"[instances.{name}.parameters]", *(f"{k} = {_toml(v)}" for k, v in params.items())]
        for base, value in held.items():
            lines += ["", f"[sources.{name}_{base}]", 'type = "constant"', f'to = "{name}.{base}"', f"value = {_toml(value)}"]
    rec = [f'"plant.{v}"' for v in ("omega",)] + [f'"plant.{"q" if m.plant == "FlexibleSpacecraft" else "sigma"}"',
                                                   '"plant.h_w"'] + [f'"{i}.{b}"' for i, b in m.record.values()]
    lines += ["", "[record]", f"variables = [{', '.join(rec)}]", ""]
    return "\n".join(lines)


def run_ftcsim(m: Mission, momentum: bool, stop: float, out: Path):
    from orchestrator.api import run

    path = out / f"{m.name}_ftcsim{'' if momentum else '_paper_equation'}.toml"
    path.write_text(scenario_text(m, momentum, stop), encoding="utf-8")
    return run(str(path)).df


def attitude(m: Mission, df) -> np.ndarray:
    """[BN] per row of ftcsim's results."""
    from plant.euler231 import dcm
    from plant.so3 import rotation_matrix

    if m.plant == "FlexibleSpacecraft":
        q = df[[f"plant.q[{i}]" for i in range(4)]].to_numpy()
        return np.array([rotation_matrix(x) for x in q])
    s = df[[f"plant.sigma[{i}]" for i in (1, 2, 3)]].to_numpy()
    return np.array([dcm(x) for x in s])


def angle_between(A, B) -> np.ndarray:
    """Rotation angle (rad) of A B^T per row: 2 asin |q_v| of its quaternion (the attitude-error metric's
    form, exact near 0, where an arccos of the trace loses half the digits)."""
    from plant.attitude_adapters import quaternion_from_dcm

    return np.array([2.0 * math.asin(min(1.0, float(np.linalg.norm(quaternion_from_dcm(a @ b.T)[1:]))))
                     for a, b in zip(A, B)])


def compare(m: Mission, flight, craft, df) -> dict:
    """The largest differences Basilisk - ftcsim over the run."""
    from orchestrator.interop.basilisk import conventions as cv

    n = min(len(df), len(flight.t))
    w = df[[f"plant.omega[{i}]" for i in (1, 2, 3)]].to_numpy()[:n]
    C_b = np.array([cv.mrp_to_dcm(s) for s in flight.sigma_BN[:n]])
    h_b = np.array([cv.inertial_momentum(s, o, m.G, craft.I_w) for s, o in zip(flight.speed[:n], flight.omega[:n])])
    h = df[[c for c in df.columns if c.startswith("plant.h_w[")]].to_numpy()[:n]
    ctrl, base = m.record["u"]
    u = df[[c for c in df.columns if c.startswith(f"{ctrl}.{base}[")]].to_numpy()[:n]
    return {"omega": float(np.abs(w - flight.omega[:n]).max()), "attitude": float(angle_between(attitude(m, df)[:n], C_b).max()),
            "wheel_momentum": float(np.abs(h - h_b).max()), "command": float(np.abs(u - flight.outputs["u"][:n]).max())}


def plot(m: Mission, flight, df, df_paper, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from orchestrator.interop.basilisk import conventions as cv

    n = min(len(df), len(flight.t))
    t = flight.t[:n]
    C_b = np.array([cv.mrp_to_dcm(s) for s in flight.sigma_BN[:n]])
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), constrained_layout=True)
    ax[0, 0].plot(t, flight.omega[:n])
    ax[0, 0].set(title="body rate, Basilisk", xlabel="t (s)", ylabel="rad/s")
    ax[0, 1].plot(t, np.abs(flight.speed[:n]) / RPM)
    ax[0, 1].axhline(6000.0, color="k", ls=":", lw=0.8)
    ax[0, 1].set(title="wheel speeds |Omega|, Basilisk (limit 6000 rpm)", xlabel="t (s)", ylabel="rpm")
    ax[1, 0].plot(t, flight.outputs["u_applied"][:n])
    ax[1, 0].set(title="wheel commands after the faults (on the body; the wheels clip at 0.2 N.m)", xlabel="t (s)",
                 ylabel="N.m")
    for d, label in ((df, "ftcsim, wheel momentum"), (df_paper, "ftcsim, the paper's equation")):
        k = min(n, len(d))
        w = d[[f"plant.omega[{i}]" for i in (1, 2, 3)]].to_numpy()[:k]
        ax[1, 1].semilogy(t[:k], np.maximum(np.abs(w - flight.omega[:k]).max(axis=1), 1e-18), label=f"|omega| diff.: {label}")
        ax[1, 1].semilogy(t[:k], np.maximum(angle_between(attitude(m, d)[:k], C_b[:k]), 1e-18), ls="--",
                          label=f"attitude diff. (rad): {label}")
    ax[1, 1].set(title="ftcsim against Basilisk", xlabel="t (s)")
    ax[1, 1].legend(fontsize=7)
    fig.suptitle(m.title, fontsize=10)
    tmp = path.with_name(f".{path.name}.partial.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    tmp.replace(path)


def fly_all(names, stop_arg, out: Path) -> dict:
    """Every mission of ``names`` in both tools, into the folder ``out``; the summary."""
    summary = {}
    for name in names:
        m = MISSIONS[name]()
        stop = m.stop if stop_arg is None else min(stop_arg, m.stop)
        t0 = time.perf_counter()
        flight, craft = fly_basilisk(m, stop)
        t1 = time.perf_counter()
        df = run_ftcsim(m, True, stop, out)
        t2 = time.perf_counter()
        df_paper = run_ftcsim(m, False, stop, out)
        with_momentum, paper = compare(m, flight, craft, df), compare(m, flight, craft, df_paper)
        summary[name] = {"title": m.title, "stop_s": stop, "step_s": m.step, "dynamics_step_s": m.dyn_step,
                         "basilisk_minus_ftcsim_wheel_momentum": with_momentum,
                         "basilisk_minus_ftcsim_paper_equation": paper,
                         "max_wheel_speed_rpm": float(np.abs(flight.speed).max() / RPM), "wheel_speed_limit_rpm": 6000.0,
                         "wall_s": {"basilisk": round(t1 - t0, 1), "ftcsim": round(t2 - t1, 1)}}
        plot(m, flight, df, df_paper, out / f"{name}.png")
        print(f"{name}: {m.title}")
        print(f"  Basilisk - ftcsim (wheel momentum): |omega| <= {with_momentum['omega']:.2g} rad/s, attitude <= "
              f"{with_momentum['attitude']:.2g} rad, |h_w| <= {with_momentum['wheel_momentum']:.2g} N.m.s, "
              f"|u| <= {with_momentum['command']:.2g} N.m")
        print(f"  Basilisk - ftcsim (paper's equation): |omega| <= {paper['omega']:.2g} rad/s, attitude <= "
              f"{paper['attitude']:.2g} rad")
        print(f"  wheel speeds <= {summary[name]['max_wheel_speed_rpm']:.0f} rpm (limit 6000); wall: Basilisk "
              f"{t1 - t0:.0f} s, ftcsim {t2 - t1:.0f} s")
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    return summary


def main(argv=None) -> int:
    import importlib.util

    from orchestrator.common.errors import InputError, SimulationError
    from orchestrator.common.outputs import OutputFolder

    ap = argparse.ArgumentParser(prog="python -m orchestrator.tools.basilisk_example", description=__doc__.splitlines()[0])
    ap.add_argument("--mission", choices=["001", "000", "both"], default="both")
    ap.add_argument("--out", required=True, help="new folder for summary.json, the plots and the ftcsim scenarios")
    ap.add_argument("--overwrite", action="store_true", help="replace a previous result of this example in --out")
    ap.add_argument("--stop", type=float, default=None, help="s: end of the runs (default: the mission's, 60 s / 120 s)")
    args = ap.parse_args(argv)
    try:
        if importlib.util.find_spec("Basilisk") is None:
            raise InputError("command line", "python -m orchestrator.tools.basilisk_example",
                             "Basilisk is not installed: pip install 'ftcsim[basilisk]'")
        if args.stop is not None and not (args.stop > 0 and math.isfinite(args.stop)):
            raise InputError("command line", "--stop", f"must be a number > 0, got {args.stop:g}")
        folder = OutputFolder(args.out, "basilisk-example", overwrite=args.overwrite).check()
        folder.fill(lambda tmp: fly_all(["001", "000"] if args.mission == "both" else [args.mission], args.stop, tmp))
    except InputError as e:
        print(f"ftcsim: error: {' '.join(str(e).split())}", file=sys.stderr)
        return 2
    except SimulationError as e:
        print(f"ftcsim: run failed: {' '.join(str(e).split())}", file=sys.stderr)
        return 1
    print(f"results in {args.out}: summary.json, one plot and the ftcsim scenarios per mission")
    return 0


if __name__ == "__main__":
    from orchestrator.common.process_exit import finish

    finish(main())
