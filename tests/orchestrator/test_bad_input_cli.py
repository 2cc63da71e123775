"""The command line's options and what they refuse (issue 23 item 1, issue 20 items 2 and 6): ``run
--start/--stop/--step/--set``, ``params``, ``campaign --runs/--stop`` and ``extends``, ``--version``,
``-v/-q/--log-file``, a closed pipe, did-you-mean for every unknown name; physical parameter values
refused before any FMU starts for every block family; SSP parameter sets (duplicates, units) and
connections (units); ``[requirements]`` metric names; a non-ASCII FMU file name; the ``verify`` of
what ``design xu2024-ftc`` writes.

Bad input: exit status 2, ONE line ``ftcsim: error: SOURCE: KEY: problem``, nothing written."""
import json
import logging
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scenario_text import PD, ROOT, variant, write

import ftcsim
from orchestrator.campaign.spec import load as load_campaign
from orchestrator.cli.main import main, parser
from orchestrator.common.errors import InputError
from orchestrator.scenario.loading import load_scenario
from orchestrator.scenario.shipped import scenario_files
from orchestrator.scenario.ssp import export_ssp
from orchestrator.scenario.toml import load as load_toml

pytestmark = pytest.mark.fmu
J_ASYM = "[[350, 3, 4], [30, 270, 10], [4, 10, 190]]"  # J[2,1] != J[1,2]
J_INDEF = "[[350, 0, 0], [0, -270, 0], [0, 0, 190]]"


def _run(argv, capsys):
    rc = main(argv)
    cap = capsys.readouterr()
    return rc, cap.err.strip().splitlines(), cap.out


def _refused(argv, capsys, tmp_path, source, key, problem):
    """Exit 2, one line naming ``source`` and ``key`` with ``problem`` in it, nothing in tmp_path
    but what was there."""
    before = sorted(p.name for p in tmp_path.iterdir())
    rc, err, _ = _run(argv, capsys)
    assert rc == 2, err
    assert len(err) == 1, err
    assert err[0].startswith(f"ftcsim: error: {source}: {key}:"), err[0]
    assert problem in err[0], err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written
    return err[0]


# -- ftcsim run: options ---------------------------------------------------------------------------
RUN_CASES = {
    "--set without =": (["--set", "ctrl.k_p"], "command line", "--set ctrl.k_p", "expected INSTANCE.PARAMETER=VALUE"),
    "--set not TOML": (["--set", "ctrl.k_p=1,"], "command line", "--set ctrl.k_p", "not a TOML number or array"),
    "--set a string": (["--set", 'ctrl.k_p="a"'], "command line", "--set ctrl.k_p", "expected a number"),
    "--set unknown parameter": (["--set", "ctrl.k_pp=1"], "command line", "--set ctrl.k_pp",
                                "has no parameter 'k_pp' (did you mean 'k_p'?)"),
    "--set unknown instance": (["--set", "ctl.k_p=1"], "command line", "--set ctl.k_p", "(did you mean 'ctrl'?)"),
    "--set wrong shape": (["--set", "plant.J=[1, 2]"], "command line", "--set plant.J", "expected shape (3, 3)"),
    "--set twice": (["--set", "ctrl.k_p=1", "--set", "ctrl.k_p=2"], "command line", "--set ctrl.k_p", "given twice"),
    "--set NaN": (["--set", "ctrl.k_p=nan"], "command line", "--set ctrl.k_p", "must be finite"),
    "--stop negative": (["--stop", "-1"], "command line", "--stop", "must be a finite number > 0 (s), got -1"),
    "--stop NaN": (["--stop", "nan"], "command line", "--stop", "must be a finite number"),
    "--start after --stop": (["--start", "5", "--stop", "2"], "command line", "--stop", "must be after start"),
    "--step zero": (["--step", "0"], "command line", "--step", "> 0"),
    "--step not dividing": (["--stop", "1", "--step", "0.3"], "command line", "--step", "whole number of steps"),
}


@pytest.mark.parametrize("case", sorted(RUN_CASES))
def test_run_options_refused(case, tmp_path, capsys, fmu_dir):
    extra, source, key, problem = RUN_CASES[case]
    path = write(tmp_path, PD, "pd.toml")
    _refused(["run", str(path), "--out", str(tmp_path / "r"), "-q", *extra], capsys, tmp_path, source or path, key,
             problem)


# -- physical values, every block family, before any FMU starts -------------------------------------
PHYSICAL = {
    # three-axis flexible spacecraft (FlexibleSpacecraft, 000) and its controller's model
    "inertia not symmetric": ("li2023_pd", f"plant.J={J_ASYM}", "plant", "J", "J is not symmetric: J[1,2] = 3"),
    "inertia not positive definite": ("li2023_pd", f"plant.J={J_INDEF}", "plant", "J", "not positive definite"),
    "controller's model inertia": ("li2023_pd", f"ctrl.J={J_INDEF}", "ctrl", "J", "not positive definite"),
    "negative modal frequency": ("li2023_pd", "plant.omega_n=[1.5, -0.1, 1.0, 1.0]", "plant", "omega_n",
                                 "omega_n has -0.1 (element 2 of 4) rad/s: must be > 0"),
    "negative damping": ("li2023_pd", "plant.zeta=[0.0056, 0.0086, -0.01, 0.0125]", "plant", "zeta", "must be >= 0"),
    "negative saturation": ("li2023_pd", "plant.u_max=-5", "plant", "u_max", "u_max = -5 N.m: must be >= 0"),
    "hub minus appendages": ("li2023_pd", "plant.J=[[1, 0, 0], [0, 1, 0], [0, 0, 1]]", "plant", "J",
                             "J - delta^T delta"),
    "effectiveness above one": ("li2023_fasmc", "plant.effectiveness=[1.0, 1.2, 1.0]", "plant", "effectiveness",
                                "must lie in [0, 1]"),
    # three-axis rigid spacecraft with wheels (001), pitch axis (002), wheels and sensors (arena)
    "rigid body with wheels": ("zhang2019_fontsm", f"plant.J={J_INDEF}", "plant", "J", "not positive definite"),
    "pitch-axis inertia": ("zhang2014_hinf_w1", "plant.J=-35.72", "plant", "J", "an inertia must be > 0"),
    "non-positive step bound": ("xu2024_flexible", "plant.h_max=0", "plant", "h_max", "must be > 0"),
    "gyro noise": ("arena/scenarios/arena_fasmc_on_zhang2019_realistic.toml", "gyro.arw=-1e-6", "gyro", "arw",
                   "must be >= 0"),
}


@pytest.mark.parametrize("case", sorted(PHYSICAL))
def test_physical_values_refused_before_any_fmu_starts(case, tmp_path, capsys, fmu_dir):
    scenario, setting, inst, base, problem = PHYSICAL[case]
    if scenario.endswith(".toml"):
        scenario = str(ROOT / scenario)
    elif scenario not in scenario_files():
        pytest.skip(f"no shipped scenario {scenario}")
    # a value given with --set is named as the option, not as the scenario file's (issue 35)
    _refused(["run", scenario, "--out", str(tmp_path / "r"), "--stop", "1", "--set", setting], capsys, tmp_path,
             "command line", f"--set {inst}.{base}", problem)


def test_physical_values_refused_in_a_scenario_file_and_the_api(tmp_path, fmu_dir):
    bad = variant({"u_max = 5.0\n\n[instances.ctrl]": f"u_max = 5.0\nJ = {J_ASYM}\n\n[instances.ctrl]"})
    with pytest.raises(InputError, match=r"instances\.plant\.parameters\.J: FlexibleSpacecraft: J is not symmetric"):
        load_toml(write(tmp_path, bad))
    with pytest.raises(InputError, match="not positive definite"):
        ftcsim.run("li2023_pd", stop=0.1, parameters={"plant.J": np.diag([350.0, -1.0, 190.0])})
    with pytest.raises(InputError, match="not positive definite"):  # in-process: the same rules
        ftcsim.load("li2023_pd", mode="inprocess", parameters={"plant.J": np.diag([350.0, -1.0, 190.0])})


# -- unknown names suggest the closest one --------------------------------------------------------
def test_unknown_scenario_command_and_api_parameter_suggest(tmp_path, capsys):
    _refused(["run", "li2023_fasm", "--out", str(tmp_path / "r")], capsys, tmp_path, "command line", "SCENARIO",
             "did you mean 'li2023_fasmc'?")
    rc, err, _ = _run_exit(["rnu", "li2023_pd"], capsys)
    assert rc == 2 and len(err) == 1 and "invalid choice: 'rnu'" in err[0] and "did you mean 'run'?" in err[0], err
    with pytest.raises(InputError, match=r"parameters\.plant\.fault_scal: .*did you mean 'fault_scale'"):
        ftcsim.load("li2023_fasmc", mode="inprocess", parameters={"plant.fault_scal": 0.5})


def _run_exit(argv, capsys):
    with pytest.raises(SystemExit) as e:
        main(argv)
    cap = capsys.readouterr()
    return e.value.code, cap.err.strip().splitlines(), cap.out


def test_params_unknown_instance_and_log_file_folder(tmp_path, capsys, fmu_dir):
    _refused(["params", "li2023_pd", "--instance", "ctl"], capsys, tmp_path, "command line", "--instance",
             "did you mean 'ctrl'?")
    _refused(["--log-file", str(tmp_path / "no" / "such" / "x.log"), "scenarios"], capsys, tmp_path, "command line",
             "--log-file", "cannot open")


# -- campaign: --runs/--stop, extends, requirements ----------------------------------------------------
CAMPAIGN = """[campaign]
scenario = "li2023_pd"
runs = 2
stop = 0.1

[parameters]
"plant.fault_scale" = 0.5
"""


def test_campaign_options_refused(tmp_path, capsys, fmu_dir):
    c = write(tmp_path, CAMPAIGN, "c.toml")
    _refused(["campaign", str(c), "--out", str(tmp_path / "o"), "--runs", "0"], capsys, tmp_path, "command line",
             "--runs", "must be >= 1")
    _refused(["campaign", str(c), "--out", str(tmp_path / "o"), "--stop", "-3"], capsys, tmp_path, "command line",
             "--stop", "must be a finite number of seconds > 0")


EXTENDS = {
    "outside the folder": ('extends = "../base.toml"', "outside the campaign's folder"),
    "missing": ('extends = "nothere.toml"', "base campaign not found"),
    "itself": ('extends = "child.toml"', "circular extends"),
    "not a file name": ("extends = 3", "expected a campaign file name"),
}


@pytest.mark.parametrize("case", sorted(EXTENDS))
def test_campaign_extends_refused(case, tmp_path, capsys):
    line, problem = EXTENDS[case]
    (tmp_path / "sub").mkdir()
    child = write(tmp_path / "sub", f"[campaign]\n{line}\nruns = 3\n", "child.toml")
    write(tmp_path, CAMPAIGN, "base.toml")
    _refused(["campaign", str(child), "--out", str(tmp_path / "sub" / "o")], capsys, tmp_path, child,
             "campaign.extends", problem)


def test_campaign_extends_cycle_refused(tmp_path, capsys):
    a = write(tmp_path, '[campaign]\nextends = "b.toml"\n', "a.toml")
    write(tmp_path, '[campaign]\nextends = "a.toml"\n', "b.toml")
    _refused(["campaign", str(a), "--out", str(tmp_path / "o")], capsys, tmp_path, tmp_path / "b.toml",
             "campaign.extends", "circular extends through a.toml")


REQUIREMENTS = {
    "misspelt generic metric": ("final_attitude_eror", "did you mean 'final_attitude_error'?"),
    "misspelt energy": ("control_enrgy", "did you mean 'control_energy'?"),
    "settling time without [settling]": ("settling_time", "only with a [settling] table"),
}


@pytest.mark.parametrize("case", sorted(REQUIREMENTS))
def test_requirement_metric_names(case, tmp_path, capsys, fmu_dir):
    metric, problem = REQUIREMENTS[case]
    c = write(tmp_path, CAMPAIGN + f"\n[requirements]\n{metric} = {{ max = 1.0 }}\n", "c.toml")
    _refused(["campaign", str(c), "--out", str(tmp_path / "o")], capsys, tmp_path, c, f"requirements.{metric}",
             problem)


def test_campaign_grid_point_with_a_meaningless_value_refused(tmp_path, capsys):
    c = write(tmp_path, CAMPAIGN.replace('"li2023_pd"', '"li2023_pd"\nmode = "inprocess"')
              + '\n[grid]\n"plant.h_max" = [0.01, -1.0]\n', "c.toml")
    _refused(["campaign", str(c), "--out", str(tmp_path / "o"), "--workers", "0"], capsys, tmp_path, c,
             "grid (point 1: plant.h_max = -1.0)", "plant.h_max: FlexibleSpacecraft: h_max = -1 s")


def test_campaign_extends_merges_and_overrides(tmp_path, fmu_dir):
    """A base in a subfolder with its own relative scenario path; the child changes runs and adds a
    parameter (tables merge key by key); --runs/--stop override both, and the folder's manifest
    text says so."""
    (tmp_path / "common").mkdir()
    shutil.copy(scenario_files()["li2023_pd"], tmp_path / "common" / "pd.toml")
    write(tmp_path / "common", CAMPAIGN.replace('"li2023_pd"', '"pd.toml"'), "base.toml")
    child = write(tmp_path, '[campaign]\nextends = "common/base.toml"\nruns = 5\n\n[parameters]\n"ctrl.k_p" = 30.0\n',
                  "child.toml")
    c = load_campaign(child)
    assert c.runs == 5 and c.timing == {"stop": 0.1}
    assert c.variants[0].scenario == str((tmp_path / "common" / "pd.toml").resolve())
    assert c.variants[0].parameters == {"plant.fault_scale": 0.5, "ctrl.k_p": 30.0}
    assert c.bases[0].instances["ctrl"].parameters["k_p"] == 30.0
    o = load_campaign(child, runs=2, stop=0.05)
    assert (o.runs, o.timing["stop"], o.n_runs) == (2, 0.05, 2) and o.digest != c.digest
    assert o.bases[0].stop == 0.05


# -- SSP import: duplicate parameters, parameter and connection units, physical values -----------------
@pytest.fixture(scope="module")
def pd_ssp(tmp_path_factory, fmu_dir):
    tmp = tmp_path_factory.mktemp("ssp")
    return export_ssp(load_toml(write(tmp, variant({"stop = 200.0": "stop = 1.0"}), "pd.toml")), tmp / "pd.ssp")


def _tampered(src: Path, dst: Path, member: str, edit) -> Path:
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            zout.writestr(item, edit(data.decode()).encode() if item.filename == member else data)
    return dst


SSP_CASES = {
    "duplicate parameter": ("resources/plant.ssv",
                            lambda t: t.replace("<ssv:Parameters>", '<ssv:Parameters>\n<ssv:Parameter name="u_max">'
                                                '<ssv:Real value="1.0" unit="N.m"/></ssv:Parameter>', 1),
                            "Component[plant]/resources/plant.ssv/u_max", "given twice"),
    "parameter unit": ("resources/plant.ssv", lambda t: t.replace('unit="kg.m2"', 'unit="N.m"', 1),
                       "Component[plant]/resources/plant.ssv/J[1,1]", "unit mismatch, N.m against kg.m2"),
    "connection unit": ("SystemStructure.ssd",
                        lambda t: t.replace('startElement="plant" startConnector="omega[1]"',
                                            'startElement="plant" startConnector="tau_applied[1]"', 1),
                        "Connection[plant.tau_applied[1] -> ctrl.omega[1]]", "unit mismatch, N.m against rad/s"),
    "inertia not symmetric": ("resources/plant.ssv",
                              lambda t: re.sub(r'(name="J\[1,2\]">\s*<ssv:Real value=")3.0', r"\g<1>30.0", t),
                              "instances.plant.parameters.J", "J is not symmetric"),
}


@pytest.mark.parametrize("case", sorted(SSP_CASES))
def test_ssp_import_refused(case, tmp_path, capsys, pd_ssp):
    member, edit, key, problem = SSP_CASES[case]
    bad = _tampered(pd_ssp, tmp_path / "bad.ssp", member, edit)
    _refused(["run", str(bad), "--out", str(tmp_path / "r")], capsys, tmp_path, bad, key, problem)


# -- the command line itself ---------------------------------------------------------------------------
def test_every_option_has_help_and_the_top_help_is_whole(capsys):
    p = parser()
    sub = next(a for a in p._actions if isinstance(a, type(p._subparsers._group_actions[0])))
    missing = [f"{name} {' '.join(a.option_strings)}" for name, cmd in [("ftcsim", p), *sub.choices.items()]
               for a in cmd._actions if a.option_strings and not a.help]
    assert not missing, missing
    text = p.format_help()
    for name in sub.choices:
        assert re.search(rf"^\s+{re.escape(name)}\s", text, re.M), name
    assert "Docs: README.md, docs/." in text  # the epilog: the text is not cut


def test_version(capsys):
    """ftcsim's version, then fmpy, pythonfmu, pythonfmu3, numpy, Python as installed, and the commit of
    this checkout (git's own answer)."""
    from importlib.metadata import version

    code, _, out = _run_exit(["--version"], capsys)
    lines = out.splitlines()
    assert code == 0 and re.fullmatch(r"ftcsim \d+\.\d+\.\d+\S*", lines[0]), out
    for pkg in ("fmpy", "pythonfmu", "pythonfmu3", "numpy"):
        assert f"{pkg} {version(pkg)}" in lines, out
    assert f"python {sys.version.split()[0]}" in lines
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    if head.returncode == 0:
        assert lines[-1].startswith(f"git commit {head.stdout.strip()}"), out


def test_closed_pipe_ends_quietly(tmp_path):
    """``ftcsim scenarios | head -1``: the first line, no message, exit 141 (128 + SIGPIPE)."""
    p = subprocess.run(f"{sys.executable} -m orchestrator.cli.main scenarios | head -1; echo \"rc=${{PIPESTATUS[0]}}\"",
                       shell=True, executable="/bin/bash", capture_output=True, text=True, cwd=ROOT, timeout=120)
    lines = p.stdout.splitlines()
    assert len(lines) == 2 and lines[0].split()[0] in scenario_files() and lines[1] == "rc=141", p.stdout
    assert p.stderr == "", p.stderr


def test_verbosity_and_log_file(tmp_path, capsys, fmu_dir):
    log = tmp_path / "ftcsim.log"
    rc, err, out = _run(["-v", "--log-file", str(log), "params", "li2023_pd", "--instance", "ctrl"], capsys)
    assert rc == 0 and "ctrl.k_p" in out
    assert any("loaded" in line for line in err), err  # -v: the debug line on stderr
    assert "DEBUG ftcsim.scenario: loaded li2023_pd" in log.read_text()
    rc, err, out = _run(["params", "li2023_pd", "--instance", "ctrl", "-q"], capsys)
    assert rc == 0 and err == [] and "ctrl.k_p" in out


class _Records(logging.Handler):
    def __init__(self):
        super().__init__(logging.DEBUG)
        self.lines = []

    def emit(self, record):
        self.lines.append(record.getMessage())


def test_lmi_solves_are_logged_with_their_time():
    import cvxpy as cp

    import lmi

    A = np.array([[-1.0, 0.5], [0.0, -2.0]])
    p = lmi.LMIProblem("tiny")
    P = p.symmetric("P", 2)
    p.positive_definite("P > 0", P, 1e-6)
    p.negative_definite("A'P + PA < 0", A.T @ P + P @ A, 1e-6)
    p.constrain(cp.trace(P) == 1)
    records, logger = _Records(), logging.getLogger("ftcsim.lmi")
    logger.addHandler(records)
    level, logger.level = logger.level, logging.INFO
    try:
        p.solve()
    finally:
        logger.removeHandler(records)
        logger.setLevel(level)
    done = [line for line in records.lines if " in " in line]
    assert done and re.search(r"tiny: solve with \w+: optimal in \d+\.\d s", done[0]), done


# -- ftcsim params ---------------------------------------------------------------------------------------
def test_params_lists_values_units_and_descriptions(capsys, fmu_dir):
    rc, _, out = _run(["params", "li2023_fasmc", "--json", "--set", "ctrl.beta=1.5"], capsys)
    rows = {f"{r['instance']}.{r['parameter']}": r for r in json.loads(out)}
    assert rc == 0
    assert rows["ctrl.beta"]["value"] == 1.5 and rows["ctrl.beta"]["unit"] == "1/s"
    assert rows["plant.J"]["unit"] == "kg.m2" and rows["plant.J"]["description"] == "hub inertia"
    J = np.array(rows["plant.J"]["value"])
    assert J.shape == (3, 3) and np.allclose(J, J.T) and np.all(np.linalg.eigvalsh(J) > 0)
    assert rows["plant.fault_scale"]["value"] == 1.0 and "fault" in rows["plant.fault_scale"]["description"]
    # every parameter of every instance, as the FMUs declare them
    sc = load_scenario("li2023_fasmc")
    declared = {f"{i}.{n.split('[')[0]}" for i, inst in sc.instances.items() for n in inst.interface.names("parameter")}
    assert set(rows) == declared


# -- same trajectory from the command line and the API -----------------------------------------------------
@pytest.mark.slow
def test_run_with_set_equals_the_api(tmp_path, capsys, fmu_dir):
    """``ftcsim run li2023_fasmc --stop 20 --set plant.fault_scale=0.5 --set ctrl.beta=1.5`` and
    ``ftcsim.run`` with the same overrides record the same trajectory; without the overrides the
    command u differs from the first step on (beta enters s = omega_e + beta q_ev, 000 (39))."""
    out = tmp_path / "cli"
    rc, err, _ = _run(["run", "li2023_fasmc", "--stop", "20", "--set", "plant.fault_scale=0.5", "--set",
                       "ctrl.beta=1.5", "--out", str(out), "--no-plots", "-q"], capsys)
    assert rc == 0, err
    cli = pd.read_parquet(out / "results.parquet").set_index("time")  # the default format
    api = ftcsim.run("li2023_fasmc", stop=20, parameters={"plant.fault_scale": 0.5, "ctrl.beta": 1.5})
    assert cli.shape == api.df.shape and cli.index[-1] == pytest.approx(20.0)
    np.testing.assert_allclose(cli.to_numpy(), api.df.to_numpy(), rtol=1e-12, atol=1e-12)
    nominal = ftcsim.run("li2023_fasmc", stop=0.1)
    u = [c for c in cli.columns if c.startswith("ctrl.u[")]
    assert np.abs(nominal.df[u].to_numpy()[1:5] - cli[u].to_numpy()[1:5]).max() > 1e-6


# -- a non-ASCII FMU file name runs ----------------------------------------------------------------------
def test_non_ascii_fmu_file_name_runs(tmp_path, fmu_dir):
    """It segfaulted the master (exit 139): the extraction folder took the file's letters and
    pythonfmu reads a wrong resources folder from a percent-encoded URI."""
    shutil.copy(fmu_dir / "PDController.fmu", tmp_path / "Régulateur_PD.fmu")
    s = write(tmp_path, '[scenario]\nextends = "li2023_pd"\n[timing]\nstop = 0.05\n'
                        '[instances.ctrl]\nfmu = "Régulateur_PD.fmu"\nparameter_set = "li2023"\n', "s.toml")
    env = {**os.environ, "FTCSIM_FMU_DIR": str(fmu_dir)}
    p = subprocess.run([sys.executable, "-m", "orchestrator.cli.main", "run", str(s), "--out", str(tmp_path / "r"),
                        "--no-plots", "-q"], capture_output=True, text=True, cwd=ROOT, env=env, timeout=300)
    assert p.returncode == 0, p.stderr
    df = pd.read_parquet(tmp_path / "r" / "results.parquet")  # the default format
    assert len(df) == 6 and np.isfinite(df.to_numpy()).all()


# -- verify what design writes -------------------------------------------------------------------------------
def test_verify_accepts_the_design_file_form_and_refuses_another_case(tmp_path, capsys):
    from papers.p004_xu2024.gains import DESIGNED

    K = np.asarray(DESIGNED["K"]).tolist()
    good = tmp_path / "d.json"
    good.write_text(json.dumps({"design": "xu2024-ftc", "case": "nonhomogeneous", "gains": {"K": K}}))
    rc, _, out = _run(["verify", "xu2024-ftc", "--gains", str(good)], capsys)
    assert rc == 0 and "all checks hold" in out, out
    other = tmp_path / "h.json"
    other.write_text(json.dumps({"design": "xu2024-ftc-homogeneous", "case": "homogeneous", "gains": {"K": K}}))
    _refused(["verify", "xu2024-ftc", "--gains", str(other)], capsys, tmp_path, other, "design",
             "file is for 'xu2024-ftc-homogeneous'")
