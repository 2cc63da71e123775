"""The block-contract checks of `ftcsim build --block` (fmus/contract.py): every shipped block passes
them, and each kind of broken block gets one clear problem naming the class. No FMU is built here."""
import numpy as np
import pytest

from fmus.contract import ContractError, check_block
from papers.registry import block_factory
from papers.registry import fmu_specs as catalog
from plant.block import Block, Variable, scalar

REF = "tests.fmus.test_block_contract:"


class Integrator(Block):
    """A correct block: y = k x (direct feedthrough), z = integral of x (state)."""

    model_name = "Integrator"

    def __init__(self, x_unit="1", k_start=2.0):
        super().__init__([Variable("x", x_unit, "input", 0.5)], [Variable("y", "1"), Variable("z", "s")],
                         scalar("k", k_start, "1", "gain"), {"y": ["x"]})

    def initialize(self, t0):
        self.k, self.z = self.p("k"), 0.0

    def outputs_at(self, t, u):
        return np.array([self.k * u[0], self.z])

    def advance(self, t, h, u):
        self.z += h * u[0]

    def get_state(self):
        return [self.z]

    def set_state(self, state):
        self.z = float(state[0])


class UndeclaredFeedthrough(Integrator):
    model_name = "UndeclaredFeedthrough"

    def __init__(self):
        super().__init__()
        self.feedthrough = {}


class HiddenState(Integrator):
    """Its get_state forgets z."""

    model_name = "HiddenState"

    def get_state(self):
        return []

    def set_state(self, state):
        pass


class CountsCalls(Integrator):
    """outputs_at counts its calls into the state."""

    model_name = "CountsCalls"

    def initialize(self, t0):
        super().initialize(t0)
        self.calls = 0.0

    def outputs_at(self, t, u):
        self.calls += 1.0
        return super().outputs_at(t, u)

    def get_state(self):
        return [self.z, self.calls]

    def set_state(self, state):
        self.z, self.calls = float(state[0]), float(state[1])


class PrimesInOutputs(Integrator):
    """outputs_at caches the input that advance then integrates (a hidden priming)."""

    model_name = "PrimesInOutputs"

    def initialize(self, t0):
        super().initialize(t0)
        self.last = 0.0

    def outputs_at(self, t, u):
        self.last = float(u[0])
        return super().outputs_at(t, u)

    def advance(self, t, h, u):
        self.z += h * self.last


class NoUnit(Integrator):
    model_name = "NoUnit"

    def __init__(self):
        super().__init__(x_unit="")


class UnknownUnit(Integrator):
    model_name = "UnknownUnit"

    def __init__(self):
        super().__init__(x_unit="Nm")


class Duplicate(Integrator):
    model_name = "Duplicate"

    def __init__(self):
        super().__init__()
        self.parameters.append(Variable("x", "1", "a parameter named like the input"))


class NonFiniteDefault(Integrator):
    model_name = "NonFiniteDefault"

    def __init__(self):
        super().__init__(k_start=float("nan"))


class NeedsArguments(Integrator):
    model_name = "NeedsArguments"

    def __init__(self, n):
        super().__init__()


class NoGetState:
    """Not a Block subclass and missing get_state / set_state."""

    model_name, description, inputs, outputs, parameters, feedthrough = "NoGetState", "", [], [], [], {}
    param_values, announced_instants = np.zeros(0), ()

    def set_parameter(self, name, value): ...
    def initialize(self, t0): ...
    def outputs_at(self, t, u): return np.zeros(0)
    def advance(self, t, h, u): ...
    def default_inputs(self): return np.zeros(0)


class BadName(Integrator):
    model_name = "my controller"


class ArrayState(Integrator):
    model_name = "ArrayState"

    def get_state(self):
        return [np.array([self.z])]


class RefusesLargeSteps(Integrator):
    """Accepts only steps of at most 1 ms (like a block built for one communication step)."""

    model_name = "RefusesLargeSteps"

    def advance(self, t, h, u):
        if h > 1e-3 * (1 + 1e-9):
            raise ValueError(f"step {h:g} s above 1 ms")
        super().advance(t, h, u)


CASES = {
    UndeclaredFeedthrough: "undeclared feedthrough: outputs change within the step when these inputs change, "
                           "but feedthrough does not declare it: y <- x",
    HiddenState: "state not restorable: after set_state(get_state())",
    CountsCalls: "outputs_at changes the state returned by get_state()",
    PrimesInOutputs: "calling outputs_at changes what the block does next",
    NoUnit: "variables without a unit: x",
    UnknownUnit: "unit 'Nm' of x is not one the build knows",
    Duplicate: "duplicate variable names: x (inputs and parameters)",
    NonFiniteDefault: "non-finite default (start) values: k = nan",
    NeedsArguments: "raised TypeError",
    NoGetState: "missing members of the block protocol: get_state, set_state",
    BadName: "model_name 'my controller' is not a plain identifier",
    ArrayState: "get_state() is not a flat list of floats",
}


@pytest.mark.parametrize("cls", list(CASES), ids=lambda c: c.__name__)
def test_broken_block_is_refused_with_its_problem(cls):
    ref = REF + cls.__name__
    with pytest.raises(ContractError) as e:
        check_block(cls, ref)
    msg = str(e.value)
    assert msg.startswith(f"{ref} breaks the block contract (plant/block.py): "), msg
    assert CASES[cls] in msg, msg
    assert len(e.value.problems) == 1, e.value.problems  # one problem, the one made on purpose


def test_a_correct_block_passes_and_a_step_limit_is_respected():
    assert check_block(Integrator, REF + "Integrator") == []
    assert check_block(RefusesLargeSteps, REF + "RefusesLargeSteps") == []  # probes at 1 ms
    with pytest.raises(ContractError, match=r"advance\(0, 0.01, u\) raised ValueError: step 0.01 s above 1 ms"):
        check_block(RefusesLargeSteps, REF + "RefusesLargeSteps", step=0.01)


def test_a_name_of_a_shipped_fmu_is_refused():
    class PDController(Integrator):
        model_name = "PDController"

    with pytest.raises(ContractError, match="model_name 'PDController' is the name of a shipped FMU"):
        check_block(PDController, "x:PDController", reserved=tuple(catalog()))


def test_over_declared_feedthrough_is_a_warning():
    class OverDeclared(Integrator):
        model_name = "OverDeclared"

        def __init__(self):
            super().__init__()
            self.feedthrough = {"y": ("x",), "z": ("x",)}  # z does not depend on x within a step

    (warning,) = check_block(OverDeclared, "x:OverDeclared")
    assert warning.startswith("z is declared to depend on x, which the probe never saw change it")


@pytest.mark.parametrize("name", sorted(n for n, s in catalog().items() if s.available()))
def test_every_shipped_block_keeps_the_contract(name):
    """No false alarm on the project's own blocks (over-declared dependences are warnings)."""
    check_block(block_factory(name), catalog()[name].factory)
