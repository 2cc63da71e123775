"""The exchange plan: who reads and writes what, in which order, at a communication point.

Built once from the components, the connections, the sources and the record list (a campaign
builds it once and runs many times); the step policies (``orchestrator/cosim/policies.py``) call
:meth:`ExchangePlan.exchange` at every communication point and :meth:`ExchangePlan.record_into`
to fill a recorder row. Two schemes:

* ``ordered`` (default): outputs are read and passed on in topological order of the
  direct-feedthrough graph (connections + each component's output dependencies), so an
  output that depends on an input is read only after that input got its value at t_k.
  Outputs are grouped by level (longest feedthrough chain from an input without a
  connected source), one get/set call per component and level. Outputs that feed no
  connection (recorded only) are read after the last level, once every input is set: with
  the lazy evaluation of ``plant.block.BlockSession`` each component then evaluates its
  outputs once per exchange.
* ``jacobi``: every output is read first, then every input is set (what libcosim and most
  fixed-step masters do): a direct-feedthrough path sees its inputs one step late. The
  exchange at the start time is always ordered, as FMI's initialisation mode makes the
  initial values consistent; Jacobi applies from the first step on. Scenario sources take
  their value at t_k after the outputs are read (as a source FMU would under Jacobi), so a
  switch at t_k reaches an output through direct feedthrough at t_{k+1}. This is exactly
  libcosim's fixed-step algorithm (checked in tests/orchestrator/test_libcosim.py).

For the other step policies: :meth:`ExchangePlan.view` gives the same operations restricted to
the components due at a point (multirate: the others hold their inputs and outputs), and
:meth:`ExchangePlan.snapshot` / :meth:`restore` / :meth:`release` save and bring back the whole
system (component states, exchanged values, source segments) for rollback. ``watch`` names
outputs a policy reads besides the recorded ones (announced instants, error variables).

A true algebraic loop (a cycle through direct feedthrough) is refused with the cycle named.
Exchanges allocate nothing: outputs land in one float array, inputs are gathered from it with
``np.take(..., out=...)``, and FMUs read and write that memory directly.
"""
from __future__ import annotations

import numpy as np

from orchestrator.common.errors import InputError


class AlgebraicLoopError(InputError):
    pass


def feedthrough_levels(components, connections, source_of, needed_outputs, origin="scenario"):
    """Level of every needed output: 0 if it depends on no connected input, else one more
    than the highest level among the outputs feeding its inputs. Raises on a cycle."""
    level: dict[tuple, int] = {}
    state: dict[tuple, int] = {}  # 1 visiting, 2 done

    def visit(node, path):
        if state.get(node) == 2:
            return level[node]
        if state.get(node) == 1:
            cycle = path[path.index(node):] + [node]
            text = " -> ".join(f"{i}.{v}" for i, v in cycle)
            raise AlgebraicLoopError(origin, "connections", f"algebraic loop through direct feedthrough: {text}")
        state[node] = 1
        inst, var = node
        best = -1
        for dep in sorted(components[inst].feedthrough.get(var, ())):
            src = source_of.get((inst, dep))
            if src is not None:
                best = max(best, visit(src, path + [node, (inst, dep)]))
        state[node] = 2
        level[node] = best + 1
        return level[node]

    for node in needed_outputs:
        visit(node, [])
    return level


class ExchangePlan:
    """The read/write operations of one communication point, built once."""

    def __init__(self, components: dict, connections, sources=(), record=(), exchange="ordered", origin="scenario",
                 sample="before", watch=()):
        """``sample``: in Jacobi exchange, record the outputs as read before the inputs change
        ("before", what libcosim records) or read again after ("after", what Ecos records: an
        output with direct feedthrough then shows the inputs just transferred). ``watch``: outputs
        a step policy reads besides the recorded ones."""
        if exchange not in ("ordered", "jacobi"):
            raise InputError(origin, "exchange", f"must be 'ordered' or 'jacobi', not {exchange!r}")
        if sample not in ("before", "after"):
            raise InputError(origin, "sample", f"must be 'before' or 'after', not {sample!r}")
        self.sample_after = sample == "after" and exchange == "jacobi"
        self.components = components
        self.connections = list(connections)  # (src_inst, src_var, dst_inst, dst_var)
        self.sources = list(sources)
        self.record = list(record)  # [(inst, var)]
        self.watch = list(watch)  # outputs a step policy reads (announced instants, error variables)
        self.exchange_scheme = exchange
        source_of = {(d, dv): (s, sv) for s, sv, d, dv in self.connections}
        sourced = {tgt for src in self.sources for tgt in src.targets}
        connected = {(s, sv) for s, sv, _, _ in self.connections}
        self.level = feedthrough_levels(components, self.connections, source_of, sorted(connected), origin)
        for inst, var in self.watch:
            if inst not in components or components[inst].variables.get(var) is None \
                    or components[inst].variables[var].causality != "output":
                raise InputError(origin, "timing", f"{inst}.{var} is not an output of an instance")
        record_only = sorted({(i, v) for i, v in self.record + self.watch
                              if components[i].variables[v].causality == "output"} - connected)
        last = max(self.level.values(), default=-1) + 1
        for node in record_only:  # read once every input is set (they feed nobody)
            self.level[node] = last
        self._build(source_of, sourced)

    def _build(self, source_of, sourced):
        comps = self.components
        out_pos, in_pos = {}, {}
        self._all_inputs = {}
        out_names = {n: [] for n in comps}
        in_names = {n: [] for n in comps}
        for (inst, var), lev in self.level.items():
            out_names[inst].append((lev, comps[inst].variables[var].vr, var))
        for inst, var in source_of:
            lev = self.level[source_of[(inst, var)]]
            in_names[inst].append((lev, comps[inst].variables[var].vr, var))
        for inst, var in sourced:
            in_names[inst].append((-1, comps[inst].variables[var].vr, var))
        recorded_inputs = [(i, v) for i, v in self.record if comps[i].variables[v].causality != "output"]
        for inst, var in recorded_inputs:
            if (inst, var) not in source_of and (inst, var) not in sourced:
                raise InputError("scenario", "record", f"{inst}.{var} is not an output nor a driven input")
        self.out_values = np.zeros(sum(len(v) for v in out_names.values()))
        self.in_values = np.zeros(sum(len(v) for v in in_names.values()))
        reads: dict[int, list] = {}
        writes: dict[int, list] = {}
        # positions first (every component), then the read/write operations
        o = i = 0
        blocks = {}
        for inst in comps:
            outs, ins = sorted(out_names[inst]), sorted(in_names[inst])
            blocks[inst] = (outs, ins, o, i)
            for _, _, var in outs:
                out_pos[(inst, var)] = o
                o += 1
            for _, _, var in ins:
                in_pos[(inst, var)] = i
                i += 1
        for inst, comp in comps.items():
            outs, ins, o0, i0 = blocks[inst]
            comp.bind([v for _, _, v in outs], self.out_values[o0 : o0 + len(outs)],
                      [v for _, _, v in ins], self.in_values[i0 : i0 + len(ins)])
            for lev in sorted({x[0] for x in outs}):
                pos = [k for k, x in enumerate(outs) if x[0] == lev]
                reads.setdefault(lev, []).append((comp, comp.subset(out_positions=pos)))
            for lev in sorted({x[0] for x in ins}):
                pos = [k for k, x in enumerate(ins) if x[0] == lev]
                sub = comp.subset(in_positions=pos)
                dst = self.in_values[i0 + pos[0] : i0 + pos[-1] + 1]
                src = (np.array([out_pos[source_of[(inst, ins[k][2])]] for k in pos], dtype=np.intp)
                       if lev >= 0 else None)  # None: driven by a source
                writes.setdefault(lev, []).append((comp, sub, src, dst))
            # every bound input at once: rewritten after a rollback (orchestrator/cosim/policies.py)
            self._all_inputs[inst] = comp.subset(in_positions=list(range(len(ins)))) if ins else None
            comp.prepare()
        self.out_pos, self.in_pos = out_pos, in_pos
        self._source_ops = []
        for s in self.sources:
            idx = np.array([in_pos[t] for t in s.targets], dtype=np.intp)
            self._source_ops.append((s, idx, np.zeros(len(idx)), sorted({t[0] for t in s.targets})))
        self._source_writes = {comp.name: sub for lev, ops in writes.items() if lev == -1 for comp, sub, _, _ in ops}
        # the sources split by the instance they drive, for exchanges of some components only
        # (multirate: a component sees a source's new value at its own next communication point)
        self._owner_sources = []
        for j, s in enumerate(self.sources):
            for owner in sorted({t[0] for t in s.targets}):
                cols = [c for c, t in enumerate(s.targets) if t[0] == owner]
                idx = np.array([in_pos[s.targets[c]] for c in cols], dtype=np.intp)
                self._owner_sources.append(((j, owner), s, owner, idx, np.array(cols, dtype=np.intp)))
        self._owner_segment: dict = {}
        self._views: dict = {}
        # recording
        self.columns = [f"{i}.{v}" for i, v in self.record]
        rec_out = [(k, out_pos[(i, v)]) for k, (i, v) in enumerate(self.record) if (i, v) in out_pos]
        rec_in = [(k, in_pos[(i, v)]) for k, (i, v) in enumerate(self.record) if (i, v) not in out_pos]
        self._rec_out_cols = np.array([k for k, _ in rec_out], dtype=np.intp)
        self._rec_out_idx = np.array([p for _, p in rec_out], dtype=np.intp)
        self._rec_in_cols = np.array([k for k, _ in rec_in], dtype=np.intp)
        self._rec_in_idx = np.array([p for _, p in rec_in], dtype=np.intp)
        levels = sorted(set(reads) | {lev for lev in writes if lev >= 0})
        ordered, jr, jw = [], [], []
        for lev in levels:
            r = [("r", c, k) for c, k in reads.get(lev, [])]
            w = [("w", c, k, s, d) for c, k, s, d in writes.get(lev, []) if lev >= 0]
            ordered += r + w
            jr += r
            jw += w
        self._ordered_ops = ordered
        self._jacobi_reads, self._jacobi_writes = jr, jw

    # -- one communication point ------------------------------------------------------------
    def reset_sources(self):
        for s in self.sources:
            s.reset()
        self._owner_segment.clear()

    def view(self, names) -> ExchangeView:
        """The exchange restricted to the components ``names`` (the ones due at a point of a
        multirate run), built once per set of names."""
        key = frozenset(names)
        v = self._views.get(key)
        if v is None:
            v = self._views[key] = ExchangeView(self, key)
        return v

    # -- rollback (orchestrator/cosim/policies.py: AdaptiveStep) ------------------------------------
    def snapshot(self) -> tuple:
        """Every component's state (``get_state``), the exchanged values and the sources'
        segments: what :meth:`restore` needs to bring the whole system back to this point."""
        states = [(c, c.get_state()) for c in self.components.values()]
        return (states, self.out_values.copy(), self.in_values.copy(),
                [s._segment for s in self.sources], dict(self._owner_segment))

    def restore(self, snap) -> None:
        """Back to the point of ``snap``: component states, exchanged values, every bound input
        written again (a third-party FMU's state need not hold its inputs) and source segments."""
        states, out_values, in_values, segments, owner = snap
        for c, state in states:
            c.set_state(state)
        self.out_values[:] = out_values
        self.in_values[:] = in_values
        for name, comp in self.components.items():
            if self._all_inputs[name] is not None:
                comp.write_some(self._all_inputs[name])
        for s, seg in zip(self.sources, segments):
            s._segment = seg
        self._owner_segment.clear()
        self._owner_segment.update(owner)

    def release(self, snap) -> None:
        """Free the component states of a snapshot that is no longer needed."""
        for c, state in snap[0]:
            c.free_state(state)

    def _apply_sources(self, t):
        changed = set()
        for s, idx, buf, owners in self._source_ops:
            if s.update(t, buf):
                self.in_values[idx] = buf
                changed.update(owners)
        for name in changed:
            self.components[name].write_some(self._source_writes[name])

    def exchange(self, t, initial=False):
        """Propagate values at communication point t (sources, then the planned operations).
        ``initial``: the consistent (ordered) exchange of the start time."""
        _exchange(self, self, t, initial)

    def record_into(self, row: np.ndarray):
        row[self._rec_out_cols] = self.out_values[self._rec_out_idx]
        if self._rec_in_cols.size:
            row[self._rec_in_cols] = self.in_values[self._rec_in_idx]


class ExchangeView:
    """The plan's operations restricted to some components (the ones due at a communication
    point of a multirate run): the others are neither read nor written, so their outputs and
    inputs hold (sampled-data semantics). Same order as the full plan, ordered or Jacobi.

    Sources: each driven component has its own record of the segment it last received, so a
    component sees a source's new value at its own next communication point."""

    def __init__(self, plan: ExchangePlan, names: frozenset):
        self.plan = plan
        self.names = names
        self._ordered_ops = [op for op in plan._ordered_ops if op[1].name in names]
        self._jacobi_reads = [op for op in plan._jacobi_reads if op[1].name in names]
        self._jacobi_writes = [op for op in plan._jacobi_writes if op[1].name in names]
        self._sources = [x for x in plan._owner_sources if x[2] in names]

    def _apply_sources(self, t):
        plan = self.plan
        seen = plan._owner_segment
        changed = []
        for key, s, owner, idx, cols in self._sources:
            k = s.segment(t)
            if seen.get(key) != k:
                seen[key] = k
                plan.in_values[idx] = s.values[k, cols]
                if owner not in changed:
                    changed.append(owner)
        for name in changed:
            plan.components[name].write_some(plan._source_writes[name])

    def exchange(self, t, initial=False):
        _exchange(self.plan, self, t, initial)


def _exchange(plan: ExchangePlan, ops, t, initial):
    """One exchange at t through ``ops`` (the whole plan or a view of it): sources, then the
    ordered operations, or in Jacobi every read before any write (sources included: a source is
    one more output with no inputs, as libcosim runs it as an FMU), then, when sampling after
    the transfer, the reads again."""
    out_values = plan.out_values
    if initial or plan.exchange_scheme == "ordered":
        ops._apply_sources(t)
        for op in ops._ordered_ops:
            if op[0] == "r":
                op[1].read_some(op[2])
            else:
                out_values.take(op[3], out=op[4])  # the method: no numpy dispatch wrapper
                op[1].write_some(op[2])
        return
    for op in ops._jacobi_reads:
        op[1].read_some(op[2])
    ops._apply_sources(t)
    for op in ops._jacobi_writes:
        out_values.take(op[3], out=op[4])
        op[1].write_some(op[2])
    if plan.sample_after:
        for op in ops._jacobi_reads:
            op[1].read_some(op[2])
