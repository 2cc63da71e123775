"""Sensor faults (issue 34 item 5): a block between a sensor and what reads it, as
``plant/fault_catalog.py`` is for the actuators. The sensor (``plant/hardware/sensors.py``, or the
plant's ideal output) stays healthy; the block delivers the faulty measurement and logs the fault's
ground truth.

:class:`GyroFault` on n rate axes (input omega_m, the gyro's measurement), by ``fault_class``
(onset T = ``onset``; the fault ends at T + ``duration`` if ``duration`` > 0, else never; faulty
axes: ``channel`` = j, or every axis: 0):

====  ==================  ==================================================================
 0    none                omega_f = omega_m
 1    bias step           omega_f = omega_m + ``magnitude`` (rad/s) from T on
 2    drift ramp          omega_f = omega_m + ``rate`` (t - T) (rate in rad/s^2) from T on
 3    stuck               omega_f frozen from T on at the measurement of the first communication point at or
                          after T (``stuck_mode`` 0), or at ``magnitude`` (1)
====  ==================  ==================================================================

Outputs: omega_f (delivered), fault = omega_f - omega_m (ground truth, rad/s), active, t_next_event.

:class:`StarTrackerFault` (input q_m, the tracker's quaternion), by ``fault_class``:

====  ==================  ==================================================================
 0    none                q_f = q_m, valid = 1
 1    outage              from T on the tracker delivers no attitude: valid = 0 and q_f holds the
                          measurement of the first communication point at or after T (what a reader
                          that ignores the flag sees: a stale attitude)
 2    frozen output       q_f frozen the same way, but valid stays 1 (a silent failure)
====  ==================  ==================================================================

Outputs: q_f, valid, fault_angle (rad: the rotation angle between q_f and q_m, ground truth), active,
t_next_event.

Timing as the actuator catalog's: an event at T acts from the first communication point t with
``happened_at(T, t)`` (plant/timing.py); the drift ramp is evaluated at the communication points
(held over the step, like every output); ``t_next_event`` announces onset and end, so a multirate
master lands on them. State: the frozen value and whether it is latched (rollback-safe).
"""
from __future__ import annotations

import math

import numpy as np

from .block import Block, scalar, vector
from .channels import channels
from .markov import T_NEVER
from .timing import happened_at

__all__ = ["GyroFault", "StarTrackerFault", "GYRO_FAULTS", "STAR_TRACKER_FAULTS", "rotation_angle"]

GYRO_NONE, GYRO_BIAS, GYRO_DRIFT, GYRO_STUCK = range(4)
GYRO_FAULTS = {GYRO_NONE: "none", GYRO_BIAS: "gyro bias step", GYRO_DRIFT: "gyro drift ramp", GYRO_STUCK: "gyro stuck"}
ST_NONE, ST_OUTAGE, ST_FROZEN = range(3)
STAR_TRACKER_FAULTS = {ST_NONE: "none", ST_OUTAGE: "star-tracker outage", ST_FROZEN: "star-tracker frozen output"}


def rotation_angle(p, q) -> float:
    """The angle (rad, in [0, pi]) of the rotation between the attitudes of unit quaternions p and q
    (scalar first): 2 acos |p . q|, computed as 2 atan2 of the vector and scalar parts' sizes."""
    p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
    c = abs(float(p @ q))
    s = math.sqrt(max(0.0, float(p @ p) * float(q @ q) - c * c))
    return 2.0 * math.atan2(s, c)


class _Timed(Block):
    """Onset, duration and the frozen value shared by the sensor-fault blocks."""

    announced_instants = ("t_next_event",)
    n_held = 0
    classes: dict = {}

    def _int(self, name: str, lo: int, hi: int) -> int:
        x = self.p(name)
        if x != round(x) or not lo <= x <= hi:
            raise ValueError(f"{self.model_name}: parameter '{name}' = {x:g} must be an integer in {lo}..{hi}")
        return int(round(x))

    def initialize_timing(self) -> None:
        self.cls = self._int("fault_class", 0, max(self.classes))
        self.onset, self.duration = self.p("onset"), self.p("duration")
        if not self.duration >= 0 or not math.isfinite(self.onset):
            raise ValueError(f"{self.model_name}: duration = {self.duration:g} s must be >= 0 (0: permanent)")
        self.end = self.onset + self.duration if self.duration > 0 else T_NEVER
        self.frozen = np.zeros(self.n_held)
        self.latched = False

    def on(self, t: float) -> bool:
        """Is the fault in force at the communication point t?"""
        return self.cls != 0 and happened_at(self.onset, t) and not happened_at(self.end, t)

    def next_event(self, t: float) -> float:
        if self.cls == 0:
            return T_NEVER
        if not happened_at(self.onset, t):
            return self.onset
        return self.end if not happened_at(self.end, t) else T_NEVER

    def held(self, t: float, x) -> np.ndarray:
        """The frozen value at t: latched in ``advance``; at the onset point, the input now."""
        return self.frozen if self.latched else np.asarray(x, dtype=float)

    def latch(self, t: float, x) -> None:
        if not self.latched and self.freezes() and self.on(t):
            self.frozen = np.array(x, dtype=float)
            self.latched = True
        elif self.latched and not self.on(t):
            self.latched = False  # the fault ended

    def freezes(self) -> bool:  # pragma: no cover - abstract
        raise NotImplementedError

    def get_state(self) -> list:
        return [1.0 if self.latched else 0.0] + self.frozen.tolist()

    def set_state(self, state) -> None:
        s = list(state)
        self.latched = s[0] == 1.0
        self.frozen = np.array(s[1:1 + self.n_held], dtype=float)


class GyroFault(_Timed):
    """Gyro faults on n axes: bias step, drift ramp, stuck (module docstring).

    Inputs:  omega_m[1..n] rad/s (``omega_m`` for n = 1)
    Outputs: omega_f[1..n] rad/s, fault[1..n] rad/s (omega_f - omega_m), active 1, t_next_event s
    Parameters: fault_class, channel, onset (s), duration (s, 0 permanent), magnitude (rad/s),
             rate (rad/s^2), stuck_mode
    """

    model_name = "GyroFault"
    description = "Gyro faults: bias step, drift ramp, stuck, with the fault's ground truth"
    classes = GYRO_FAULTS

    def __init__(self, n_axes: int = 3):
        n = self.n = self.n_held = int(n_axes)
        if n < 1 or n != n_axes:
            raise ValueError(f"n_axes must be an integer >= 1, got {n_axes}")
        inputs = channels("omega_m", n, "rad/s", "measured body rate (the gyro's output)")
        outputs = (channels("omega_f", n, "rad/s", "body rate delivered by the faulty gyro")
                   + channels("fault", n, "rad/s", "omega_f - omega_m (ground truth)")
                   + scalar("active", 0.0, "1", "1 while the fault is in force")
                   + scalar("t_next_event", T_NEVER, "s", "announced instant: next onset or end"))
        params = (scalar("fault_class", 0, "1", "0 none, 1 bias step, 2 drift ramp, 3 stuck")
                  + scalar("channel", 0, "1", f"faulty axis 1..{n} (0: every axis)")
                  + scalar("onset", 0.0, "s", "fault onset T")
                  + scalar("duration", 0.0, "s", "fault duration (0: permanent)")
                  + scalar("magnitude", 0.0, "rad/s", "class 1: bias; class 3 with stuck_mode 1: stuck value")
                  + scalar("rate", 0.0, "rad/s2", "class 2: drift rate")
                  + scalar("stuck_mode", 0, "1", "class 3: 0 frozen at the measurement at onset, 1 at magnitude"))
        names = [v.name for v in inputs]
        feed = {v.name: [names[i % n]] for i, v in enumerate(outputs[:2 * n])}
        super().__init__(inputs, outputs, params, feed)
        self.frozen = np.zeros(n)
        self.latched = False

    def initialize(self, t0: float) -> None:
        self.initialize_timing()
        ch = self._int("channel", 0, self.n)
        self.mask = np.ones(self.n, dtype=bool) if ch == 0 else np.arange(self.n) == ch - 1
        self.magnitude, self.rate = self.p("magnitude"), self.p("rate")
        self.stuck_mode = self._int("stuck_mode", 0, 1)

    def freezes(self) -> bool:
        return self.cls == GYRO_STUCK and self.stuck_mode == 0

    def delivered(self, t: float, omega_m) -> np.ndarray:
        w = np.asarray(omega_m, dtype=float)
        if not self.on(t):
            return w.copy()
        out, m = w.copy(), self.mask
        if self.cls == GYRO_BIAS:
            out[m] += self.magnitude
        elif self.cls == GYRO_DRIFT:
            out[m] += self.rate * (t - self.onset)
        elif self.cls == GYRO_STUCK:
            out[m] = self.magnitude if self.stuck_mode == 1 else self.held(t, w)[m]
        return out

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        w = np.asarray(u[0:self.n], dtype=float)
        f = self.delivered(t, w)
        return np.concatenate((f, f - w, (1.0 if self.on(t) else 0.0, self.next_event(t))))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        self.latch(t, u[0:self.n])


class StarTrackerFault(_Timed):
    """Star-tracker outage and frozen output (module docstring).

    Inputs:  q_m[0..3] 1 (the tracker's quaternion, scalar first)
    Outputs: q_f[0..3] 1, valid 1, fault_angle rad, active 1, t_next_event s
    Parameters: fault_class, onset (s), duration (s, 0 permanent)
    """

    model_name = "StarTrackerFault"
    description = "Star-tracker faults: outage (invalid, stale attitude) and frozen output, with the fault's ground truth"
    classes = STAR_TRACKER_FAULTS
    n_held = 4

    def __init__(self):
        inputs = vector("q_m", 4, "1", "measured attitude quaternion (the tracker's output)", [1, 0, 0, 0], first=0)
        outputs = (vector("q_f", 4, "1", "attitude quaternion delivered by the faulty tracker", [1, 0, 0, 0], first=0)
                   + scalar("valid", 1.0, "1", "1: the tracker reports a valid attitude; 0 in an outage")
                   + scalar("fault_angle", 0.0, "rad", "rotation angle between q_f and q_m (ground truth)")
                   + scalar("active", 0.0, "1", "1 while the fault is in force")
                   + scalar("t_next_event", T_NEVER, "s", "announced instant: next onset or end"))
        params = (scalar("fault_class", 0, "1", "0 none, 1 outage, 2 frozen output")
                  + scalar("onset", 0.0, "s", "fault onset T")
                  + scalar("duration", 0.0, "s", "fault duration (0: permanent)"))
        qs = [v.name for v in inputs]
        feed = {v.name: qs for v in outputs[:4]}
        feed["fault_angle"] = qs
        super().__init__(inputs, outputs, params, feed)
        self.frozen = np.array([1.0, 0.0, 0.0, 0.0])
        self.latched = False

    def initialize(self, t0: float) -> None:
        self.initialize_timing()
        self.frozen = np.array([1.0, 0.0, 0.0, 0.0])

    def freezes(self) -> bool:
        return self.cls in (ST_OUTAGE, ST_FROZEN)

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        q = np.asarray(u[0:4], dtype=float)
        on = self.on(t)
        qf = self.held(t, q).copy() if on else q.copy()
        valid = 0.0 if (on and self.cls == ST_OUTAGE) else 1.0
        return np.concatenate((qf, (valid, rotation_angle(qf, q) if on else 0.0, 1.0 if on else 0.0, self.next_event(t))))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        self.latch(t, u[0:4])


# -- factories of the catalog FMUs (diagnosis/catalog.py lists them) ---------------------------------
def gyro_fault_3() -> GyroFault:
    b = GyroFault(3)
    b.model_name = "GyroFault3"
    return b


def star_tracker_fault() -> StarTrackerFault:
    return StarTrackerFault()
