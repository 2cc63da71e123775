"""The FMI-version-independent half of the block adapters (fmus/adapter.py for FMI 2.0,
fmus/adapter3.py for FMI 3.0): one block, its inputs held between steps, lazy outputs,
fixed parameters, and an FMU state that covers everything.

* parameters are ``fixed``: read when the FMU leaves initialisation mode (or at the
  first output read during initialisation); setting one afterwards is an error;
* outputs are recomputed lazily after an input change or a step;
* the FMU state holds the inputs, the parameters, the time and every internal state of
  the block, as JSON-safe floats, so that rollback is exact (also serialised);
* the FMU starts from the start values of its own modelDescription.xml (FMI: they are the
  FMU's initial values). ``ftcsim build`` writes the block's defaults there, so nothing
  changes for a built FMU; ``ftcsim export-ssp`` writes the scenario's values into the copy it
  packs (fmus/configure.py), so a host that applies no parameter set (Ecos's plain ``init()``)
  runs the scenario;
* what a host hands in is checked here, once for every block and both FMI versions (issue 37): a
  communication step that is not a finite number > 0, a step that starts before the end of the
  previous one (time going backwards), a non-finite start time, input or parameter, an unknown value
  reference or a variable that cannot be set raise ``ValueError`` naming the block, the variable and
  the value; the export library turns it into an error status with that message
  (fmus/native/README.md). The block never sees such a value, so no block can hang on an infinite
  step or carry a NaN into its state.

It imports neither pythonfmu nor pythonfmu3, so either kind of FMU can embed it.
"""
import math
import os
import sys
from xml.etree import ElementTree

import numpy as np

from plant.session import BlockSession

# pythonfmu 0.7's native findClass() (and pythonfmu3's, which shares it) takes the slave
# module's __dict__ with the borrowed PyModule_GetDict() and then Py_DECREFs it: every
# instantiation drops one reference the module owns. The dict may own a single reference,
# so it would be freed during the very first instantiation and the next one fails
# ("[ctor] findClass ... bad argument to internal function") or crashes. We hold one
# reference when the slave class is defined (a cushion) and give one back with each
# instance constructed, which balances the books.
_MODULE_DICT_REFS = []


def hold_module_dict(cls) -> None:
    module = sys.modules.get(cls.__module__)
    if module is not None:
        _MODULE_DICT_REFS.append(module.__dict__)


_STARTS: dict = {}  # (modelDescription path, mtime, size) -> {variable name: start value}


def model_description_starts(resources) -> dict:
    """Variable name -> start value (float) of the Real / Float64 variables of the modelDescription
    next to ``resources`` (the FMU's resources folder), read once per file; {} without one."""
    if not resources:
        return {}
    path = os.path.join(os.path.dirname(os.path.abspath(resources)), "modelDescription.xml")
    try:
        st = os.stat(path)
    except OSError:
        return {}
    key = (path, st.st_mtime_ns, st.st_size)
    starts = _STARTS.get(key)
    if starts is None:
        starts = {}
        variables = ElementTree.parse(path).getroot().find("ModelVariables")
        for v in variables if variables is not None else ():
            holder = v.find("Real") if v.tag == "ScalarVariable" else v if v.tag == "Float64" else None
            if holder is not None and holder.get("start") is not None:
                starts[v.get("name")] = float(holder.get("start"))
        _STARTS[key] = starts
    return starts


class BlockRuntime:
    """Mixin for a pythonfmu(3) slave class; subclasses set ``block_factory``.

    The block is driven through :class:`plant.block.BlockSession` (held inputs, lazy outputs),
    the same object the in-process components use."""

    block_factory = None
    author = "ftcsim"

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        hold_module_dict(cls)

    def _init_block(self):
        hold_module_dict(type(self))
        block = self.block = type(self).block_factory()
        self.modelName = block.model_name
        self.description = block.description
        self.session = BlockSession(block)
        self._t0 = 0.0
        self._stale_params = True
        self._running = False
        self._n_in = len(block.inputs)
        self._n_out = len(block.outputs)
        self._get_plans, self._set_plans = {}, {}  # value-reference request -> index array (_get/_set_values)
        self._apply_model_description_starts()
        return block

    def _apply_model_description_starts(self):
        """Parameters and inputs whose start value in the FMU's modelDescription differs from the
        block's default take the modelDescription's (see the module docstring)."""
        starts = model_description_starts(getattr(self, "resources", None))
        if not starts:
            return
        block, session = self.block, self.session
        for i, v in enumerate(block.parameters):
            x = starts.get(v.name)
            if x is not None and x != float(block.param_values[i]):
                block.set_parameter(v.name, x)
        for i, v in enumerate(block.inputs):
            x = starts.get(v.name)
            if x is not None and x != float(session.u[i]):
                session.set_input(i, x)

    def _register_block_variables(self, variable, causality, variability, initial) -> None:
        """Register inputs, outputs, parameters (in that order) as pythonfmu(3) variables of
        class ``variable`` (``Real`` / ``Float64``) with that FMI version's enumerations:
        parameters ``fixed``/``exact``, inputs and outputs ``continuous``."""
        block, session = self.block, self.session

        def make(kind, v, getter, setter):
            extra = (dict(variability=variability.fixed, initial=initial.exact) if kind == "parameter"
                     else dict(variability=variability.continuous))
            return variable(v.name, causality=getattr(causality, kind), description=v.description,
                            getter=getter, setter=setter, **extra)

        for i, v in enumerate(block.inputs):
            self.register_variable(make("input", v, lambda i=i: float(session.u[i]),
                                        lambda x, i=i: session.set_input(i, x)))
        for i, v in enumerate(block.outputs):
            self.register_variable(make("output", v, lambda i=i: float(self._outputs()[i]), None))
        for i, v in enumerate(block.parameters):
            self.register_variable(make("parameter", v, lambda i=i: float(self.block.param_values[i]),
                                        lambda x, name=v.name: self._set_parameter(name, x)))

    # -- variable access ---------------------------------------------------------------
    def _set_parameter(self, name, x):
        if self._running:
            raise RuntimeError(f"parameter {name} is fixed after initialisation")
        self.block.set_parameter(name, x)
        self._stale_params = True

    def _ensure_initialized(self):
        if self._stale_params:
            self.block.initialize(self._t0)
            self._stale_params = False
            self.session.invalidate()

    def _outputs(self):
        self._ensure_initialized()
        return self.session.outputs()

    def _variable(self, vr):
        """The registered variable of value reference ``vr``; ValueError for an unknown one."""
        var = self.vars.get(vr) if isinstance(vr, int) else None
        if var is None:
            raise ValueError(f"{self.block.model_name}: unknown value reference {vr!r} (this FMU has "
                             f"{min(self.vars)}..{max(self.vars)})")
        return var

    def _check_values(self, vrs, values):
        """Every value a host sets must be a finite number (inputs and parameters alike)."""
        if all(map(math.isfinite, values)):
            return
        for vr, x in zip(vrs, values):
            if not math.isfinite(x):
                name = self.vars[vr].name if vr in self.vars else f"value reference {vr}"
                raise ValueError(f"{self.block.model_name}: {name} = {x!r} is not a finite number "
                                 f"(at t = {self.session.t!r} s)")

    def _get_values(self, vrs, first_input: int):
        """Values for value references; inputs start at ``first_input``, outputs follow.
        A request for outputs only (what a master asks every step) is one indexed copy, its
        index array computed once per distinct request."""
        key = tuple(vrs)
        idx = self._get_plans.get(key)
        if idx is None:
            lo = first_input + self._n_in
            hi = lo + self._n_out
            if key and all(lo <= vr < hi for vr in key):
                idx = self._get_plans[key] = np.array([vr - lo for vr in key], dtype=np.intp)
            else:
                getters = [None if lo <= vr < hi else self._variable(vr).getter for vr in vrs]
                y = self._outputs() if any(g is None for g in getters) else None
                return [float(y[vr - lo]) if g is None else float(g()) for vr, g in zip(vrs, getters)]
        return self._outputs()[idx].tolist()

    def _set_values(self, vrs, values, first_input: int):
        self._check_values(vrs, values)
        session = self.session
        key = tuple(vrs)
        pos = self._set_plans.get(key)
        if pos is None:
            n_in = self._n_in
            if key and all(first_input <= vr < first_input + n_in for vr in key):  # inputs only: one call
                pos = self._set_plans[key] = session.input_positions([vr - first_input for vr in key])
            else:
                setters = [None if first_input <= vr < first_input + n_in else self._setter(vr) for vr in vrs]
                for vr, x, setter in zip(vrs, values, setters):
                    if setter is None:
                        session.set_input(vr - first_input, x)
                    else:
                        setter(x)
                return
        session.set_inputs(pos, values)

    def _setter(self, vr):
        var = self._variable(vr)
        if var.setter is None:
            raise ValueError(f"{self.block.model_name}: {var.name} (value reference {vr}) cannot be set")
        return var.setter

    # -- life cycle ----------------------------------------------------------------------
    @property
    def _t(self):
        return self.session.t

    def _start(self, start_time):
        if not math.isfinite(start_time):
            raise ValueError(f"{self.block.model_name}: start time {start_time!r} is not a finite number")
        self._t0 = self.session.t = float(start_time)

    def _check_step(self, t, h):
        """The communication step from ``t`` by ``h`` (s): finite, ``h`` > 0, and not starting before the end
        of the previous step (to rounding: hosts form ``t`` as a sum or from integer ticks)."""
        name = self.block.model_name
        if not (math.isfinite(t) and math.isfinite(h) and h > 0.0):
            raise ValueError(f"{name}: communication step from t = {t!r} s by h = {h!r} s: the time must be a finite "
                             "number and the step size a finite number > 0")
        end = self.session.t
        if t < end - 1e-9 * max(1.0, abs(end)):
            raise ValueError(f"{name}: communication step from t = {t!r} s, before the end of the previous one "
                             f"({end!r} s): time cannot go backwards (restore an FMU state to step again)")

    def exit_initialization_mode(self):
        self._ensure_initialized()
        self._running = True

    def do_step(self, current_time, step_size):
        self._check_step(current_time, step_size)
        self._ensure_initialized()
        self.session.t = current_time
        self.session.advance(current_time, step_size)
        return True

    # -- state ------------------------------------------------------------------------------
    def _get_fmu_state(self):
        return {**self.session.get_state(), "p": self.block.param_values.tolist()}

    def _set_fmu_state(self, state):
        self.block.param_values[:] = state["p"]
        self.session.set_state(state)
