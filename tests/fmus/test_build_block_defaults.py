"""`ftcsim build --block` (issue 32 item 5): a value the factory sets on the block instance becomes the
FMU's start value, or the build refuses it in one line naming it; never silently dropped (the trap:
the FMU applied the class's declared start values over what its factory had set, and ran with J = I,
omega(0) = 0)."""
import sys
import textwrap

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from fmus.build import BuildError, start_values
from orchestrator.cli.main import main

pytestmark = pytest.mark.fmu

USER = textwrap.dedent('''
    import numpy as np
    from plant.block import Block, matrix, vector


    class Spinner(Block):
        """Torque-free rate of a rigid body (Euler's equation), explicit Euler steps: a user's block."""
        model_name = "Spinner"

        def __init__(self):
            super().__init__(vector("tau", 3, "N.m", "torque"), vector("omega", 3, "rad/s", "rate"),
                             matrix("J", np.eye(3), "kg.m2", "inertia") + vector("omega_init", 3, "rad/s", "initial rate"))
            self.w = np.zeros(3)

        def initialize(self, t0):
            self.Jm = self.p_matrix("J")
            self.w = self.p_vector("omega_init")

        def outputs_at(self, t, u):
            return self.w.copy()

        def advance(self, t, h, u):
            self.w = self.w + h * np.linalg.solve(self.Jm, u[:3] - np.cross(self.w, self.Jm @ self.w))

        def get_state(self):
            return self.w.tolist()

        def set_state(self, s):
            self.w = np.array(s, dtype=float)


    def configured():
        """Values set on the instance: they must be the FMU's start values."""
        b = Spinner()
        b.set_parameter("omega_init[1]", 0.3)
        b.set_parameters({"J[1,1]": 12.0, "J[2,2]": 15.0, "J[3,3]": 20.0})
        return b


    def shadowed():
        """A value set as an attribute named after a parameter: no FMU variable carries it."""
        b = Spinner()
        b.omega_init = [0.3, 0.0, 0.0]
        return b
''')


@pytest.fixture
def user(tmp_path, monkeypatch):
    (tmp_path / "userblocks.py").write_text(USER)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.chdir(tmp_path)
    sys.modules.pop("userblocks", None)  # each test's own copy (the build refuses a module imported from elsewhere)
    yield tmp_path
    sys.modules.pop("userblocks", None)


def test_instance_values_are_the_start_values(user):
    import userblocks

    starts = start_values(userblocks.configured())
    assert starts["omega_init[1]"] == "0.3" and starts["J[2,2]"] == "15.0" and starts["omega_init[2]"] == "0.0"
    assert start_values(userblocks.Spinner())["J[1,1]"] == "1.0"  # the class's own declaration otherwise


@pytest.mark.slow
def test_a_value_set_by_the_factory_reaches_the_built_fmu(user, capsys):
    assert main(["build", "--block", "userblocks:configured", "--path", str(user), "--out", str(user / "Spinner.fmu")]) == 0
    md = read_model_description(str(user / "Spinner.fmu"))
    start = {v.name: float(v.start) for v in md.modelVariables if v.start is not None}
    assert start["omega_init[1]"] == 0.3 and start["J[3,3]"] == 20.0
    r = simulate_fmu(str(user / "Spinner.fmu"), stop_time=0.02, output_interval=0.01)
    assert r["omega[1]"][0] == 0.3  # the FMU runs with the factory's value (it ran with omega(0) = 0 before)


def test_an_attribute_named_after_a_parameter_is_refused_in_one_line(user, capsys):
    import userblocks

    with pytest.raises(BuildError, match=r"omega_init = \[0.3 0. 0. \] is set as an attribute.*omega_init = \[0. 0. 0.\]"):
        start_values(userblocks.shadowed(), "userblocks:shadowed")
    assert main(["build", "--block", "userblocks:shadowed", "--path", str(user), "--out", str(user / "X.fmu")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--block" in err[0] and "omega_init" in err[0] and "set_parameter('omega_init[1]'" in err[0]
    assert not (user / "X.fmu").exists()


def test_shipped_blocks_keep_their_declared_start_values():
    """Every shipped factory sets its values through set_defaults: the instance's values are the
    declared ones, so the shipped FMUs' modelDescriptions do not change."""
    from papers.paper import resolve
    from papers.registry import fmu_specs

    for model, spec in fmu_specs().items():
        b = resolve(spec.factory)()
        starts = start_values(b, spec.factory)
        declared = {v.name: repr(float(v.start)) for v in b.inputs + b.parameters}
        assert starts == declared, model
        assert np.all(np.isfinite([float(x) for x in starts.values()]))
