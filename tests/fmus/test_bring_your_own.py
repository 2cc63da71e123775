"""`ftcsim build --block`: the documented example block (docs/examples/pd_block.py) becomes a valid
FMU (fmpy and the fmu-manipulation-toolbox checker), rolls back exactly and runs in li2023_fasmc in
place of FASMC; a user's package outside the project is embedded; what cannot be embedded is refused."""
import json
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmu_driver import Driver

from fmus.build import BuildError, build_block
from orchestrator.cli.main import main
from orchestrator.cosim.block import BlockComponent
from orchestrator.cosim.master import Master
from orchestrator.cosim.runner import run_scenario
from orchestrator.cosim.sources import PiecewiseConstant
from orchestrator.scenario.fmu_checks import check_fmu, toolbox_problems
from orchestrator.scenario.toml import load
from papers.registry import block_factory

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "docs" / "examples"
sys.path.insert(0, str(EXAMPLES))
from pd_block import MinimalPD  # noqa: E402

pytestmark = pytest.mark.fmu


def pd_law(q, omega, q_d, f_hat, k_p=20.0, k_d=60.0, u_max=5.0):
    """The documented law, row by row, written independently of the block (000 (4) for q_e)."""
    q0, qv, d0, dv = q[:, :1], q[:, 1:], q_d[:, :1], q_d[:, 1:]
    q_ev = d0 * qv - np.cross(dv, qv) - q0 * dv
    return np.clip(-k_p * q_ev - k_d * omega - f_hat, -u_max, u_max), q_ev


def build_example(out, fmi):
    """MinimalPD.fmu, built the documented way: `ftcsim build --block pd_block:MinimalPD --path docs/examples`."""
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main(["build", "--block", "pd_block:MinimalPD", "--path", str(EXAMPLES), "--out", str(out), "--fmi", fmi])
    lines = buf.getvalue().splitlines()
    assert rc == 0, lines
    assert lines == [f"built {out} (model MinimalPD, FMI {fmi}, embeds pd_block.py of the block's own)",
                     "  valid (fmpy, fmu-manipulation-toolbox)"]  # no contract warning: the feedthrough is exact
    return out


@pytest.fixture(scope="module")
def example_fmu(tmp_path_factory):
    return build_example(tmp_path_factory.mktemp("example") / "MinimalPD.fmu", "2")


@pytest.fixture(scope="module")
def example_fmu3(tmp_path_factory):
    return build_example(tmp_path_factory.mktemp("example3") / "MinimalPD.fmu", "3")


@pytest.fixture(params=["2", "3"], ids=["fmi2", "fmi3"])
def any_example_fmu(request):
    return request.getfixturevalue("example_fmu" if request.param == "2" else "example_fmu3")


@pytest.mark.slow
def test_example_fmu_validates_and_declares_the_block(any_example_fmu):
    example_fmu = any_example_fmu
    assert check_fmu(example_fmu) == []  # load checks + fmpy.validate_fmu
    assert toolbox_problems(example_fmu) == []  # fmutool -check: schema and semantic rules
    md = read_model_description(str(example_fmu))
    block = MinimalPD()
    deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
    assert deps == {v.name: sorted(block.feedthrough.get(v.name, ())) for v in block.outputs}
    assert deps["omega_e[2]"] == ["omega[2]"] and "omega[1]" not in deps["u[2]"]  # exact, element by element
    units = {v.name: v.unit or "1" for v in md.modelVariables}
    assert all(units[v.name] == v.unit for v in block.inputs + block.outputs + block.parameters)
    with zipfile.ZipFile(example_fmu) as z:
        names = set(z.namelist())
        module = z.read("resources/slavemodule.txt").decode().strip()
        info = json.loads(z.read("resources/ftcsim_build.json"))
        embedded = z.read("resources/pd_block.py")
    assert embedded == (EXAMPLES / "pd_block.py").read_bytes()
    adapter = "adapter3" if md.fmiVersion.startswith("3") else "adapter"
    assert {"resources/plant/block.py", f"resources/fmus/{adapter}.py", f"resources/{module}.py"} <= names
    assert not any(n.startswith(("resources/orchestrator/", "resources/papers/", "resources/controller/")) for n in names)
    prefix = "ftcsim3_minimalpd_" if adapter == "adapter3" else "ftcsim_minimalpd_"
    assert module.startswith(prefix) and len(module) == len(prefix) + 10  # unique per code
    assert info["factory"] == "pd_block:MinimalPD" and info["embedded_user_modules"] == {"pd_block": "pd_block.py"}
    assert info["requirements"] == ["numpy>=1.26"]


@pytest.mark.slow
def test_example_fmu_rolls_back_exactly_and_computes_the_law(any_example_fmu):
    drv = Driver(any_example_fmu, "byo_rollback")
    rng = np.random.default_rng(3)
    inputs = [dict(zip(["q[0]", "q[1]", "q[2]", "q[3]", "omega[1]", "omega[2]", "omega[3]", "q_d[0]", "q_d[1]",
                        "f_hat[1]"], rng.normal(0, 0.2, 10) + [0.9, 0, 0, 0, 0, 0, 0, 1, 0, 0])) for _ in range(6)]
    outs = drv.outputs()

    def run(t):
        rows = []
        for u in inputs:
            drv.set(u)
            rows.append(drv.get(outs))
            drv.step(t, 0.01)
            t += 0.01
        return rows

    try:
        drv.initialize({"k_p": 12.0})
        run(0.0)
        state = drv.save()
        blob = drv.serialize(state)
        first = run(0.06)
        drv.restore(state)
        second = run(0.06)
        drv.restore(drv.deserialize(blob))
        third = run(0.06)
        assert first == second == third
        u = np.array([list(x.values()) for x in inputs])
        q, w, qd = u[:, 0:4], u[:, 4:7], np.c_[u[:, 7:9], np.zeros((6, 2))]
        f = np.c_[u[:, 9], np.zeros((6, 2))]
        cmd, q_ev = pd_law(q, w, qd, f, k_p=12.0)
        got = np.array(first)
        assert np.allclose(got[:, 0:3], cmd, rtol=0, atol=1e-14)
        assert np.allclose(got[:, 4:7], q_ev, rtol=0, atol=1e-14)
        assert np.abs(cmd).max() == 5.0 and np.abs(cmd).min() < 5.0  # saturated and unsaturated rows
    finally:
        drv.free()


def own_controller_scenario(tmp_path, ctrl_fmu, stop=2.0):
    """docs/examples/own_controller.toml with the controller FMU given, shortened to ``stop`` s
    (faults from 0.5 s, so that the estimate that the PD feeds forward is not trivial)."""
    text = (EXAMPLES / "own_controller.toml").read_text()
    assert 'fmu = "MinimalPD.fmu"' in text
    text = text.replace('fmu = "MinimalPD.fmu"', f'fmu = "{Path(ctrl_fmu).as_posix()}"')
    text += f"\n[timing]\nstop = {stop}\n\n[instances.plant.parameters]\nfault_onset = 0.5\n"
    path = tmp_path / "own_controller.toml"
    path.write_text(text)
    return path


def reference_run(scenario, exchange):
    """The same scenario in-process, the controller being the MinimalPD block itself."""
    comps = {name: BlockComponent(name, MinimalPD() if name == "ctrl" else block_factory(inst.model_name)())
             for name, inst in scenario.instances.items()}
    for name, comp in comps.items():
        comp.setup(scenario.start, scenario.stop, scenario.instances[name].parameters, {})
    sources = [PiecewiseConstant(s.name, s.times, s.values, s.targets) for s in scenario.sources]
    return Master(comps, scenario.connections, sources, scenario.record, exchange=exchange).run(
        scenario.start, scenario.stop, scenario.step)


@pytest.mark.slow
def test_example_runs_in_li2023_fasmc_in_place_of_fasmc(example_fmu, tmp_path, fmu_dir):
    scenario = load(own_controller_scenario(tmp_path, example_fmu))
    assert scenario.instances["ctrl"].model_name == "MinimalPD"
    assert scenario.instances["plant"].model_name == "FlexibleSpacecraft" and scenario.instances["est"].model_name == "FAFEO"
    result = run_scenario(scenario)
    assert result.complete, result.error
    ref = reference_run(scenario, "ordered")
    assert ref.columns == result.columns and np.array_equal(ref.data, result.data)  # the FMU is the block, bit for bit
    # the command is the documented law of the recorded signals (ordered exchange: same t)
    q, w, f = result.vector("plant.q"), result.vector("plant.omega"), result.vector("est.f_hat")
    q_d = np.tile(scenario.sources[0].values[0], (len(q), 1))
    cmd, q_ev = pd_law(q, w, q_d, f)
    assert np.abs(result.vector("ctrl.u") - cmd).max() <= 1e-13
    assert np.abs(result.vector("ctrl.q_e")[:, 1:] - q_ev).max() <= 1e-15
    assert np.abs(f).max() > 1e-3  # the fault estimate really is fed forward
    # physics: the PD nulls the initial rate (omega(0) = (0.02, -0.03, 0.01) rad/s) within the 5 N.m limit
    rate = np.linalg.norm(w, axis=1)
    assert rate[-1] < 0.5 * rate[0] and np.abs(cmd).max() <= 5.0


@pytest.mark.slow
def test_user_package_outside_the_project_is_embedded(tmp_path):
    """A package in a user's folder (not the project, not installed), with a submodule of its own:
    the FMU carries it and runs in a fresh Python that cannot import it from anywhere else."""
    pkg = tmp_path / "user" / "mylaws"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text('"""A user\'s package."""\n')
    (pkg / "gains.py").write_text("K = 3.5\n")
    (pkg / "law.py").write_text(
        "import numpy as np\nfrom plant.block import Block, Variable\nfrom .gains import K\n\n\n"
        "class Gain(Block):\n    model_name = 'UserGain'\n\n    def __init__(self):\n"
        "        super().__init__([Variable('x', 'rad/s')], [Variable('y', 'N.m')], [Variable('k', 'N.m.s', '', K)], {'y': ['x']})\n\n"
        "    def initialize(self, t0):\n        self.k = self.p('k')\n\n"
        "    def outputs_at(self, t, u):\n        return np.array([self.k * u[0]])\n\n"
        "    def advance(self, t, h, u):\n        pass\n\n"
        "    def get_state(self):\n        return []\n\n"
        "    def set_state(self, s):\n        pass\n")
    built = build_block("mylaws.law:Gain", out=tmp_path / "out", paths=[tmp_path / "user"])
    assert built.path == tmp_path / "out" / "UserGain.fmu"
    assert built.embedded == ["mylaws/__init__.py", "mylaws/gains.py", "mylaws/law.py"]
    assert check_fmu(built.path) == []
    code = ("from fmpy import simulate_fmu\n"
            f"r = simulate_fmu({str(built.path)!r}, stop_time=0.02, output_interval=0.01, start_values={{'x': 2.0}}, "
            "output=['y'])\nprint(r['y'][-1])\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd="/", timeout=120)
    assert p.returncode == 0, p.stderr
    assert float(p.stdout.split()[-1]) == 7.0  # K = 3.5 from mylaws/gains.py, x = 2


def test_what_cannot_be_embedded_is_refused(tmp_path, monkeypatch):
    user, other = tmp_path / "user", tmp_path / "elsewhere"
    user.mkdir()
    other.mkdir()
    (other / "helper_xyz.py").write_text("SCALE = 1.0\n")
    (user / "uses_helper.py").write_text(
        "import helper_xyz  # noqa: F401\nfrom pd_block import MinimalPD\n\n\n"
        "class HelpedPD(MinimalPD):\n    model_name = 'HelpedPD'\n")
    monkeypatch.setenv("PYTHONPATH", str(other))  # importable, but neither installed nor a --path
    monkeypatch.syspath_prepend(str(other))
    with pytest.raises(BuildError) as e:
        build_block("uses_helper:HelpedPD", out=tmp_path, paths=[user, EXAMPLES])
    msg = str(e.value)
    assert msg.startswith("uses_helper:HelpedPD: cannot embed the block's code: ")
    assert f"module helper_xyz ({other / 'helper_xyz.py'}) is imported by the block but is neither in the project" in msg
    assert "add its folder with --path" in msg
    import sysconfig

    with pytest.raises(BuildError, match="is a folder of the Python installation"):
        build_block("pd_block:MinimalPD", out=tmp_path, paths=[EXAMPLES, sysconfig.get_paths()["purelib"]])
    assert not list(tmp_path.glob("*.fmu"))


def test_cli_refuses_a_broken_block_in_one_line(tmp_path, capsys, monkeypatch):
    (tmp_path / "broken_block.py").write_text(
        "from pd_block import MinimalPD\n\n\nclass Leaky(MinimalPD):\n    model_name = 'Leaky'\n\n"
        "    def __init__(self):\n        super().__init__()\n        self.feedthrough = {}\n")
    monkeypatch.syspath_prepend(str(EXAMPLES))
    rc = main(["build", "--block", "broken_block:Leaky", "--path", str(tmp_path), "--out", str(tmp_path / "x.fmu")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    assert err[0].startswith("ftcsim: error: command line: --block: broken_block:Leaky breaks the block contract"), err
    assert "undeclared feedthrough" in err[0] and "u[1] <- q[0], q[1], q[2], q[3] and 6 more" in err[0], err
    assert not (tmp_path / "x.fmu").exists()


@pytest.mark.slow
def test_two_versions_of_a_block_share_a_process_each_with_its_own_code(tmp_path, monkeypatch):
    """A second version of pd_block (k_p 21 instead of 20), built in a fresh process: it runs here,
    where the documented pd_block is imported, with its own code (issue 20: it used to run the
    imported one, or be refused); building it here is refused (the checks would use the imported
    module)."""
    from fmpy import read_model_description

    from orchestrator.cosim.fmu import fmu_component

    (tmp_path / "pd_block.py").write_text((EXAMPLES / "pd_block.py").read_text().replace(
        'scalar("k_p", 20.0', 'scalar("k_p", 21.0'))
    p = subprocess.run([sys.executable, "-m", "orchestrator.cli", "build", "--block", "pd_block:MinimalPD", "--out",
                        str(tmp_path / "v2.fmu")], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert p.returncode == 0, p.stderr
    monkeypatch.syspath_prepend(str(EXAMPLES))
    import pd_block

    assert pd_block.__file__ == str(EXAMPLES / "pd_block.py")
    assert pd_block.MinimalPD().param_values.tolist()[0] == 20.0  # this process has the documented version
    comp = fmu_component("ctrl", tmp_path / "v2.fmu", read_model_description(str(tmp_path / "v2.fmu")))
    try:
        comp.setup(0.0, 1.0, {}, {})
        assert comp.read_values(["k_p"]) == [21.0]  # the FMU's default: its own code
    finally:
        comp.terminate()
    with pytest.raises(BuildError, match=f"module pd_block is imported in this process from {EXAMPLES / 'pd_block.py'}, "
                                         f"but the FMU would embed {tmp_path / 'pd_block.py'}"):
        build_block("pd_block:MinimalPD", out=tmp_path / "v3.fmu", paths=[tmp_path])
