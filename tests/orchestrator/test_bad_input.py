"""Malformed scenarios: one message naming file and key, exit status 2, nothing written."""
import pytest
from scenario_text import PD, variant, write

from orchestrator.cli.main import main

CASES = {
    "unknown instance": ({'["plant.q", "ctrl.q"]': '["plnt.q", "ctrl.q"]'}, "connections[0]", "unknown instance 'plnt'"),
    "unknown variable": ({'["plant.q", "ctrl.q"]': '["plant.qq", "ctrl.q"]'}, "connections[0]", "no variable 'qq'"),
    "output wired to output": ({'["ctrl.u", "plant.u"]': '["ctrl.u", "plant.tau_applied"]'}, "connections[2]", "expected an input"),
    "input used as source": ({'["ctrl.u", "plant.u"]': '["plant.u", "ctrl.omega"]'}, "connections[2]", "expected an output"),
    "step is a string": ({"step = 0.01": 'step = "0.01"'}, "timing.step", "expected a number"),
    "negative step": ({"step = 0.01": "step = -0.01"}, "timing.step", "must be > 0"),
    "zero step": ({"step = 0.01": "step = 0.0"}, "timing.step", "must be > 0"),
    "stop before start": ({"start = 0.0": "start = 300.0"}, "timing.stop", "must be after start"),
    "step does not divide": ({"step = 0.01": "step = 0.03"}, "timing.step", "whole number of steps"),
    "duplicate connection into one input": (
        {'["plant.omega", "ctrl.omega"],': '["plant.omega", "ctrl.omega"],\n  ["plant.omega", "ctrl.omega_d"],\n  ["plant.d_vib", "ctrl.omega"],'},
        "connections[3]", "already driven by connections[1]",
    ),
    "unknown parameter": ({"k_p = 20.0": "k_pp = 20.0"}, "instances.ctrl.parameters.k_pp", "no parameter 'k_pp'"),
    "NaN parameter": ({"k_p = 20.0": "k_p = nan"}, "instances.ctrl.parameters.k_p", "must be finite"),
    "boolean parameter": ({"k_p = 20.0": "k_p = true"}, "instances.ctrl.parameters.k_p", "expected a number"),
    "wrong vector length": ({"omega_init = [0.02, -0.03, 0.01]": "omega_init = [0.02, -0.03]"}, "instances.plant.parameters.omega_init", "expected shape (3,)"),
    "output set as parameter": ({"k_p = 20.0": "u = 20.0"}, "instances.ctrl.parameters.u", "not a parameter"),
    "source width": ({"values = [[0.8426149773176358, 0.3, 0.2, -0.4],": "values = [[0.3, 0.2, -0.4],"}, "sources.attitude_command.values[0]", "expected 4 numbers"),
    "source times not increasing": ({"times = [0.0, 80.0]": "times = [80.0, 0.0]"}, "sources.attitude_command.times", "strictly increasing"),
    "unknown section": ({"[metrics]": "[metric]"}, "metric", "unknown section"),
    "unknown parameter set": ({'fmu = "PDController"\nparameter_set = "li2023"': 'fmu = "PDController"\nparameter_set = "li2024"'}, "instances.ctrl.parameter_set", "unknown set 'li2024'"),
    "missing FMU": ({'fmu = "PDController"': 'fmu = "NoSuchController"'}, "instances.ctrl.fmu", "FMU file not found"),
    "TOML syntax": ({"stop = 200.0": "stop = 200.0.0"}, "-", "not valid TOML"),
    # a loop of matching units (N.m into the fault-estimate input; tau_applied -> omega is refused for its units)
    "algebraic loop": ({'["plant.omega", "ctrl.omega"],': '["plant.omega", "ctrl.omega"],\n  ["plant.tau_applied", "ctrl.f_hat"],'},
                       "connections", "algebraic loop"),
    "unit mismatch": ({'["plant.omega", "ctrl.omega"],': '["plant.tau_applied", "ctrl.omega"],'}, "connections[1]",
                      "unit mismatch, N.m against rad/s: plant.tau_applied[1..3] (FlexibleSpacecraft output) drives "
                      "ctrl.omega[1..3] (PDController input)"),
    # typos are errors, with the closest valid key suggested
    "scenario key typo": ({'paper = "000"': 'paper = "000"\npapr = "000"'}, "scenario.papr", "did you mean 'paper'"),
    "timing key typo": ({"step = 0.01": "step = 0.01\nstpo = 1.0"}, "timing.stpo", "did you mean 'stop'"),
    "instance key typo": ({'fmu = "PDController"': 'fmu = "PDController"\nparameter_sets = "li2023"'},
                          "instances.ctrl.parameter_sets", "did you mean 'parameter_set'"),
    "source key typo": ({"times = [0.0, 80.0]": "time = [0.0, 80.0]"}, "sources.attitude_command.time", "did you mean 'times'"),
    "record key typo": ({"[record]\nvariables": "[record]\nvariable"}, "record.variable", "did you mean 'variables'"),
    "metrics key typo": ({'control = "ctrl.u"': 'contrl = "ctrl.u"'}, "metrics.contrl", "did you mean 'control'"),
    "top-level key": ({"connections = [": "conections = 1\nconnections = ["}, "conections", "did you mean 'connections'"),
    # numbers: types, NaN / INF, huge values, sizes
    "NaN stop": ({"stop = 200.0": "stop = nan"}, "timing.stop", "must be finite"),
    "INF step": ({"step = 0.01": "step = inf"}, "timing.step", "must be finite"),
    "boolean stop": ({"stop = 200.0": "stop = true"}, "timing.stop", "expected a number"),
    "missing stop": ({"stop = 200.0\n": ""}, "timing.stop", "missing"),
    "huge stop": ({"stop = 200.0": "stop = 99999999999999999999999999999999999999"}, "timing.step", "steps, more than"),
    "huge integer parameter": ({"k_p = 20.0": "k_p = " + "9" * 400}, "instances.ctrl.parameters.k_p", "too large"),
    "INF parameter": ({"k_p = 20.0": "k_p = -inf"}, "instances.ctrl.parameters.k_p", "must be finite"),
    "string in a vector": ({"omega_init = [0.02, -0.03, 0.01]": 'omega_init = [0.02, "a", 0.01]'},
                           "instances.plant.parameters.omega_init", "expected a number"),
    "ragged matrix": ({"u_max = 5.0\n\n[instances.ctrl]": "u_max = 5.0\nJ = [[1.0, 2.0, 3.0], [4.0, 5.0]]\n\n[instances.ctrl]"},
                      "instances.plant.parameters.J", "expected"),
    "matrix of wrong shape": ({"u_max = 5.0\n\n[instances.ctrl]": "u_max = 5.0\nJ = [[1.0, 2.0], [3.0, 4.0]]\n\n[instances.ctrl]"},
                              "instances.plant.parameters.J", "expected shape (3, 3)"),
    "NaN in source values": ({"values = [[0.8426149773176358, 0.3, 0.2, -0.4],": "values = [[nan, 0.3, 0.2, -0.4],"},
                             "sources.attitude_command.values[0]", "must be finite"),
    "exchange scheme": ({'exchange = "ordered"': 'exchange = "gauss"'}, "timing.exchange", "must be 'ordered' or 'jacobi'"),
    # structure
    "instance name with a dash": ({"[instances.ctrl]": '[instances."ctrl-x"]', "[instances.ctrl.parameters]": '[instances."ctrl-x".parameters]'},
                                  "instances.ctrl-x", "identifier"),
    "fmu is a number": ({'fmu = "PDController"': "fmu = 5"}, "instances.ctrl.fmu", "expected a non-empty string"),
    "parameter set is a number": ({'fmu = "PDController"\nparameter_set = "li2023"': 'fmu = "PDController"\nparameter_set = 3'},
                                  "instances.ctrl.parameter_set", "unknown set 3"),
    "source type": ({'type = "piecewise_constant"': 'type = "ramp"'}, "sources.attitude_command.type", "unknown source type"),
    "source target": ({'to = "ctrl.q_d"': 'to = "ctrl.qq_d"'}, "sources.attitude_command.to", "no variable 'qq_d'"),
    "record a parameter": ({'variables = ["plant.q",': 'variables = ["ctrl.k_p", "plant.q",'}, "record.variables[0]",
                           "only inputs and outputs are recorded"),
    "record an undriven input": ({'variables = ["plant.q",': 'variables = ["ctrl.omega_d", "plant.q",'}, "record.variables[0]",
                                 "not driven by anything"),
    "metrics u_max a string": ({"u_max = 5.0\n" * 1 + "attitude_error": "u_max = 5.0\n" + "attitude_error"}, "-", "-"),
    "metrics signal unknown": ({'attitude_error = "ctrl.q_e"': 'attitude_error = "ctrl.nope"'}, "metrics.attitude_error",
                               "no variable 'nope'"),
    "connections not a list": ({'connections = [\n  ["plant.q", "ctrl.q"],\n  ["plant.omega", "ctrl.omega"],\n  ["ctrl.u", "plant.u"],\n]':
                                'connections = "plant.q -> ctrl.q"'}, "connections", "expected a list"),
    "connection of three": ({'["plant.q", "ctrl.q"]': '["plant.q", "ctrl.q", "ctrl.q_d"]'}, "connections[0]", "expected"),
    "connection not strings": ({'["plant.q", "ctrl.q"]': '[1, 2]'}, "connections[0]", "expected 'instance.variable'"),
    "sources not a table": ({"[sources.attitude_command]": "[sources_x]"}, "sources_x", "unknown section"),
    "extends missing file": ({'name = "li2023_pd"': 'name = "li2023_pd"\nextends = "nothere.toml"'}, "scenario.extends", "not found"),
    "extends outside the folder": ({'name = "li2023_pd"': 'name = "li2023_pd"\nextends = "../../x.toml"'}, "scenario.extends",
                                   "outside the scenario's folder"),
    "extends itself": ({'name = "li2023_pd"': 'name = "li2023_pd"\nextends = "case.toml"'}, "scenario.extends", "circular"),
    "extends a number": ({'name = "li2023_pd"': 'name = "li2023_pd"\nextends = 3'}, "scenario.extends", "expected a file name"),
    "extends an unknown shipped name": ({'name = "li2023_pd"': 'name = "li2023_pd"\nextends = "li2023_pdx"'}, "scenario.extends",
                                        "no shipped scenario"),
}
# step policies (orchestrator/cosim/policies.py): one message per problem
_ADAPTIVE = 'exchange = "ordered"\nstep_policy = "adaptive"'
CASES.update({
    "instance step not a multiple": ({'fmu = "PDController"': 'fmu = "PDController"\nstep = 0.025'}, "instances.ctrl.step",
                                     "0.025 s is not a whole multiple of the base step timing.step = 0.01 s"),
    "instance step smaller than the base": ({'fmu = "PDController"': 'fmu = "PDController"\nstep = 0.005'},
                                            "instances.ctrl.step", "not a whole multiple"),
    "instance step under the fixed policy": ({'exchange = "ordered"': 'exchange = "ordered"\nstep_policy = "fixed"',
                                              'fmu = "PDController"': 'fmu = "PDController"\nstep = 0.02'},
                                             "instances.ctrl.step", "needs timing.step_policy = 'multirate', not 'fixed'"),
    "instance step under the adaptive policy": ({'exchange = "ordered"': _ADAPTIVE,
                                                 'fmu = "PDController"': 'fmu = "PDController"\nstep = 0.02'},
                                                "instances.ctrl.step", "not 'adaptive'"),
    "instance step not a number": ({'fmu = "PDController"': 'fmu = "PDController"\nstep = "fast"'}, "instances.ctrl.step",
                                   "expected a number"),
    "run not a whole number of instance steps": ({"stop = 200.0": "stop = 200.01",
                                                  'fmu = "PDController"': 'fmu = "PDController"\nstep = 0.02'},
                                                 "instances.ctrl.step", "not a whole number of this instance's steps"),
    "instance key typo": ({'fmu = "PDController"': 'fmu = "PDController"\nsteps = 0.02'}, "instances.ctrl.steps",
                          "did you mean 'step'"),
    "unknown step policy": ({'exchange = "ordered"': 'exchange = "ordered"\nstep_policy = "adaptiv"'},
                            "timing.step_policy", "did you mean 'adaptive'"),
    "step policy typo": ({'exchange = "ordered"': 'exchange = "ordered"\nstep_polcy = "adaptive"'}, "timing.step_polcy",
                         "did you mean 'step_policy'"),
    "rtol zero": ({'exchange = "ordered"': _ADAPTIVE + "\nrtol = 0.0"}, "timing.rtol", "must be > 0, got 0"),
    "rtol negative": ({'exchange = "ordered"': _ADAPTIVE + "\nrtol = -1e-6"}, "timing.rtol", "must be > 0"),
    "atol negative": ({'exchange = "ordered"': _ADAPTIVE + "\natol = -1e-6"}, "timing.atol", "must be >= 0"),
    "min step above max step": ({'exchange = "ordered"': _ADAPTIVE + "\nmin_step = 0.01\nmax_step = 0.001"},
                                "timing.min_step", "min_step = 0.01 s is larger than max_step = 0.001 s"),
    "default min step above max step": ({'exchange = "ordered"': _ADAPTIVE + "\nmin_step = 0.02"},
                                        "timing.min_step", "larger than max_step = 0.01 s"),
    "safety above one": ({'exchange = "ordered"': _ADAPTIVE + "\nsafety = 1.5"}, "timing.safety", "must be in (0, 1]"),
    "output step does not divide": ({'exchange = "ordered"': _ADAPTIVE + "\noutput_step = 0.03"}, "timing.output_step",
                                    "not a whole number of output intervals"),
    "error variable is an input": ({'exchange = "ordered"': _ADAPTIVE + '\nerror_variables = ["plant.u"]'},
                                   "timing.error_variables[0]", "expected an output"),
    "adaptive key without the adaptive policy": ({'exchange = "ordered"': 'exchange = "ordered"\nrtol = 1e-6'}, "timing.rtol",
                                                 "only used with step_policy = 'adaptive'"),
    "announces a parameter": ({'fmu = "PDController"': 'fmu = "PDController"\nannounces = ["k_p"]'},
                              "instances.ctrl.announces", "'k_p' is not an output of PDController (it is a parameter)"),
    "announces under the fixed policy": ({'exchange = "ordered"': 'exchange = "ordered"\nstep_policy = "fixed"',
                                          'fmu = "PDController"': 'fmu = "PDController"\nannounces = ["u[1]"]'},
                                         "instances.ctrl.announces", "need timing.step_policy = 'multirate' or 'adaptive'"),
    "announcer with a slow step": ({'fmu = "PDController"': 'fmu = "PDController"\nstep = 0.02\nannounces = ["u[1]"]'},
                                   "instances.ctrl.announces", "runs at the base step"),
    "record_announced without announcer": ({'exchange = "ordered"': 'exchange = "ordered"\nrecord_announced = true'},
                                           "timing.record_announced", "no instance announces instants"),
})
CASES = {k: v for k, v in CASES.items() if v[1] != "-"}
# whole values replaced (multi-line arrays): key regex -> new text
WHOLE = {
    "departures not a list": (r"departures = \[.*?\n\]", 'departures = "none"', "scenario.departures", "expected a list"),
    "record not a list": (r"variables = \[.*?\]", 'variables = "plant.q"', "record.variables", "expected a list"),
    "description not a string": (r'description = "[^"]*"', "description = 5", "scenario.description", "expected a string"),
    "empty instances": (r"\[instances\.plant\].*?(?=# 000 Table 1)", "[instances]\n", "instances", "no instances"),
}


def _run(argv, capsys):
    rc = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    return rc, err


@pytest.mark.parametrize("case", sorted(CASES))
def test_malformed_scenario(case, tmp_path, capsys, fmu_dir):
    repl, key, problem = CASES[case]
    path = write(tmp_path, variant(repl))
    out = tmp_path / "results"
    rc, err = _run(["run", str(path), "--out", str(out), "--quiet"], capsys)
    assert rc == 2
    assert len(err) == 1, err
    assert err[0].startswith(f"ftcsim: error: {path}: {key}:"), err[0]
    assert problem in err[0], err[0]
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary leftovers


@pytest.mark.parametrize("case", sorted(WHOLE))
def test_malformed_scenario_values(case, tmp_path, capsys, fmu_dir):
    import re

    pattern, new, key, problem = WHOLE[case]
    text, n = re.subn(pattern, new, PD, count=1, flags=re.S)
    assert n == 1, case
    path = write(tmp_path, text)
    out = tmp_path / "results"
    rc, err = _run(["run", str(path), "--out", str(out), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1, err
    assert err[0].startswith(f"ftcsim: error: {path}: {key}:") and problem in err[0], err[0]
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] == [path.name]


def test_algebraic_loop_names_the_cycle(tmp_path, capsys, fmu_dir):
    path = write(tmp_path, variant(CASES["algebraic loop"][0]))
    rc, err = _run(["run", str(path), "--out", str(tmp_path / "r"), "--quiet"], capsys)
    assert rc == 2
    # u[k] -> tau_applied[j] -> f_hat[j] -> u[k]: all three hops are named
    assert "ctrl.u[" in err[0] and "plant.u[" in err[0] and "plant.tau_applied[" in err[0] and "ctrl.f_hat[" in err[0]


def test_missing_scenario_file(tmp_path, capsys):
    rc, err = _run(["run", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "r")], capsys)
    assert rc == 2 and err == [f"ftcsim: error: {tmp_path / 'nope.toml'}: -: scenario file not found"]


def test_corrupt_fmu_file(tmp_path, capsys, fmu_dir):
    bad = tmp_path / "Broken.fmu"
    bad.write_bytes(b"this is not a zip archive")
    path = write(tmp_path, variant({'fmu = "PDController"': 'fmu = "Broken.fmu"'}))
    rc, err = _run(["run", str(path), "--out", str(tmp_path / "r"), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1
    assert f"{path}: instances.ctrl.fmu:" in err[0] and "not an FMU" in err[0]
    assert not (tmp_path / "r").exists()


def test_zip_without_model_description(tmp_path, capsys, fmu_dir):
    import zipfile

    bad = tmp_path / "Empty.fmu"
    with zipfile.ZipFile(bad, "w") as z:
        z.writestr("readme.txt", "nothing here")
    path = write(tmp_path, variant({'fmu = "PDController"': 'fmu = "Empty.fmu"'}))
    rc, err = _run(["run", str(path), "--out", str(tmp_path / "r"), "--quiet"], capsys)
    assert rc == 2 and "modelDescription" in err[0] and "instances.ctrl.fmu" in err[0]


def test_bad_cli_argument(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main(["run", "x.toml", "--mode", "warp"])
    assert e.value.code == 2
    assert "invalid choice: 'warp'" in capsys.readouterr().err


def test_out_is_a_file(tmp_path, capsys, fmu_dir):
    path = write(tmp_path, PD)
    f = tmp_path / "taken"
    f.write_text("x")
    rc, err = _run(["run", str(path), "--out", str(f)], capsys)
    assert rc == 2 and "--out" in err[0] and f.read_text() == "x"


def test_adaptive_run_refuses_an_fmu_that_cannot_roll_back(tmp_path, capsys, fmu_dir):
    """An FMU whose modelDescription says canGetAndSetFMUstate = false: one message naming it."""
    import zipfile

    src = fmu_dir / "PDController.fmu"
    dst = tmp_path / "NoRollback.fmu"
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                assert b'canGetAndSetFMUstate="true"' in data
                data = data.replace(b'canGetAndSetFMUstate="true"', b'canGetAndSetFMUstate="false"')
            zout.writestr(item, data)
    text = variant({'fmu = "PDController"': 'fmu = "NoRollback.fmu"', 'exchange = "ordered"': _ADAPTIVE})
    path = write(tmp_path, text)
    rc, err = _run(["run", str(path), "--out", str(tmp_path / "r"), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1, err
    assert err[0].startswith(f"ftcsim: error: {path}: instances.ctrl.fmu: NoRollback.fmu cannot get and set its state"), err[0]
    assert "canGetAndSetFMUstate = false" in err[0] and "'adaptive'" in err[0]
    # the same FMU runs with the fixed step, which needs no rollback
    fixed = write(tmp_path, variant({'fmu = "PDController"': 'fmu = "NoRollback.fmu"', "stop = 200.0": "stop = 0.05"}), "f.toml")
    assert main(["run", str(fixed), "--out", str(tmp_path / "f"), "--quiet", "--no-plots"]) == 0
