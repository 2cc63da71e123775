"""The block contract shared by every model (plant, estimator, controller).

A block is a plain Python object that knows nothing about FMI. :class:`BlockProtocol` lists every
member a runtime reads (the FMI adapters of ``fmus/block_runtime.py``, the in-process component
``orchestrator/cosim/block.py``, :class:`plant.session.BlockSession`); ``fmus/contract.py`` refuses a
block that lacks one, naming it. :class:`Block` implements the parameter storage; a model subclasses it.

* ``model_name``, ``description``: the FMU's model name (a plain identifier) and what it is;
* ``inputs``, ``outputs``, ``parameters``: lists of :class:`~plant.naming.Variable` with structured
  FMI names (``omega[1]``, ``J[1,2]``, ``K[r,i,j]``), SI units and descriptions; a paper's numbers
  reach the parameters through :meth:`Block.set_defaults`;
* ``param_values``: a float64 numpy array of the parameter values in declared order (what the FMU
  state saves and restores, what a parameter variable reads);
* ``feedthrough``: for every output, the inputs it depends on directly (within one
  communication step). Outputs not listed depend on no input. It must be exact: the FMU's
  ``dependencies``, the master's exchange order and the lazy output evaluation rely on it;
* ``announced_instants``: the outputs (unit s) that announce the next instant at which the block
  must be stepped to (a sample instant, a mode jump); each always holds a time after the current
  one. Empty for most blocks. A scenario names them in ``[instances.NAME] announces`` and the
  multirate and adaptive step policies land on them (``orchestrator/cosim/policies.py``);
* ``set_parameter(name, value)``: one scalar parameter by its structured name (before ``initialize``);
* ``initialize(t0)``: read and check the parameters (``ValueError`` naming the parameter),
  set the initial state;
* ``default_inputs()``: the input vector before anything is connected (the inputs' start values);
* ``outputs_at(t, u)``: what the block emits at time ``t`` for the input vector ``u`` (inputs
  in declared order), as a float array in declared output order. It never changes the
  block's state: calling it any number of times, or not at all, changes nothing;
* ``advance(t, h, u)``: move the state from ``t`` to ``t + h`` with ``u`` held (zero-order
  hold). Step-like signals inside the step follow ``plant/timing.py``;
* ``get_state()`` / ``set_state(state)``: every internal state as a flat list of floats, so
  that rollback restores the block bit for bit.

Optional: ``feedthrough_outputs(t, u, y)``: ``y`` from ``outputs_at`` at the same ``t`` and state
with only the outputs that depend on inputs recomputed for the new ``u`` (a plant whose state
outputs need not be evaluated again when its command changes).

``plant`` holds the contract because it is the base package (numpy only) that ``estimator`` and
``controller`` depend on. The names of ``plant/naming.py`` (``Variable``, ``vector``, ``scalar``, ...)
and ``plant/session.py`` (``BlockSession``) can still be imported from here.
"""
from __future__ import annotations

import math
from typing import Protocol, runtime_checkable

import numpy as np

from plant.naming import (  # noqa: F401 (the names model modules import from here)
    Variable,
    matrix,
    rule_tensor,
    scalar,
    split_name,
    structured_values,
    vector,
)
from plant.session import BlockSession, input_affects, input_positions  # noqa: F401 (the same)


@runtime_checkable
class BlockProtocol(Protocol):
    """Every member a runtime reads of a block (see the module docstring); ``fmus/contract.py``
    checks a block against this list."""

    model_name: str
    description: str
    inputs: list
    outputs: list
    parameters: list
    param_values: np.ndarray
    feedthrough: dict
    announced_instants: tuple

    def set_parameter(self, name: str, value: float) -> None: ...
    def initialize(self, t0: float) -> None: ...
    def default_inputs(self) -> np.ndarray: ...
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray: ...
    def advance(self, t: float, h: float, u: np.ndarray) -> None: ...
    def get_state(self) -> list: ...
    def set_state(self, state: list) -> None: ...


class Block:
    """Base class implementing parameter storage; subclasses implement the dynamics."""

    model_name = "Block"
    description = ""
    announced_instants: tuple = ()  # outputs announcing the next instant to step to (module docstring)

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

    def _by_base(self) -> dict:
        """base name -> [(position, indices, indexed)] of the parameters, split once per block (a block
        of 5000 structured names read its arrays in 55 ms, splitting every name for every array)."""
        cache = getattr(self, "_base_index", None)
        if cache is None or cache[0] != len(self.parameters):
            groups: dict = {}
            for k, v in enumerate(self.parameters):
                b, ix = split_name(v.name)
                groups.setdefault(b, []).append((k, ix, "[" in v.name))
            cache = self._base_index = (len(self.parameters), groups)
        return cache[1]

    def p_array(self, base: str) -> np.ndarray:
        """Parameters ``base[i]``, ``base[i,j]``, ``base[r,i,j]``... as an array (1-based names)."""
        entries = [(ix, self.param_values[k]) for k, ix, indexed in self._by_base().get(base, ()) if indexed]
        if not entries:
            raise KeyError(f"{self.model_name} has no parameter array '{base}'")
        shape = tuple(max(ix[d] for ix, _ in entries) for d in range(len(entries[0][0])))
        a = np.zeros(shape)
        for ix, x in entries:
            a[tuple(i - 1 for i in ix)] = x
        return a

    def p_vector(self, base: str) -> np.ndarray:
        """Parameters ``base[i]`` in index order, as a 1-D array (0- or 1-based names)."""
        items = sorted((ix, self.param_values[k]) for k, ix, _ in self._by_base().get(base, ()))
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
