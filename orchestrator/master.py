"""The co-simulation master: connects components and steps them with a fixed step.

At each communication point t_k the master propagates outputs to inputs, records, then
calls ``step(t_k, h)`` on every component. Two exchange schemes:

* ``ordered`` (default): outputs are read and passed on in topological order of the
  direct-feedthrough graph (connections + each FMU's output ``dependencies``), so an
  output that depends on an input is read only after that input got its value at t_k.
  Outputs are grouped by level (longest feedthrough chain from an input without a
  connected source), one get/set call per component and level.
* ``jacobi``: every output is read first, then every input is set (what libcosim and
  most fixed-step masters do): a direct-feedthrough path sees its inputs one step late.
  The exchange at the start time is always ordered, as FMI's initialisation mode makes
  the initial values consistent; Jacobi applies from the first step on. Scenario sources
  take their value at t_k after the outputs are read (as a source FMU would under
  Jacobi), so a switch at t_k reaches an output through direct feedthrough at t_{k+1}.
  This is exactly libcosim's fixed-step algorithm (checked in tests/test_libcosim.py):
  at t0 it iterates set-inputs/get-outputs N times (N = number of simulators) in
  initialisation mode, i.e. a consistent initial exchange for any feedthrough chain
  through at most N-1 components; then each step is set inputs, doStep, get outputs,
  transfer, so the inputs of step k are the outputs read after step k-1.

A true algebraic loop (a cycle through direct feedthrough) is refused with the cycle named.
The hot loop does no allocation: outputs land in one float array, inputs are gathered
from it with ``np.take(..., out=...)``, and FMUs read and write that memory directly.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError


class AlgebraicLoopError(InputError):
    pass


@dataclass
class RunResult:
    columns: list[str]
    time: np.ndarray
    data: np.ndarray  # (rows, len(columns))
    complete: bool
    error: str | None = None
    wall_time: float = 0.0
    steps: int = 0
    exchange: str = "ordered"
    mode: str = "fmu"
    info: dict = field(default_factory=dict)

    def column(self, name: str) -> np.ndarray:
        return self.data[:, self.columns.index(name)]

    def vector(self, base: str) -> np.ndarray:
        """All columns ``base[...]`` in index order, as (rows, n)."""
        cols = [i for i, c in enumerate(self.columns) if c.startswith(base + "[")]
        return self.data[:, cols]


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


def time_grid(t0: float, h: float, n: int) -> np.ndarray:
    """Communication points t_0..t_n. When t0 and h are whole nanoseconds (every
    scenario we have), t_k = (t0_ns + k h_ns) / 1e9 from integer nanoseconds: the
    correctly rounded value of t0 + k h, and exactly the doubles libcosim passes to
    fmi2DoStep (it keeps time as int64 ns and steps with h_k = t_{k+1} - t_k). The run
    passes h_k = t_{k+1} - t_k too, so an FMU that adds t_k + h_k lands on t_{k+1}
    exactly. Otherwise t0 + k h in floating point."""
    t0_ns, h_ns = round(t0 * 1e9), round(h * 1e9)
    if h_ns > 0 and abs(h * 1e9 - h_ns) < 1e-6 and abs(t0 * 1e9 - t0_ns) < 1e-6 and abs(t0_ns) + n * h_ns < 2**53:
        return (t0_ns + h_ns * np.arange(n + 1, dtype=np.int64)) / 1e9
    return t0 + h * np.arange(n + 1)


class Master:
    """Build once from components + wiring, then ``run`` (or drive step by step)."""

    def __init__(self, components: dict, connections, sources=(), record=(), exchange="ordered", origin="scenario"):
        if exchange not in ("ordered", "jacobi"):
            raise InputError(origin, "exchange", f"must be 'ordered' or 'jacobi', not {exchange!r}")
        self.components = components
        self.connections = list(connections)  # (src_inst, src_var, dst_inst, dst_var)
        self.sources = list(sources)
        self.record = list(record)  # [(inst, var)]
        self.exchange = exchange
        source_of = {(d, dv): (s, sv) for s, sv, d, dv in self.connections}
        sourced = {tgt for src in self.sources for tgt in src.targets}
        needed = {(s, sv) for s, sv, _, _ in self.connections}
        needed |= {(i, v) for i, v in self.record if components[i].variables[v].causality == "output"}
        self.level = feedthrough_levels(components, self.connections, source_of, sorted(needed), origin)
        self._build(source_of, sourced)

    # -- plan -------------------------------------------------------------------------------
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
        n_out = sum(len(v) for v in out_names.values())
        n_in = sum(len(v) for v in in_names.values())
        self.out_values = np.zeros(n_out)
        self.in_values = np.zeros(n_in)
        self._reads: dict[int, list] = {}
        self._writes: dict[int, list] = {}
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
            comp.bind(
                [v for _, _, v in outs],
                self.out_values[o0 : o0 + len(outs)],
                [v for _, _, v in ins],
                self.in_values[i0 : i0 + len(ins)],
            )
            for lev in sorted({x[0] for x in outs}):
                pos = [k for k, x in enumerate(outs) if x[0] == lev]
                self._reads.setdefault(lev, []).append((comp, comp.subset(out_positions=pos)))
            for lev in sorted({x[0] for x in ins}):
                pos = [k for k, x in enumerate(ins) if x[0] == lev]
                sub = comp.subset(in_positions=pos)
                dst = self.in_values[i0 + pos[0] : i0 + pos[-1] + 1]
                if lev >= 0:
                    src = np.array([out_pos[source_of[(inst, ins[k][2])]] for k in pos], dtype=np.intp)
                else:
                    src = None  # driven by a source
                self._writes.setdefault(lev, []).append((comp, sub, src, dst))
            comp._prepare_subsets()
        # sources
        self._source_ops = []
        for s in self.sources:
            idx = np.array([in_pos[t] for t in s.targets], dtype=np.intp)
            buf = np.zeros(len(idx))
            owners = sorted({t[0] for t in s.targets})
            self._source_ops.append((s, idx, buf, owners))
        self._source_writes = {
            comp.name: sub for lev, ops in self._writes.items() if lev == -1 for comp, sub, _, _ in ops
        }
        # recording
        self.columns = [f"{i}.{v}" for i, v in self.record]
        self._rec_out = [(k, out_pos[(i, v)]) for k, (i, v) in enumerate(self.record) if (i, v) in out_pos]
        self._rec_in = [(k, in_pos[(i, v)]) for k, (i, v) in enumerate(self.record) if (i, v) not in out_pos]
        self._rec_out_cols = np.array([k for k, _ in self._rec_out], dtype=np.intp)
        self._rec_out_idx = np.array([p for _, p in self._rec_out], dtype=np.intp)
        self._rec_in_cols = np.array([k for k, _ in self._rec_in], dtype=np.intp)
        self._rec_in_idx = np.array([p for _, p in self._rec_in], dtype=np.intp)
        levels = sorted(set(self._reads) | {lev for lev in self._writes if lev >= 0})
        ordered, reads, writes = [], [], []
        for lev in levels:
            r = [("r", c, k) for c, k in self._reads.get(lev, [])]
            w = [("w", c, k, s, d) for c, k, s, d in self._writes.get(lev, [])]
            ordered += r + w
            reads += r
            writes += w
        self._ordered_ops = ordered
        self._ops = ordered if self.exchange == "ordered" else reads + writes
        self._jacobi_reads, self._jacobi_writes = reads, writes

    # -- stepping -----------------------------------------------------------------------------
    def _apply_sources(self, t):
        changed = set()
        for s, idx, buf, owners in self._source_ops:
            if s.update(t, buf):
                self.in_values[idx] = buf
                changed.update(owners)
        for name in changed:
            self.components[name].write_some(self._source_writes[name])

    def exchange_at(self, t, initial=False):
        """Propagate values at communication point t (sources, then the planned ops).
        ``initial``: the consistent (ordered) exchange of the start time."""
        out_values = self.out_values
        if initial or self.exchange == "ordered":
            self._apply_sources(t)
            for op in self._ordered_ops:
                if op[0] == "r":
                    op[1].read_some(op[2])
                else:
                    np.take(out_values, op[3], out=op[4])
                    op[1].write_some(op[2])
            return
        # Jacobi: every output is read before any input changes, sources included (a
        # source is one more output with no inputs: libcosim with the source as an FMU)
        for op in self._jacobi_reads:
            op[1].read_some(op[2])
        self._apply_sources(t)
        for op in self._jacobi_writes:
            np.take(out_values, op[3], out=op[4])
            op[1].write_some(op[2])

    def record_into(self, row: np.ndarray):
        row[self._rec_out_cols] = self.out_values[self._rec_out_idx]
        if self._rec_in_cols.size:
            row[self._rec_in_cols] = self.in_values[self._rec_in_idx]

    def run(self, t0, t1, h, progress=False) -> RunResult:
        """Step from t0 to t1 with step h. Components must be set up already. On an
        error the rows recorded so far are returned with ``complete=False``."""
        from .components import ComponentError

        n = int(round((t1 - t0) / h))
        data = np.full((n + 1, len(self.columns)), np.nan)
        times = time_grid(t0, h, n)
        tlist = times.tolist()  # Python floats: numpy scalars are slow in block arithmetic
        hlist = np.diff(times).tolist()  # h_k = t_{k+1} - t_k, so that t_k + h_k == t_{k+1}
        for s in self.sources:
            s.reset()
        comps = list(self.components.values())
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=n, delay=2.0, unit="step", leave=False, mininterval=0.5)
        error = None
        rows = done = 0
        t_wall = time.perf_counter()
        try:
            for k in range(n):
                t = tlist[k]
                self.exchange_at(t, initial=(k == 0))
                self.record_into(data[k])
                rows = k + 1
                for c in comps:
                    c.step(t, hlist[k])
                if bar is not None and not k & 1023:
                    bar.update(k - done)
                    done = k
            self.exchange_at(tlist[n])
            self.record_into(data[n])
            rows = n + 1
        except ComponentError as e:
            error = str(e)
        finally:
            if bar is not None:
                bar.close()
        wall = time.perf_counter() - t_wall
        return RunResult(
            columns=self.columns,
            time=times[:rows],
            data=data[:rows],
            complete=error is None,
            error=error,
            wall_time=wall,
            steps=max(0, rows - 1),
            exchange=self.exchange,
        )
