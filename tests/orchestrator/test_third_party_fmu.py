"""A third-party FMU in a shipped scenario: a C FMU (FMI 2.0, compiled from tests/fmus/third_party/,
not made by pythonfmu) replaces FASMC in li2023_fasmc and runs in our master in ordered and Jacobi
modes; interfaces are matched by name, causality and unit, and each mismatch is one clear message
naming both ends."""
import sys
from pathlib import Path

import numpy as np
import pytest
from scenario_text import write

from orchestrator.cli.main import main
from orchestrator.cosim.block import BlockComponent
from orchestrator.cosim.master import Master
from orchestrator.cosim.runner import run_scenario
from orchestrator.cosim.sources import PiecewiseConstant
from orchestrator.scenario.fmu_checks import check_fmu, toolbox_problems
from orchestrator.scenario.interfaces import fmu_unit_definitions
from orchestrator.scenario.toml import load
from papers.registry import block_factory
from plant.units import known_units, mismatch

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs" / "examples"))
from pd_block import MinimalPD  # noqa: E402  (the same law, written in Python)

pytestmark = pytest.mark.fmu
PD_CONNECTIONS = """connections = [
  ["plant.q", "ctrl.q"],
  ["plant.omega", "ctrl.omega"],
  ["plant.omega", "est.omega"],
  ["est.f_hat", "ctrl.f_hat"],
  ["ctrl.u", "est.u"],
  ["ctrl.u", "plant.u"],
]
"""


def replaced(c_fmu, connections=PD_CONNECTIONS, stop=2.0):
    """li2023_fasmc with FASMC replaced by the C FMU (a changed fmu replaces the instance's table)."""
    return (f"{connections}\n[scenario]\nextends = \"li2023_fasmc\"\nname = \"c_fmu_in_li2023\"\n\n"
            f"[timing]\nstop = {stop}\n\n[instances.plant.parameters]\nfault_onset = 0.5\n\n"
            f"[instances.ctrl]\nfmu = \"{Path(c_fmu).as_posix()}\"\n")


def test_c_fmu_passes_the_load_checks(c_fmu):
    assert check_fmu(c_fmu) == []  # binary for this platform, plain modelIdentifier, fmpy.validate_fmu
    assert toolbox_problems(c_fmu) == []
    from fmpy import read_model_description

    md = read_model_description(str(c_fmu))
    assert md.generationTool == "gcc, by hand" and md.coSimulation.modelIdentifier == "c_attitude_pd"
    assert fmu_unit_definitions(md)["N.m"] == known_units()["N.m"]


def reference(scenario, exchange):
    """The same scenario in-process with the Python MinimalPD in place of the C FMU."""
    comps = {name: BlockComponent(name, MinimalPD() if name == "ctrl" else block_factory(inst.model_name)())
             for name, inst in scenario.instances.items()}
    for name, comp in comps.items():
        comp.setup(scenario.start, scenario.stop, scenario.instances[name].parameters, {})
    sources = [PiecewiseConstant(s.name, s.times, s.values, s.targets) for s in scenario.sources]
    return Master(comps, scenario.connections, sources, scenario.record, exchange=exchange).run(
        scenario.start, scenario.stop, scenario.step)


def test_c_fmu_runs_in_li2023_fasmc_ordered_and_jacobi(c_fmu, tmp_path, fmu_dir):
    scenario = load(write(tmp_path, replaced(c_fmu)))
    assert scenario.instances["ctrl"].model_name == "CAttitudePD"
    runs = {}
    for exchange in ("ordered", "jacobi"):
        result = run_scenario(scenario, exchange=exchange)
        assert result.complete, result.error
        ref = reference(scenario, exchange)
        assert ref.columns == result.columns and np.array_equal(ref.time, result.time)
        u, u_ref = result.vector("ctrl.u"), ref.vector("ctrl.u")
        # C and numpy evaluate the same law: equal to rounding over the whole closed loop
        assert np.abs(u - u_ref).max() <= 1e-12, exchange
        assert np.abs(result.data - ref.data).max() <= 1e-10, exchange
        runs[exchange] = result
    # the exchange scheme matters (the C FMU's u feeds through from q and omega): the test has teeth
    assert np.abs(runs["ordered"].vector("ctrl.u") - runs["jacobi"].vector("ctrl.u")).max() > 1e-4
    omega = runs["ordered"].vector("plant.omega")
    assert np.linalg.norm(omega[-1]) < 0.5 * np.linalg.norm(omega[0])  # the C law controls the spacecraft
    assert np.abs(runs["ordered"].vector("est.f_hat")).max() > 1e-3  # and uses the estimate


def _one_error(tmp_path, capsys, text):
    path = write(tmp_path, text)
    rc = main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    assert not (tmp_path / "out").exists()
    return err[0].removeprefix(f"ftcsim: error: {path}: ")


def test_missing_input_names_both_ends(c_fmu, tmp_path, capsys, fmu_dir):
    """The base's connections kept: FASMC's d2_hat input does not exist on the replacement."""
    text = replaced(c_fmu, connections="")
    msg = _one_error(tmp_path, capsys, text)
    assert msg == ("connections[4]: est.d2_hat -> ctrl.d2_hat: instance 'ctrl' (CAttitudePD, CAttitudePD.fmu) has no "
                   "variable 'd2_hat' (its inputs: q[0..3], omega[1..3], q_d[0..3], f_hat[1..3])"), msg


def test_unit_mismatch_names_both_ends(c_fmu, tmp_path, capsys, fmu_dir):
    conns = PD_CONNECTIONS.replace('["plant.omega", "est.omega"]', '["ctrl.u", "est.omega"]')
    msg = _one_error(tmp_path, capsys, replaced(c_fmu, conns))
    assert msg == ("connections[2]: ctrl.u -> est.omega: unit mismatch, N.m against rad/s: ctrl.u[1..3] (CAttitudePD "
                   "output) drives est.omega[1..3] (FAFEO input)"), msg


def test_output_wired_to_output_names_both_ends(c_fmu, tmp_path, capsys, fmu_dir):
    conns = PD_CONNECTIONS.replace('["plant.q", "ctrl.q"]', '["plant.q", "ctrl.q_e"]')
    msg = _one_error(tmp_path, capsys, replaced(c_fmu, conns))
    assert msg == ("connections[0]: plant.q -> ctrl.q_e: 'ctrl.q_e[0]' is an output, expected an input "
                   "(an output wired to an output)"), msg


def test_every_mismatch_is_listed_at_once(c_fmu, tmp_path, capsys, fmu_dir):
    conns = PD_CONNECTIONS.replace('["plant.q", "ctrl.q"]', '["plant.q", "ctrl.q_e"]').replace(
        '["plant.omega", "est.omega"]', '["ctrl.u", "est.omega"]')
    msg = _one_error(tmp_path, capsys, replaced(c_fmu, conns))
    assert msg.startswith("connections: 2 connections do not match: [0] plant.q -> ctrl.q_e: ") and \
        "| [2] ctrl.u -> est.omega: unit mismatch, N.m against rad/s" in msg, msg


def test_units_are_matched_in_process_too(tmp_path, scenarios):
    """The blocks' own declarations: li2023_pd with the rate wired into the fault-estimate input."""
    from scenario_text import PD

    from orchestrator.common.errors import InputError

    text = PD.replace('["plant.omega", "ctrl.omega"],', '["plant.omega", "ctrl.omega"],\n  ["plant.omega", "ctrl.f_hat"],')
    with pytest.raises(InputError) as e:
        load(write(tmp_path, text), in_process=True)
    assert e.value.key == "connections[2]"
    assert e.value.problem == ("plant.omega -> ctrl.f_hat: unit mismatch, rad/s against N.m: plant.omega[1..3] "
                               "(FlexibleSpacecraft output) drives ctrl.f_hat[1..3] (PDController input)")


def test_unit_equivalence_by_definition():
    torque = {"Nm": known_units()["N.m"]}
    assert mismatch("Nm", torque, "N.m", {}) is None  # another name, the same SI definition
    assert mismatch("", {}, "1", {}) is None  # no unit is dimensionless
    assert mismatch("deg", {}, "rad", {}) == "deg against rad (same dimension, another scale: no conversion is made)"
    assert mismatch("N.m", {}, "rad/s", {}) == "N.m against rad/s"
    assert mismatch("lbf.ft", {}, "N.m", {}) == "lbf.ft against N.m"  # unknown and undefined: refused
