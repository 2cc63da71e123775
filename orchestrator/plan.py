"""The exchange plan: who reads and writes what, in which order, at a communication point.

Built once from the components, the connections, the sources and the record list (a campaign
builds it once and runs many times); the step policies (``orchestrator/policies.py``) call
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

A true algebraic loop (a cycle through direct feedthrough) is refused with the cycle named.
Exchanges allocate nothing: outputs land in one float array, inputs are gathered from it with
``np.take(..., out=...)``, and FMUs read and write that memory directly.
"""
from __future__ import annotations

import numpy as np

from .errors import InputError


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
                 sample="before"):
        """``sample``: in Jacobi exchange, record the outputs as read before the inputs change
        ("before", what libcosim records) or read again after ("after", what Ecos records: an
        output with direct feedthrough then shows the inputs just transferred)."""
        if exchange not in ("ordered", "jacobi"):
            raise InputError(origin, "exchange", f"must be 'ordered' or 'jacobi', not {exchange!r}")
        if sample not in ("before", "after"):
            raise InputError(origin, "sample", f"must be 'before' or 'after', not {sample!r}")
        self.sample_after = sample == "after" and exchange == "jacobi"
        self.components = components
        self.connections = list(connections)  # (src_inst, src_var, dst_inst, dst_var)
        self.sources = list(sources)
        self.record = list(record)  # [(inst, var)]
        self.exchange_scheme = exchange
        source_of = {(d, dv): (s, sv) for s, sv, d, dv in self.connections}
        sourced = {tgt for src in self.sources for tgt in src.targets}
        connected = {(s, sv) for s, sv, _, _ in self.connections}
        self.level = feedthrough_levels(components, self.connections, source_of, sorted(connected), origin)
        record_only = sorted({(i, v) for i, v in self.record if components[i].variables[v].causality == "output"}
                             - connected)
        last = max(self.level.values(), default=-1) + 1
        for node in record_only:  # read once every input is set (they feed nobody)
            self.level[node] = last
        self._build(source_of, sourced)

    def _build(self, source_of, sourced):
        comps = self.components
        out_pos, in_pos = {}, {}
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
            comp._prepare_subsets()
        self._source_ops = []
        for s in self.sources:
            idx = np.array([in_pos[t] for t in s.targets], dtype=np.intp)
            self._source_ops.append((s, idx, np.zeros(len(idx)), sorted({t[0] for t in s.targets})))
        self._source_writes = {comp.name: sub for lev, ops in writes.items() if lev == -1 for comp, sub, _, _ in ops}
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
        out_values = self.out_values
        if initial or self.exchange_scheme == "ordered":
            self._apply_sources(t)
            for op in self._ordered_ops:
                if op[0] == "r":
                    op[1].read_some(op[2])
                else:
                    out_values.take(op[3], out=op[4])  # the method: no numpy dispatch wrapper
                    op[1].write_some(op[2])
            return
        # Jacobi: every output is read before any input changes, sources included (a
        # source is one more output with no inputs: libcosim with the source as an FMU)
        for op in self._jacobi_reads:
            op[1].read_some(op[2])
        self._apply_sources(t)
        for op in self._jacobi_writes:
            out_values.take(op[3], out=op[4])
            op[1].write_some(op[2])
        if self.sample_after:
            for op in self._jacobi_reads:
                op[1].read_some(op[2])

    def record_into(self, row: np.ndarray):
        row[self._rec_out_cols] = self.out_values[self._rec_out_idx]
        if self._rec_in_cols.size:
            row[self._rec_in_cols] = self.in_values[self._rec_in_idx]
