"""The block contract shared by every model (plant, estimator, controller).

A block is a plain Python object that knows nothing about FMI (:class:`BlockProtocol` states it):

* ``inputs``, ``outputs``, ``parameters``: lists of :class:`Variable` with structured FMI names
  (``omega[1]``, ``J[1,2]``, ``K[r,i,j]``), SI units and descriptions; a paper's numbers reach
  the parameters through :meth:`Block.set_defaults`;
* ``feedthrough``: for every output, the inputs it depends on directly (within one
  communication step). Outputs not listed depend on no input. It must be exact: the FMU's
  ``dependencies``, the master's exchange order and the lazy output evaluation rely on it;
* ``initialize(t0)``: read and check the parameters (``ValueError`` naming the parameter),
  set the initial state;
* ``outputs_at(t, u)``: what the block emits at time ``t`` for the input vector ``u`` (inputs
  in declared order), as a float array in declared output order. It never changes the
  block's state: calling it any number of times, or not at all, changes nothing;
* ``feedthrough_outputs(t, u, y)`` (optional): ``y`` from ``outputs_at`` at the same ``t`` and
  state with only the outputs that depend on inputs recomputed for the new ``u`` (a plant
  whose state outputs need not be evaluated again when its command changes);
* ``advance(t, h, u)``: move the state from ``t`` to ``t + h`` with ``u`` held (zero-order
  hold). Step-like signals inside the step follow ``plant/timing.py``;
* ``get_state()`` / ``set_state(state)``: every internal state as a flat list of floats, so
  that rollback restores the block bit for bit.

:class:`BlockSession` drives a block with held inputs and lazily evaluated outputs; the FMI
adapters (``fmus/block_runtime.py``) and the in-process path of the orchestrator both use it,
which is why an FMU run and an in-process run agree bit for bit. ``plant`` holds the contract
because it is the base package (numpy only) that ``estimator`` and ``controller`` depend on.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

_INDEXED = re.compile(r"^(?P<base>[A-Za-z_][A-Za-z0-9_]*)\[(?P<idx>[0-9]+(?:,[0-9]+)*)\]$")


@runtime_checkable
class BlockProtocol(Protocol):
    """What the FMI adapters and the in-process components require of a block."""

    model_name: str
    description: str
    inputs: list
    outputs: list
    parameters: list
    feedthrough: dict

    def set_parameter(self, name: str, value: float) -> None: ...
    def initialize(self, t0: float) -> None: ...
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray: ...
    def advance(self, t: float, h: float, u: np.ndarray) -> None: ...
    def get_state(self) -> list: ...
    def set_state(self, state: list) -> None: ...
    def default_inputs(self) -> np.ndarray: ...


@dataclass(frozen=True)
class Variable:
    """One scalar of a block's interface. ``unit`` is an SI unit string ("1" if none)."""

    name: str
    unit: str = "1"
    description: str = ""
    start: float = 0.0


def split_name(name: str) -> tuple[str, tuple[int, ...]]:
    """``'J[1,2]'`` -> ``('J', (1, 2))``; ``'k_p'`` -> ``('k_p', ())``."""
    m = _INDEXED.match(name)
    if not m:
        return name, ()
    return m["base"], tuple(int(i) for i in m["idx"].split(","))


def vector(base: str, n: int, unit: str = "1", description: str = "", start=None, first: int = 1):
    """Variables ``base[first] .. base[first+n-1]`` with optional start values."""
    starts = [0.0] * n if start is None else [float(v) for v in np.ravel(start)]
    if len(starts) != n:
        raise ValueError(f"{base}: {len(starts)} start values for {n} elements")
    return [Variable(f"{base}[{first + i}]", unit, description, starts[i]) for i in range(n)]


def matrix(base: str, values, unit: str = "1", description: str = ""):
    """Variables ``base[i,j]`` (1-based) holding the entries of a 2-D array."""
    a = np.atleast_2d(np.asarray(values, dtype=float))
    return [
        Variable(f"{base}[{i + 1},{j + 1}]", unit, description, float(a[i, j]))
        for i in range(a.shape[0])
        for j in range(a.shape[1])
    ]


def rule_tensor(base: str, values, unit: str = "1", description: str = ""):
    """Variables ``base[r,i,j]`` (1-based; r = rule) for an (r, m, k) array of rule matrices."""
    a = np.asarray(values, dtype=float)
    return [
        Variable(f"{base}[{r + 1},{i + 1},{j + 1}]", unit, description, float(a[r, i, j]))
        for r in range(a.shape[0])
        for i in range(a.shape[1])
        for j in range(a.shape[2])
    ]


def scalar(name: str, value: float, unit: str = "1", description: str = ""):
    return [Variable(name, unit, description, float(value))]


def structured_values(base: str, value) -> dict:
    """``{'J[1,1]': .., 'J[1,2]': ..}`` for an array (1-based indices; a scalar gives ``{base: x}``).
    The one place that turns arrays into structured FMI names (parameter sets, gain files)."""
    a = np.asarray(value, dtype=float)
    if a.ndim == 0:
        return {base: float(a)}
    return {f"{base}[{','.join(str(i + 1) for i in idx)}]": float(a[idx]) for idx in np.ndindex(*a.shape)}


class Block:
    """Base class implementing parameter storage; subclasses implement the dynamics."""

    model_name = "Block"
    description = ""

    def __init__(self, inputs, outputs, parameters, feedthrough=None):
        self.inputs: list[Variable] = list(inputs)
        self.outputs: list[Variable] = list(outputs)
        self.parameters: list[Variable] = list(parameters)
        self.feedthrough: dict[str, tuple[str, ...]] = {
            k: tuple(v) for k, v in (feedthrough or {}).items()
        }
        self._param_pos = {v.name: i for i, v in enumerate(self.parameters)}
        self.param_values = np.array([v.start for v in self.parameters], dtype=float)
        self.input_index = {v.name: i for i, v in enumerate(self.inputs)}
        self.output_index = {v.name: i for i, v in enumerate(self.outputs)}
        names = [v.name for v in self.inputs + self.outputs + self.parameters]
        if len(set(names)) != len(names):
            raise ValueError(f"{self.model_name}: duplicate variable names")
        for out, ins in self.feedthrough.items():
            if out not in self.output_index or any(i not in self.input_index for i in ins):
                raise ValueError(f"{self.model_name}: feedthrough {out} <- {ins} names unknown variables")

    # -- parameters -------------------------------------------------------------
    def set_parameter(self, name: str, value: float) -> None:
        """Set one scalar parameter by its structured name (before ``initialize``)."""
        if name not in self._param_pos:
            raise KeyError(f"{self.model_name} has no parameter '{name}'")
        value = float(value)
        if not math.isfinite(value):
            raise ValueError(f"{self.model_name}: parameter '{name}' = {value} is not finite")
        self.param_values[self._param_pos[name]] = value

    def set_parameters(self, values: dict) -> None:
        for name, value in values.items():
            self.set_parameter(name, value)

    def p(self, name: str) -> float:
        """Scalar parameter value."""
        return float(self.param_values[self._param_pos[name]])

    def p_array(self, base: str) -> np.ndarray:
        """Parameters ``base[i]``, ``base[i,j]``, ``base[r,i,j]``... as an array (1-based names)."""
        entries = [
            (split_name(v.name)[1], self.param_values[k])
            for k, v in enumerate(self.parameters)
            if split_name(v.name)[0] == base and "[" in v.name
        ]
        if not entries:
            raise KeyError(f"{self.model_name} has no parameter array '{base}'")
        shape = tuple(max(ix[d] for ix, _ in entries) for d in range(len(entries[0][0])))
        a = np.zeros(shape)
        for ix, x in entries:
            a[tuple(i - 1 for i in ix)] = x
        return a

    def p_vector(self, base: str) -> np.ndarray:
        """Parameters ``base[i]`` in index order, as a 1-D array (0- or 1-based names)."""
        items = sorted(
            (split_name(v.name)[1], self.param_values[i])
            for i, v in enumerate(self.parameters)
            if split_name(v.name)[0] == base
        )
        return np.array([x for _, x in items], dtype=float)

    def p_matrix(self, base: str) -> np.ndarray:
        """Parameters ``base[i,j]`` as a 2-D array."""
        return self.p_array(base)

    def p_tensor(self, base: str) -> np.ndarray:
        """Parameters ``base[r,i,j]`` as a 3-D array (rule matrices)."""
        return self.p_array(base)

    def set_defaults(self, values: dict) -> None:
        """Replace the start values of parameters (what an FMU declares as its defaults).

        ``values`` maps a scalar name (``k_p``) or an array base name (``J``, ``K``) to a value
        of the matching shape; a paper's folder passes its parameter set and gains this way,
        so the algorithm modules stay free of any paper's numbers."""
        for base, value in values.items():
            if np.ndim(value):
                declared = [split_name(v.name)[1] for v in self.parameters if split_name(v.name)[0] == base and "[" in v.name]
                shape = tuple(max(ix[d] for ix in declared) for d in range(len(declared[0]))) if declared else None
                if shape is not None and np.shape(value) != shape:
                    raise ValueError(
                        f"{base}: default of shape {np.shape(value)} given, the block {self.model_name} declares {shape} "
                        f"(sizes follow the constructor arguments)"
                    )
            names = structured_values(base, value) if np.ndim(value) else {base: float(value)}
            for name, x in names.items():
                if name not in self._param_pos:
                    raise KeyError(f"{self.model_name} has no parameter '{name}' (from defaults '{base}')")
                k = self._param_pos[name]
                v = self.parameters[k]
                self.parameters[k] = Variable(v.name, v.unit, v.description, x)
                self.param_values[k] = x

    def parameter_values(self) -> dict:
        return {v.name: float(self.param_values[i]) for i, v in enumerate(self.parameters)}

    # -- the contract -------------------------------------------------------------
    def initialize(self, t0: float) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def advance(self, t: float, h: float, u: np.ndarray) -> None:  # pragma: no cover
        raise NotImplementedError

    def get_state(self) -> list:  # pragma: no cover
        raise NotImplementedError

    def set_state(self, state: list) -> None:  # pragma: no cover
        raise NotImplementedError

    def default_inputs(self) -> np.ndarray:
        return np.array([v.start for v in self.inputs], dtype=float)


class StatelessBlock(Block):
    """A block without state (a static law, a source that is a function of time): advancing does
    nothing and its state is the empty list."""

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        pass

    def get_state(self) -> list:
        return []

    def set_state(self, state) -> None:
        pass


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
