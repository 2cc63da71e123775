"""A block written only to the documented protocol (plant/block.py: BlockProtocol), not derived from
plant.block.Block, builds into a working FMU and runs in-process; a block that lacks any member of
the protocol is refused by the contract check with a message naming that member, before any build."""
import importlib
import textwrap

import pytest

from fmus.build import build_block
from fmus.contract import ContractError, check_block
from orchestrator.cosim.block import BlockComponent
from plant.block import BlockProtocol

SOURCE = textwrap.dedent('''
    """A leaky integrator with a gain, written to plant.block.BlockProtocol only (no base class)."""
    import numpy as np

    from plant.naming import Variable


    class LeakyGain:
        model_name = "ProtocolOnlyLeakyGain"
        description = "x' = u - a x, y = k x + u"
        announced_instants = ()

        def __init__(self):
            self.inputs = [Variable("u", "1", "input")]
            self.outputs = [Variable("y", "1", "output")]
            self.parameters = [Variable("k", "1", "gain", 2.0), Variable("a", "1/s", "leak rate", 0.5)]
            self.param_values = np.array([v.start for v in self.parameters])
            self.feedthrough = {"y": ("u",)}
            self.x = 0.0

        def set_parameter(self, name, value):
            self.param_values[[v.name for v in self.parameters].index(name)] = float(value)

        def initialize(self, t0):
            self.k, self.a = (float(v) for v in self.param_values)
            self.x = 0.0

        def default_inputs(self):
            return np.zeros(1)

        def outputs_at(self, t, u):
            return np.array([self.k * self.x + u[0]])

        def advance(self, t, h, u):
            self.x = self.x + h * (u[0] - self.a * self.x)  # one explicit Euler step

        def get_state(self):
            return [self.x]

        def set_state(self, state):
            self.x = float(state[0])
''')
MEMBERS = sorted(set(BlockProtocol.__annotations__) | {n for n, f in vars(BlockProtocol).items()
                                                         if callable(f) and not n.startswith("_")})


@pytest.fixture
def module(tmp_path, monkeypatch):
    folder = tmp_path / "user"
    folder.mkdir()
    (folder / "protocol_only.py").write_text(SOURCE)
    monkeypatch.syspath_prepend(str(folder))
    return folder, importlib.import_module("protocol_only")


def _expected(u, h, n, k=2.0, a=0.5):
    x, ys = 0.0, []
    for _ in range(n):
        ys.append(k * x + u)
        x = x + h * (u - a * x)
    return ys


@pytest.mark.fmu
def test_a_block_written_to_the_protocol_builds_into_a_working_fmu(module, tmp_path):
    from fmu_driver import Driver

    folder, mod = module
    assert isinstance(mod.LeakyGain(), BlockProtocol)
    built = build_block("protocol_only:LeakyGain", out=tmp_path / "out", paths=[folder])
    fmu = Driver(built.path, "g")
    try:
        fmu.initialize({"k": 3.0})
        ys = []
        for i in range(5):
            fmu.set({"u": 1.0})
            ys.append(fmu.get(["y"])[0])
            fmu.step(i * 0.1, 0.1)
    finally:
        fmu.free()
    assert ys == _expected(1.0, 0.1, 5, k=3.0)  # the block's own arithmetic, bit for bit
    # and in-process, through the component the master uses
    c = BlockComponent("g", mod.LeakyGain())
    c.setup(0.0, 1.0, {"k": 3.0}, {"u": 1.0})
    assert c.read_values(["k", "a"]) == [3.0, 0.5]


@pytest.mark.parametrize("member", MEMBERS)
def test_a_block_missing_a_protocol_member_is_refused_naming_it(module, member):
    _, mod = module
    base = mod.LeakyGain
    namespace = {k: v for k, v in vars(base).items() if k != member and not k.startswith("__")}
    cls = type("Lacking", (), {**namespace, "__init__": lambda self: base.__init__(self)})

    def lacking():
        b = cls()
        b.__dict__.pop(member, None)
        return b

    with pytest.raises(ContractError) as e:
        check_block(lacking, f"protocol_only:Lacking_{member}")
    assert f"missing members of the block protocol: {member} " in str(e.value), str(e.value)


def test_the_shipped_blocks_keep_the_whole_protocol():
    from papers.registry import block_factory, fmu_specs

    for model in fmu_specs():
        b = block_factory(model)()
        assert isinstance(b, BlockProtocol), model
        assert len(b.param_values) == len(b.parameters)
        assert all(v.unit == "s" for v in b.outputs if v.name in b.announced_instants), model
