"""Step policies: when the master exchanges, steps and records.

A policy drives one run over an :class:`orchestrator.cosim.plan.ExchangePlan`: it chooses the
communication points, calls ``plan.exchange(t)``, steps every component, records rows into an
:class:`orchestrator.cosim.recorder.Recorder`, and stops early on a component error or a stop request
(``orchestrator/common/interrupt.py``). Every policy reports :class:`RunStats`, whose
``extra["step_statistics"]`` goes into metrics.json.

* :class:`FixedStep`: one common step h for everyone, communication times on an integer
  nanosecond grid (:func:`time_grid`), exactly libcosim's.
* :class:`MultirateStep`: a base step h on the same grid; each component has its own
  communication step, a whole multiple m of h (libcosim's decimation factor): it is stepped
  at the base points k with k % m == 0 over H = t_{k+m} - t_k and, between its points, neither
  read nor written, so its inputs and outputs hold (sampled data). Components may announce
  their next sample instant through an output (``announced``): the master then shortens the
  common step of the base-rate components (m = 1) to land exactly on it, exchanges there among
  them, and goes on to the grid point (optionally recording a row at the instant). Slower
  components keep their own grid.
* :class:`AdaptiveStep`: error-controlled variable steps by step doubling with rollback (one step
  h against two of h/2 from the same state, through get/set state), weighted rtol/atol norm on
  chosen outputs, a PI step-size controller; steps land on the output grid and on announced
  instants, rows are recorded there.

Which components are due, and in which order values move, is the plan's business
(:meth:`ExchangePlan.view` for the components due at a point); the policies only choose times.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from orchestrator.common.interrupt import REQUEST as _REQUEST
from orchestrator.common.progress import Progress
from orchestrator.common.watchdog import Hung, forced_stop, run_deadline, stop_reason
from orchestrator.cosim.component import ComponentError
from plant.timing import StepWindow


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


@dataclass
class RunStats:
    """What a policy reports about its run (also written into metrics.json)."""

    steps: int = 0
    wall_time: float = 0.0
    error: str | None = None
    interrupted: int = 0
    extra: dict = field(default_factory=dict)


def _stop(stats: RunStats, request, t: float) -> None:
    """Record why the loop stops at ``t``: a signal (``stats.interrupted``) or the time limit."""
    stats.error, stats.interrupted, timed_out = stop_reason(request, t)
    if timed_out:
        stats.extra["timed_out"] = True


class StepPolicy:
    name = "base"

    def run(self, plan, t0: float, t1: float, recorder, progress=False) -> RunStats:  # pragma: no cover
        raise NotImplementedError


class FixedStep(StepPolicy):
    """One common communication step ``h`` (s) for every component."""

    name = "fixed"

    def __init__(self, h: float):
        self.h = float(h)

    def run(self, plan, t0, t1, recorder, progress=False) -> RunStats:
        REQUEST = _REQUEST  # a local name: the loop reads it every step
        deadline, monotonic = run_deadline(), time.monotonic
        n = int(round((t1 - t0) / self.h))
        times = time_grid(t0, self.h, n)
        tlist = times.tolist()  # Python floats: numpy scalars are slow in block arithmetic
        hlist = np.diff(times).tolist()  # h_k = t_{k+1} - t_k, so that t_k + h_k == t_{k+1}
        plan.reset_sources()
        comps = list(plan.components.values())
        stats = RunStats()
        with _Stepping(stats, n, progress) as loop:
            for k in range(n):
                t = tlist[k]
                plan.exchange(t, initial=(k == 0))
                plan.record_into(recorder.row(t))
                if REQUEST or (deadline is not None and monotonic() > deadline):  # a signal or the time limit
                    _stop(stats, REQUEST, t)
                    break
                for c in comps:
                    c.step(t, hlist[k])
                stats.steps = k + 1
                loop.tick(k)
            else:
                plan.exchange(tlist[n], initial=(n == 0))
                plan.record_into(recorder.row(tlist[n]))
        stats.extra["step_statistics"] = step_statistics(
            self.name, stats, accepted=stats.steps, smallest=self.h if stats.steps else None,
            largest=self.h if stats.steps else None, do_steps={c.name: stats.steps for c in comps})
        return stats


def step_statistics(policy, stats, accepted, smallest, largest, do_steps, rejected=0, rollbacks=0, **more) -> dict:
    """The ``step_statistics`` of metrics.json (steps in s, wall time in s)."""
    return {"policy": policy, "accepted_steps": int(accepted), "rejected_steps": int(rejected),
            "rollbacks": int(rollbacks), "smallest_step": smallest, "largest_step": largest,
            "do_steps": dict(do_steps), "do_steps_total": int(sum(do_steps.values())),
            "wall_time_s": round(stats.wall_time, 4), **more}


def _missing_outputs(plan, refs, what):
    missing = [f"{i}.{v}" for i, v in refs if (i, v) not in plan.out_pos]
    if missing:
        raise ValueError(f"{what} {', '.join(missing)} not read by the exchange plan: build the Master with "
                         "watch=policy.watch")
    return np.array([plan.out_pos[r] for r in refs], dtype=np.intp)


def next_instant(values, t: float, t_end: float):
    """The earliest announced instant strictly inside the step (t, t_end), or None. "Strictly
    inside" is plant/timing.py's rule: an instant within EVENT_TOL * h of either end already
    belongs to that end, where every block treats it as the communication point itself."""
    w = StepWindow(t, t_end - t)
    best = None
    for x in values.tolist():
        if w.contains(x) and (best is None or x < best):
            best = x
    return best


class MultirateStep(StepPolicy):
    """Base step ``h`` (s); ``multiples``: instance -> whole multiple m >= 1 of h (default 1);
    ``announced``: [(instance, output)] giving the next instant the instance must be stepped to
    (instances with m = 1); ``record_announced``: a row at every landed instant too."""

    name = "multirate"

    def __init__(self, h: float, multiples=None, announced=(), record_announced=False):
        self.h = float(h)
        self.multiples = {k: int(v) for k, v in (multiples or {}).items()}
        bad = {k: v for k, v in self.multiples.items() if v < 1}
        if bad:
            raise ValueError(f"multirate: step multiples must be whole numbers >= 1, got {bad}")
        self.announced = list(announced)
        self.record_announced = bool(record_announced)
        slow = [i for i, _ in self.announced if self.multiples.get(i, 1) != 1]
        if slow:
            raise ValueError(f"multirate: instance {slow[0]} announces instants, so it must run at the base step")

    @property
    def watch(self):
        return self.announced

    def run(self, plan, t0, t1, recorder, progress=False) -> RunStats:
        REQUEST = _REQUEST  # a local name: the loop reads it every step
        deadline, monotonic = run_deadline(), time.monotonic
        stats = RunStats()
        n = int(round((t1 - t0) / self.h))
        tl = time_grid(t0, self.h, n).tolist()
        comps = plan.components
        mult = {name: self.multiples.get(name, 1) for name in comps}
        unknown = set(self.multiples) - set(comps)
        if unknown:
            stats.error = f"multirate: no instance {sorted(unknown)[0]!r}"
            return stats
        fast = [c for name, c in comps.items() if mult[name] == 1]
        slow = [(c, mult[name]) for name, c in comps.items() if mult[name] > 1]
        for c, m in slow:
            if n % m:
                stats.error = (f"multirate: the run of {n} base steps is not a whole number of instance "
                               f"{c.name}'s steps ({m} base steps)")
                return stats
        if self.announced:
            ann = _missing_outputs(plan, self.announced, "announced instants")
            fixed_only = [c.name for c in fast if not c.variable_step]
            if fixed_only:
                stats.error = (f"instance '{fixed_only[0]}' cannot vary its communication step "
                               "(canHandleVariableCommunicationStepSize is false): announced instants need it")
                return stats
        if not self.announced:
            return self._run_periodic(plan, tl, n, fast, slow, comps, recorder, progress, stats, REQUEST, deadline,
                                      monotonic)
        fast_view = plan.view(c.name for c in fast)
        views = {}

        def due(k):
            key = tuple(k % m == 0 for _, m in slow)
            v = views.get(key)
            if v is None:
                v = views[key] = plan.view([c.name for c in fast] + [c.name for (c, _), d in zip(slow, key) if d])
            return v

        plan.reset_sources()
        do_steps = dict.fromkeys(comps, 0)
        smallest, largest, landed = None, None, 0
        with _Stepping(stats, n, progress) as loop:
            for k in range(n + 1):
                t = tl[k]
                due(k).exchange(t, initial=(k == 0))
                plan.record_into(recorder.row(t))
                if k == n:
                    break
                if REQUEST or (deadline is not None and monotonic() > deadline):  # a signal or the time limit
                    _stop(stats, REQUEST, t)
                    break
                for c, m in slow:
                    if k % m == 0:
                        c.step(t, tl[k + m] - t)
                        do_steps[c.name] += 1
                t_end = tl[k + 1]
                s = t
                if self.announced:
                    while True:
                        tau = next_instant(plan.out_values[ann], s, t_end)
                        if tau is None:
                            break
                        for c in fast:
                            c.step(s, tau - s)
                            do_steps[c.name] += 1
                        smallest = tau - s if smallest is None else min(smallest, tau - s)
                        largest = tau - s if largest is None else max(largest, tau - s)
                        s = tau
                        landed += 1
                        fast_view.exchange(s)
                        if self.record_announced:
                            plan.record_into(recorder.row(s))
                for c in fast:
                    c.step(s, t_end - s)
                    do_steps[c.name] += 1
                h = t_end - s
                smallest = h if smallest is None else min(smallest, h)
                largest = h if largest is None else max(largest, h)
                stats.steps = k + 1
                loop.tick(k)
        common = stats.steps + landed
        stats.extra["step_statistics"] = step_statistics(
            self.name, stats, accepted=common, smallest=smallest, largest=largest, do_steps=do_steps,
            base_step=self.h, step_multiples={c.name: m for c, m in slow}, announced_instants=landed)
        return stats


    def _run_periodic(self, plan, tl, n, fast, slow, comps, recorder, progress, stats, REQUEST, deadline, monotonic):
        """The loop without announced instants: the instances due at base step k repeat with the
        period L = lcm of the multiples, so the exchange view and the slow instances to step are
        looked up by k mod L (built once), and the counts are known in advance; the same calls in the
        same order as the general loop."""
        import math

        period = 1
        for _, m in slow:
            period = period * m // math.gcd(period, m)
        views, due_slow = {}, []
        for k in range(period):
            key = tuple(k % m == 0 for _, m in slow)
            if key not in views:
                views[key] = plan.view([c.name for c in fast] + [c.name for (c, _), d in zip(slow, key) if d])
            due_slow.append((views[key], [(c, m) for c, m in slow if k % m == 0]))
        hl = np.diff(np.asarray(tl)).tolist()
        plan.reset_sources()
        with _Stepping(stats, n, progress) as loop:
            for k in range(n + 1):
                t = tl[k]
                view, stepped = due_slow[k % period]
                view.exchange(t, initial=(k == 0))
                plan.record_into(recorder.row(t))
                if k == n:
                    break
                if REQUEST or (deadline is not None and monotonic() > deadline):  # a signal or the time limit
                    _stop(stats, REQUEST, t)
                    break
                for c, m in stepped:
                    c.step(t, tl[k + m] - t)
                h = hl[k]
                for c in fast:
                    c.step(t, h)
                stats.steps = k + 1
                loop.tick(k)
        k = stats.steps
        do_steps = {name: 0 for name in comps}
        for c in fast:
            do_steps[c.name] = k
        for c, m in slow:
            do_steps[c.name] = (k + m - 1) // m  # base steps j < k with j % m == 0
        used = hl[:k]
        stats.extra["step_statistics"] = step_statistics(
            self.name, stats, accepted=k, smallest=min(used) if used else None, largest=max(used) if used else None,
            do_steps=do_steps, base_step=self.h, step_multiples={c.name: m for c, m in slow}, announced_instants=0)
        return stats


class AdaptiveStep(StepPolicy):
    """Error-controlled variable communication steps with rollback (step doubling).

    From a state at t (every component at t, the exchange at t done), with a proposed step h:

    1. save every component's state (``get_state``) and the exchanged values;
    2. one step of h, exchange at t + h, keep the error outputs y_1;
    3. restore the saved state; two steps of h/2 (exchange at t + h/2 and at t + h), error
       outputs y_2;
    4. err = sqrt(mean(((y_2 - y_1) / (atol + rtol max(|y_1|, |y_2|)))^2)). The master's
       coupling (inputs held over a step) is first order, a local error O(h^2), so y_2 - y_1
       estimates the error of y_2 itself (2^p - 1 = 1 with p = 1);
    5. err <= 1: accept y_2 (the system stays where the half steps left it) and propose the next
       step with the PI controller h_new = h safety err^(-0.35) err_prev^(0.2) (Gustafsson's
       0.7/k and 0.4/k with k = 2), the factor kept in [0.2, 5] and not above 1 right after a
       rejection; err > 1: restore the saved state, h_new = h max(0.2, safety err^(-1/2)), retry.

    Steps stay within [min_step, max_step] and land exactly on every point of the output grid
    (``output_step``; a step that would leave less than half a step before the next grid point
    is split in two equal ones) and on announced instants; rows are recorded at grid points (and
    at announced instants with ``record_announced``). A step at min_step is accepted whatever
    its error (counted in ``accepted_above_tolerance``). Each attempt costs three doSteps per
    component and one rollback (two if rejected)."""

    name = "adaptive"
    ALPHA, BETA, FAC_MIN, FAC_MAX = 0.35, 0.2, 0.2, 5.0

    def __init__(self, h0: float, output_step: float, rtol: float, atol: float, min_step: float, max_step: float,
                 error_variables, safety: float = 0.9, announced=(), record_announced=False):
        self.h0, self.output_step = float(h0), float(output_step)
        self.rtol, self.atol, self.safety = float(rtol), float(atol), float(safety)
        self.min_step, self.max_step = float(min_step), float(max_step)
        self.error_variables = list(error_variables)
        self.announced = list(announced)
        self.record_announced = bool(record_announced)
        if not self.rtol > 0 or not self.atol >= 0:
            raise ValueError(f"adaptive: rtol must be > 0 and atol >= 0 (rtol = {rtol}, atol = {atol})")
        if not 0 < self.min_step <= self.max_step:
            raise ValueError(f"adaptive: need 0 < min_step <= max_step (min_step = {min_step}, max_step = {max_step})")
        if not 0 < self.safety <= 1:
            raise ValueError(f"adaptive: safety must be in (0, 1], got {safety}")
        if not self.error_variables:
            raise ValueError("adaptive: no error variables")

    @property
    def watch(self):
        return self.error_variables + [a for a in self.announced if a not in self.error_variables]

    def expected_rows(self, t0, t1):
        return int(round((t1 - t0) / self.output_step)) + 1

    def run(self, plan, t0, t1, recorder, progress=False) -> RunStats:
        REQUEST = _REQUEST  # a local name: the loop reads it every step
        deadline, monotonic = run_deadline(), time.monotonic
        stats = RunStats()
        comps = list(plan.components.values())
        for c in comps:
            if not c.can_roll_back or not c.variable_step:
                what = "get and set its state" if not c.can_roll_back else "vary its step"
                stats.error = f"instance '{c.name}' cannot {what}: step_policy 'adaptive' needs both"
                return stats
        err_idx = _missing_outputs(plan, self.error_variables, "error variables")
        ann_idx = _missing_outputs(plan, self.announced, "announced instants") if self.announced else None
        n_out = int(round((t1 - t0) / self.output_step))
        grid = time_grid(t0, self.output_step, n_out).tolist()
        out = plan.out_values
        rtol, atol = self.rtol, self.atol
        h = min(max(self.h0, self.min_step), self.max_step)
        err_prev, rejected_before = 1.0, False
        acc = rej = rolls = forced = landed = attempts = 0
        smallest = largest = None
        bar = _progress_bar(n_out) if progress else None
        t_wall = time.perf_counter()
        plan.reset_sources()
        t, g = grid[0], 1
        snap = None
        try:
            plan.exchange(t, initial=True)
            plan.record_into(recorder.row(t))
            while g <= n_out:
                if REQUEST or (deadline is not None and monotonic() > deadline):  # a signal or the time limit
                    _stop(stats, REQUEST, t)
                    break
                target, is_grid = grid[g], True
                if ann_idx is not None:
                    tau = next_instant(out[ann_idx], t, target)
                    if tau is not None:
                        target, is_grid = tau, False
                remaining = target - t
                wanted = h
                if h >= remaining * (1 - 1e-12):
                    h_try, t_new, lands = remaining, target, True
                elif h > 0.5 * remaining:
                    h_try, lands = 0.5 * remaining, False
                    t_new = t + h_try
                else:
                    h_try, lands = h, False
                    t_new = t + h
                snap = plan.snapshot()
                attempts += 1
                for c in comps:  # one step of h
                    c.step(t, t_new - t)
                plan.exchange(t_new)
                y1 = out[err_idx].copy()
                plan.restore(snap)
                rolls += 1
                t_mid = t + 0.5 * (t_new - t)
                for c in comps:  # two steps of h/2
                    c.step(t, t_mid - t)
                plan.exchange(t_mid)
                for c in comps:
                    c.step(t_mid, t_new - t_mid)
                plan.exchange(t_new)
                y2 = out[err_idx]
                scale = atol + rtol * np.maximum(np.abs(y1), np.abs(y2))
                with np.errstate(divide="ignore", invalid="ignore"):
                    ratio = np.where(y2 == y1, 0.0, (y2 - y1) / scale)
                err = float(np.sqrt(np.mean(ratio * ratio)))
                if not np.isfinite(err):
                    err = np.inf
                if err <= 1.0 or h_try <= self.min_step * (1 + 1e-12):
                    if err > 1.0:
                        forced += 1
                    plan.release(snap)
                    snap = None
                    acc += 1
                    stats.steps = acc
                    smallest = h_try if smallest is None else min(smallest, h_try)
                    largest = h_try if largest is None else max(largest, h_try)
                    t = t_new
                    if lands:
                        if is_grid:
                            plan.record_into(recorder.row(t))
                            g += 1
                            if bar is not None:
                                bar.update(1)
                        else:
                            landed += 1
                            if self.record_announced:
                                plan.record_into(recorder.row(t))
                    fac = self.FAC_MAX if err == 0 else self.safety * err ** -self.ALPHA * err_prev ** self.BETA
                    fac = min(self.FAC_MAX, max(self.FAC_MIN, fac))
                    if rejected_before:
                        fac = min(fac, 1.0)
                    h_new = h_try * fac
                    if h_try < wanted and fac >= 1.0:  # shortened to land: do not let that shrink h
                        h_new = max(h_new, wanted)
                    err_prev, rejected_before = max(err, 1e-4), False
                else:
                    plan.restore(snap)
                    plan.release(snap)
                    snap = None
                    rolls += 1
                    rej += 1
                    rejected_before = True
                    h_new = h_try * max(self.FAC_MIN, self.safety * err ** -0.5)
                h = min(max(h_new, self.min_step), self.max_step)
        except ComponentError as e:
            stats.error = str(e)
        finally:
            if snap is not None:
                try:
                    plan.release(snap)
                except ComponentError:
                    pass
            if bar is not None:
                bar.close()
        stats.wall_time = time.perf_counter() - t_wall
        stats.extra["step_statistics"] = step_statistics(
            self.name, stats, accepted=acc, rejected=rej, rollbacks=rolls, smallest=smallest, largest=largest,
            do_steps={c.name: 3 * attempts for c in comps}, accepted_above_tolerance=forced,
            announced_instants=landed, rtol=rtol, atol=atol, min_step=self.min_step, max_step=self.max_step,
            output_step=self.output_step, error_variables=[f"{i}.{v}" for i, v in self.error_variables])
        return stats


class _Stepping:
    """The frame of a policy's stepping loop (``with _Stepping(stats, n, progress) as loop:``): a
    progress bar over ``n`` steps when ``progress``, advanced by :meth:`tick`; on leaving, the bar
    closed and ``stats.wall_time`` set, and a component error ends the loop as ``stats.error``."""

    def __init__(self, stats: RunStats, n: int, progress: bool):
        self.stats = stats
        self.bar = _progress_bar(n) if progress else None
        self.done = 0

    def __enter__(self):
        self.t_wall = time.perf_counter()
        return self

    def tick(self, k: int):
        """After step ``k``: the bar brought up to it every 1024 steps."""
        if self.bar is not None and not k & 1023:
            self.bar.update(k - self.done)
            self.done = k

    def __exit__(self, kind, exc, tb):
        if self.bar is not None:
            self.bar.close()
        self.stats.wall_time = time.perf_counter() - self.t_wall
        if kind is not None and issubclass(kind, (ComponentError, Hung)):
            self.stats.error = str(exc)
            fired = forced_stop()
            if fired:  # a call that did not return after a stop was due (orchestrator/common/watchdog.py)
                self.stats.error = fired  # an FMU reports Hung as its own error: the cause is the stop
                if _REQUEST:
                    self.stats.interrupted = _REQUEST.signum
                else:
                    self.stats.extra["timed_out"] = True
            return True
        return False


def _progress_bar(n):
    """A bar on a terminal (after 2 s), else a plain log line every 30 s (orchestrator/common/progress.py)."""
    return Progress(n, "stepping", unit="step", delay=2.0, leave=False, every=30.0)
