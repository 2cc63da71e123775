"""A block driven with held inputs and lazily evaluated outputs: :class:`BlockSession`, used by the FMI
adapters (``fmus/block_runtime.py``) and by the in-process component of the orchestrator
(``orchestrator/cosim/block.py``) alike, which is why an FMU run and an in-process run agree bit for bit.
It reads a block only through :class:`plant.block.BlockProtocol`."""
from __future__ import annotations

import numpy as np


def input_affects(block) -> np.ndarray:
    """For each input of ``block``, whether some output depends on it directly (``feedthrough``)."""
    feeds = set().union(*block.feedthrough.values()) if block.feedthrough else set()
    return np.array([v.name in feeds for v in block.inputs], dtype=bool)


def input_positions(positions, affects) -> tuple:
    """Input indices prepared once for :meth:`BlockSession.set_inputs`: (a slice when they are
    consecutive, else the index array; whether any output depends on them, from ``affects``)."""
    pos = np.asarray(positions, dtype=np.intp)
    hit = bool(affects[pos].any()) if pos.size else False
    if pos.size and np.array_equal(pos, np.arange(pos[0], pos[0] + pos.size)):
        return slice(int(pos[0]), int(pos[0]) + pos.size), hit
    return pos, hit


class BlockSession:
    """A block driven with held inputs and lazily evaluated outputs (FMU and in-process alike).

    Outputs are evaluated only when read and only if something they depend on changed: a
    step or a state change invalidates all of them; setting an input invalidates them only if
    some output depends on that input (``feedthrough``), and then the block's optional
    ``feedthrough_outputs`` updates just those. So each output is evaluated once per exchange
    however many times, and in whatever groups, the master reads it."""

    def __init__(self, block):
        self.block = block
        self.t = 0.0
        self.u = block.default_inputs()
        self.y = np.zeros(len(block.outputs))
        self.affects = input_affects(block)
        self._partial = getattr(block, "feedthrough_outputs", None)
        self._state_dirty = True  # everything must be evaluated
        self._input_dirty = False  # only outputs with feedthrough must be

    def invalidate(self) -> None:
        self._state_dirty = True

    def set_input(self, i: int, x: float) -> None:
        self.u[i] = x
        if self.affects[i]:
            self._input_dirty = True

    def input_positions(self, positions) -> tuple:
        """``positions`` prepared for :meth:`set_inputs` (:func:`input_positions`)."""
        return input_positions(positions, self.affects)

    def set_inputs(self, positions, values) -> None:
        """Set several inputs: ``positions`` an index array, or what :meth:`input_positions` returned."""
        if isinstance(positions, tuple):
            positions, affects = positions
        else:
            affects = self.affects[positions].any()
        self.u[positions] = values
        if affects:
            self._input_dirty = True

    def outputs(self) -> np.ndarray:
        if self._state_dirty:
            self.y = self.block.outputs_at(self.t, self.u)
        elif self._input_dirty:
            self.y = (self._partial(self.t, self.u, self.y) if self._partial is not None
                      else self.block.outputs_at(self.t, self.u))
        self._state_dirty = self._input_dirty = False
        return self.y

    def advance(self, t: float, h: float) -> None:
        self.block.advance(t, h, self.u)
        self.t = t + h
        self._state_dirty = True

    def get_state(self) -> dict:
        return {"t": self.t, "u": self.u.tolist(), "x": list(self.block.get_state())}

    def set_state(self, state: dict) -> None:
        self.t = float(state["t"])
        self.u = np.array(state["u"], dtype=float)
        self.block.set_state(state["x"])
        self._state_dirty = True
