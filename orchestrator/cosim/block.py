"""The in-process component: a block run without FMI, through the same
:class:`plant.block.BlockSession` as the FMU adapters (``fmus/block_runtime.py``): the reference
path an FMU run is compared against, bit for bit."""
from __future__ import annotations

import numpy as np

from orchestrator.cosim.component import ComponentError, Subsets, VarInfo, as_slice
from plant.session import BlockSession, input_affects, input_positions


class BlockComponent(Subsets):
    """The same block run in-process, without FMI: the reference path. It drives the block
    through the same :class:`plant.session.BlockSession` as the FMU adapters, and reads nothing
    of the block beyond :class:`plant.block.BlockProtocol`."""

    def __init__(self, name: str, block):
        super().__init__()
        self.name = name
        self.block = block
        self.model_name = block.model_name
        self.origin = f"in-process {self.model_name}"
        vr = 0
        self.variables = {}
        for causality, group in (("input", block.inputs), ("output", block.outputs), ("parameter", block.parameters)):
            for v in group:
                self.variables[v.name] = VarInfo(vr, causality, v.unit, v.start)
                vr += 1
        self.feedthrough = {v.name: set(block.feedthrough.get(v.name, ())) for v in block.outputs}
        self._input_index = {v.name: i for i, v in enumerate(block.inputs)}
        self._output_index = {v.name: i for i, v in enumerate(block.outputs)}
        self._parameter_index = {v.name: i for i, v in enumerate(block.parameters)}
        self.t = 0.0
        self.session = None
        self.can_roll_back = self.variable_step = True

    def _fail(self, function, t, e):
        return ComponentError(self.name, function, t, 3, f"{type(e).__name__}: {e}", self.origin)

    def setup(self, t0, t1, params: dict, inputs: dict):
        try:
            for name, value in params.items():
                self.block.set_parameter(name, value)
            self.block.initialize(t0)
        except Exception as e:
            raise self._fail("initialize", t0, e) from None
        self.session = BlockSession(self.block)
        self.session.t = self.t = t0
        for n, x in inputs.items():
            self.session.set_input(self._input_index[n], x)

    def bind(self, out_names, out_buf, in_names, in_buf):
        self._out_pos = np.array([self._output_index[n] for n in out_names], dtype=np.intp)
        self._in_pos = np.array([self._input_index[n] for n in in_names], dtype=np.intp)
        self._out_buf, self._in_buf = out_buf, in_buf

    def prepare(self):
        # consecutive positions become slices (a view copy instead of fancy indexing); the input
        # subsets carry, computed once, whether an output depends on them (BlockSession)
        self._out_calls = [(as_slice(p), as_slice(self._out_pos[p]), p.size) for p in self.out_subsets]
        affects = input_affects(self.block)
        self._in_calls = [(as_slice(p), input_positions(self._in_pos[p], affects), p.size) for p in self.in_subsets]

    def read_some(self, k: int):
        pos, src, n = self._out_calls[k]
        if n == 0:
            return
        try:
            y = self.session.outputs()
        except Exception as e:
            raise self._fail("outputs_at", self.t, e) from None
        self._out_buf[pos] = y[src]

    def write_some(self, k: int):
        pos, dst, n = self._in_calls[k]
        if n == 0:
            return
        self.session.set_inputs(dst, self._in_buf[pos])

    def step(self, t: float, h: float):
        try:
            self.session.advance(t, h)
        except Exception as e:
            raise self._fail("advance", t, e) from None
        self.t = t + h

    def read_values(self, names) -> list[float]:
        """The values the block holds for the parameters ``names``."""
        return [float(self.block.param_values[self._parameter_index[n]]) for n in names]

    def get_state(self):
        return self.session.get_state()

    def set_state(self, state):
        try:
            self.session.set_state(state)
        except Exception as e:
            raise self._fail("set_state", self.t, e) from None
        self.t = self.session.t

    def free_state(self, state):
        pass

    def terminate(self):
        pass
