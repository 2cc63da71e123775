"""Time-function semantics for step-like signals (fault onsets, switching schedules).

Hosts form communication times differently: integer nanoseconds (libcosim), ``t += h``
(Ecos, OMSimulator) or ``start + k*h`` (compiled masters). The same nominal instant 40 s may
reach a block as 40.0, 40.000000000000007 or 39.999999999999993. A schedule that switches at
an instant lying on the communication grid must give the same answer in every host, so no
block compares a stage time with an event time directly. The rule, stated once here and used
by every block:

* Inside a communication step ``advance(t, h, u)`` over [t, t + h], an event at time ``T``
  is placed relative to the step with the tolerance ``tol = STEP_TOL * h``:

  - ``T <= t + tol``:      it happened at or before the start: the new value holds over the
                           whole step (one-sided value from the right at t);
  - ``T >= t + h - tol``:  it happens at or after the end: the old value holds over the whole
                           step, the end point included (one-sided value from the left);
  - otherwise:             it is inside the step: stages at ``tau >= T`` see the new value.

* At a communication point (``outputs_at(t, u)``), the value is the one that holds right
  after ``t`` (from the right): an event at ``T <= t + POINT_TOL * max(1, |t|)`` has happened.

So a switch that falls on a communication point acts exactly at that point in every host,
whatever rounding its time arithmetic carries: a host that accumulates ``t += h`` is 1.4e-11 s
off at 100 s with h = 10 ms (measured with Ecos), far inside both tolerances. Events that are
not on the grid are resolved at the integration stage; an event closer than ``STEP_TOL * h`` to
a step end is taken at that end.
"""
from __future__ import annotations

STEP_TOL = 1e-6  # inside a step: relative to the step h
POINT_TOL = 1e-9  # at a communication point: relative to max(1, |t|)


# The rule as plain float functions: the reference code calls them (through StepWindow) and the
# kernels compile these very functions (plant/kernels/common.py: window, active, contains, happened).
def step_bounds(t: float, h: float) -> tuple:
    """(lo, hi) of the step [t, t + h]: events at or before ``lo`` happened before the step, events
    at or after ``hi`` happen after it."""
    tol = STEP_TOL * h
    return t + tol, t + h - tol


def event_active(T: float, tau: float, lo: float, hi: float) -> bool:
    """True if an event at ``T`` has happened for the stage at time ``tau`` of the step (lo, hi)."""
    if T <= lo:
        return True
    if T >= hi:
        return False
    return tau >= T


def event_inside(T: float, lo: float, hi: float) -> bool:
    """True if ``T`` lies strictly inside the step (lo, hi) (the value changes during it)."""
    return lo < T and T < hi


class StepWindow:
    """Where events fall relative to one communication step [t, t + h]."""

    __slots__ = ("t", "h", "lo", "hi")

    def __init__(self, t: float, h: float):
        self.t, self.h = t, h
        self.lo, self.hi = step_bounds(t, h)

    def active(self, T: float, tau: float) -> bool:
        """True if an event at ``T`` has happened for the stage at time ``tau`` of this step."""
        return event_active(T, tau, self.lo, self.hi)

    def contains(self, T: float) -> bool:
        """True if ``T`` lies strictly inside the step (the value changes during it)."""
        return event_inside(T, self.lo, self.hi)


def happened_at(T: float, t: float) -> bool:
    """True if an event at ``T`` has happened at the communication point ``t`` (from the right)."""
    return T <= t + POINT_TOL * max(1.0, abs(t))

