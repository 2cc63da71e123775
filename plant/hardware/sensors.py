"""Sampled attitude sensors with seeded noise: rate gyro, star tracker, single-axis angle sensor.

Every sensor samples at its own instants t_k = t0 + k ``sample_period`` (``sampling.SampleClock``)
and holds the last measurement in between (zero-order hold, what a flight computer reading the
sensor's last output sees). At a communication point that is a sample instant the measurement is
formed from the input at that point (direct feedthrough); a sample instant strictly inside a
communication step uses the input held over the step. ``t_next_sample`` announces the next
instant (a master that lands on it samples exactly).

Noise is drawn in advance: the noise of sample k is in the state before the sample is taken, so
``outputs_at`` stays pure, and the PCG64 stream's state is part of the block's state (exact
rollback; the same ``seed`` gives the same noise in every host and every rerun).

* :class:`RateGyro`: the discrete form of Farrenkopf's gyro model as Markley & Crassidis give it
  (*Fundamentals of Spacecraft Attitude Determination and Control*, Springer 2014, gyro models),
  plus a Gauss-Markov term for the bias instability of data sheets:

      omega_m,k = omega(t_k) + 1/2 (beta_k + beta_k+1) + g_k + n_k,
      beta_k+1  = beta_k + sigma_u sqrt(T) w_k                  (rate random walk, sigma_u rad/s^1.5)
      n_k       ~ N(0, sigma_v^2 / T + sigma_u^2 T / 12)        (angle random walk sigma_v rad/s^0.5,
                                                                  the sample's average over T)
      g_k+1     = phi g_k + sigma_b sqrt(1 - phi^2) w'_k,  phi = exp(-T / tau_b)
                                                                 (bias instability as a first-order
                                                                  Gauss-Markov process, sigma_b rad/s,
                                                                  correlation time tau_b; stationary from
                                                                  k = 0; sigma_b = 0 switches it off)

  with beta_0 = ``bias_init``. Output ``bias`` is the ground truth 1/2 (beta_k + beta_k+1) + g_k of
  the held sample.
* :class:`StarTracker`: q_m = dq (x) q (composition with C(dq (x) q) = C(dq) C(q)), dq the rotation
  by the small body-frame angles dtheta_k = b + [sigma_cross n_1, sigma_cross n_2, sigma_roll n_3]
  with the roll component about the ``boresight`` body axis (white noise per sample plus a constant
  bias b; the usual star-tracker error model, Markley & Crassidis ch. 5: the error about the
  boresight several times the cross-boresight one). q_m has the hemisphere of q (q_m . q >= 0).
* :class:`AngleSensor`: theta_m = theta + b + sigma n_k on each axis (a single-axis attitude
  sensor for the pitch-axis plants of 002/003: the star tracker's error about one axis).

The parameter sets behind the arena's defaults are in ``plant/hardware/datasheets.py`` (cited).
"""
from __future__ import annotations

import math

import numpy as np

from ..block import Block, scalar, vector
from ..channels import channels
from ..so3 import rotation_matrix
from .sampling import NormalStream, SampleClock, check_seed

__all__ = ["SampledSensor", "RateGyro", "StarTracker", "AngleSensor", "compose"]


def compose(p, q) -> np.ndarray:
    """p (x) q for scalar-first quaternions with C(p (x) q) = C(p) C(q) (C of plant/so3.py):
    [p0 q0 - p_v.q_v, p0 q_v + q0 p_v - p_v x q_v]."""
    p0, p1, p2, p3 = p
    q0, q1, q2, q3 = q
    return np.array([p0 * q0 - p1 * q1 - p2 * q2 - p3 * q3,
                     p0 * q1 + q0 * p1 - (p2 * q3 - p3 * q2),
                     p0 * q2 + q0 * p2 - (p3 * q1 - p1 * q3),
                     p0 * q3 + q0 * p3 - (p1 * q2 - p2 * q1)])


def small_rotation(theta) -> np.ndarray:
    """The quaternion of the frame rotation by the angle vector theta (rad): [cos(a/2), sin(a/2) e]."""
    a = math.sqrt(float(theta[0]) ** 2 + float(theta[1]) ** 2 + float(theta[2]) ** 2)
    if a == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    s = math.sin(0.5 * a) / a
    return np.array([math.cos(0.5 * a), s * theta[0], s * theta[1], s * theta[2]])


class SampledSensor(Block):
    """Base of the sensors: the sample clock, the held measurement and the noise stream.

    Subclasses give ``measure(u)`` (the measurement of the due sample, from the state and the input,
    pure), ``next_sample()`` (draw what the next sample needs), ``truth()`` (ground-truth outputs of
    the held sample) and their extra state (``extra_state`` / ``set_extra_state``)."""

    announced_instants = ("t_next_sample",)
    n_measured = 0

    def __init__(self, inputs, outputs, params, feedthrough):
        params = (params + scalar("sample_period", 0.1, "s", "time between samples T")
                  + scalar("seed", 0, "1", "seed of the noise stream (PCG64)"))
        super().__init__(inputs, outputs + scalar("t_next_sample", 0.0, "s", "announced instant: next sample"),
                         params, feedthrough)
        self.clock = None
        self.stream = None
        self.y_held = np.zeros(self.n_measured)

    def initialize(self, t0: float) -> None:
        self.clock = SampleClock(t0, self.p("sample_period"), self.model_name)
        self.stream = NormalStream(check_seed(self.p("seed"), self.model_name))
        self.initialize_sensor(t0)
        self.y_held = self.measure(self.default_inputs())  # replaced by the first sample at t0

    # -- the sampling --------------------------------------------------------------------------------
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        c = self.clock
        if c.due(t):
            return np.concatenate((self.measure(u), self.truth(True), (c.t0 + (c.k + 1) * c.T,)))
        return np.concatenate((self.y_held, self.truth(False), (c.t_next,)))

    def _take(self, u) -> None:
        self.y_held = self.measure(u)
        self.latch_truth()
        self.next_sample()
        self.clock.k += 1

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        if self.clock.due(t):
            self._take(u)
        while self.clock.inside(t, h):  # an instant inside the step: the input held over it
            self._take(u)

    def get_state(self) -> list:
        return [float(self.clock.k)] + self.y_held.tolist() + self.extra_state() + self.stream.get_state()

    def set_state(self, state) -> None:
        s = list(state)
        m = self.n_measured
        self.clock.k = int(s[0])
        self.y_held = np.array(s[1:1 + m], dtype=float)
        n_rng = NormalStream.STATE_FLOATS
        self.set_extra_state(s[1 + m:len(s) - n_rng])
        self.stream.set_state(s[len(s) - n_rng:])

    # -- what the subclasses give ----------------------------------------------------------------------
    def initialize_sensor(self, t0: float) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def measure(self, u) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def next_sample(self) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def truth(self, due: bool) -> np.ndarray:
        """Ground-truth outputs: of the sample being taken (``due``) or of the held one."""
        return np.zeros(0)

    def latch_truth(self) -> None:
        pass

    def extra_state(self) -> list:
        return []

    def set_extra_state(self, values) -> None:
        pass


class RateGyro(SampledSensor):
    """Rate gyro on n axes: ARW, rate random walk, Gauss-Markov bias instability (module docstring).

    Inputs:  omega[1..n] rad/s (true body rate; ``omega`` for n = 1)
    Outputs: omega_m[1..n] rad/s (held measurement), bias[1..n] rad/s (its bias, ground truth),
             t_next_sample s
    Parameters: arw sigma_v, rrw sigma_u (declared in rad/s: the 1-sigma rate noise of a 1 s average and
             the 1-sigma bias change over 1 s, numerically sigma_v in rad/s^0.5 and sigma_u in rad/s^1.5,
             units FMI cannot write), bi_sigma sigma_b (rad/s),
             bi_tau tau_b (s), bias_init[1..n] (rad/s), sample_period (s), seed
    """

    model_name = "RateGyro"
    description = "Rate gyro: angle random walk, rate random walk, Gauss-Markov bias instability, sampled, seeded"

    def __init__(self, n_axes: int = 3):
        n = self.n = self.n_measured = int(n_axes)
        if n < 1:
            raise ValueError(f"n_axes must be >= 1, got {n_axes}")
        inputs = channels("omega", n, "rad/s", "true body rate")
        outputs = (channels("omega_m", n, "rad/s", "measured body rate (held between samples)")
                   + channels("bias", n, "rad/s", "bias of the held measurement (ground truth)"))
        params = (scalar("arw", 0.0, "rad/s", "angle random walk sigma_v: 1-sigma noise of a 1 s rate average "
                                                 "(numerically sigma_v in rad/s^0.5)")
                  + scalar("rrw", 0.0, "rad/s", "rate random walk sigma_u: 1-sigma bias change over 1 s "
                                                "(numerically sigma_u in rad/s^1.5)")
                  + scalar("bi_sigma", 0.0, "rad/s", "bias instability: Gauss-Markov standard deviation")
                  + scalar("bi_tau", 3600.0, "s", "bias instability: Gauss-Markov correlation time")
                  + channels("bias_init", n, "rad/s", "initial bias beta_0"))
        names = [v.name for v in inputs]
        feed = {v.name: [names[i]] for i, v in enumerate(outputs[:n])}
        super().__init__(inputs, outputs, params, feed)

    def initialize_sensor(self, t0: float) -> None:
        n, T = self.n, self.p("sample_period")
        self.sv, self.su, self.sb, self.tau = self.p("arw"), self.p("rrw"), self.p("bi_sigma"), self.p("bi_tau")
        for name in ("arw", "rrw", "bi_sigma"):
            if self.p(name) < 0:
                raise ValueError(f"{self.model_name}: {name} = {self.p(name):g} must be >= 0")
        if not self.tau > 0:
            raise ValueError(f"{self.model_name}: bi_tau = {self.tau:g} s must be > 0")
        self.sn = math.sqrt(self.sv ** 2 / T + self.su ** 2 * T / 12.0)  # sigma_v, sigma_u per 1 s
        self.sw = self.su * math.sqrt(T)
        self.phi = math.exp(-T / self.tau)
        self.sg = self.sb * math.sqrt(max(0.0, 1.0 - self.phi * self.phi))
        self.beta = self.p_vector("bias_init") if n > 1 else np.array([self.p("bias_init")])
        w = self.stream.draw(3 * n)
        self.beta_next = self.beta + self.sw * w[0:n]
        self.g = self.sb * w[n:2 * n]  # stationary from the start
        self.noise = self.sn * w[2 * n:]
        self.b_held = 0.5 * (self.beta + self.beta_next) + self.g

    def measure(self, u) -> np.ndarray:
        return np.asarray(u[0:self.n], dtype=float) + 0.5 * (self.beta + self.beta_next) + self.g + self.noise

    def latch_truth(self) -> None:
        self.b_held = 0.5 * (self.beta + self.beta_next) + self.g

    def truth(self, due: bool) -> np.ndarray:
        return 0.5 * (self.beta + self.beta_next) + self.g if due else self.b_held

    def next_sample(self) -> None:
        n = self.n
        w = self.stream.draw(3 * n)
        self.beta = self.beta_next
        self.beta_next = self.beta + self.sw * w[0:n]
        self.g = self.phi * self.g + self.sg * w[n:2 * n]
        self.noise = self.sn * w[2 * n:]

    def extra_state(self) -> list:
        return self.beta.tolist() + self.beta_next.tolist() + self.g.tolist() + self.noise.tolist() + self.b_held.tolist()

    def set_extra_state(self, values) -> None:
        n = self.n
        v = np.array(values, dtype=float)
        self.beta, self.beta_next, self.g, self.noise, self.b_held = (v[i * n:(i + 1) * n].copy() for i in range(5))


class StarTracker(SampledSensor):
    """Star tracker: attitude quaternion with cross-boresight / about-boresight noise (module docstring).

    Inputs:  q[0..3] 1 (true attitude, scalar first)
    Outputs: q_m[0..3] 1 (held measurement), t_next_sample s
    Parameters: sigma_cross (rad), sigma_roll (rad), boresight (1: body axis 1, 2 or 3),
             bias[1..3] (rad, constant error angles), sample_period (s), seed
    """

    model_name = "StarTracker"
    description = "Star tracker: quaternion with cross-/about-boresight white noise and bias, sampled, seeded"

    def __init__(self):
        self.n_measured = 4
        inputs = vector("q", 4, "1", "true attitude quaternion, scalar first", [1, 0, 0, 0], first=0)
        outputs = vector("q_m", 4, "1", "measured attitude quaternion (held between samples)", [1, 0, 0, 0], first=0)
        params = (scalar("sigma_cross", 0.0, "rad", "1-sigma noise about the two cross-boresight axes")
                  + scalar("sigma_roll", 0.0, "rad", "1-sigma noise about the boresight")
                  + scalar("boresight", 3, "1", "body axis of the boresight (1, 2 or 3)")
                  + vector("bias", 3, "rad", "constant error angles (body axes)"))
        qs = [v.name for v in inputs]
        super().__init__(inputs, outputs, params, {v.name: qs for v in outputs})

    def initialize_sensor(self, t0: float) -> None:
        axis = self.p("boresight")
        if axis not in (1.0, 2.0, 3.0):
            raise ValueError(f"{self.model_name}: boresight = {axis:g} must be 1, 2 or 3")
        for name in ("sigma_cross", "sigma_roll"):
            if self.p(name) < 0:
                raise ValueError(f"{self.model_name}: {name} = {self.p(name):g} rad must be >= 0")
        sigma = np.full(3, self.p("sigma_cross"))
        sigma[int(axis) - 1] = self.p("sigma_roll")
        self.sigma, self.bias = sigma, self.p_vector("bias")
        self.noise = self.sigma * self.stream.draw(3)

    def measure(self, u) -> np.ndarray:
        q = np.asarray(u[0:4], dtype=float)
        nq = math.sqrt(float(q @ q))
        if not nq > 0:
            raise ValueError(f"{self.model_name}: input q has norm {nq:g}")
        q = q / nq
        qm = compose(small_rotation(self.bias + self.noise), q)
        return -qm if float(qm @ q) < 0.0 else qm

    def next_sample(self) -> None:
        self.noise = self.sigma * self.stream.draw(3)

    def extra_state(self) -> list:
        return self.noise.tolist()

    def set_extra_state(self, values) -> None:
        self.noise = np.array(values, dtype=float)

    @staticmethod
    def error_angles(q_true, q_meas) -> np.ndarray:
        """The angle vector dtheta (rad, |dtheta| < pi/2) with C(q_meas) = C(dq) C(q_true), dq the
        frame rotation by dtheta (for checks): the skew part of E = C(q_meas) C(q_true)^T is
        -sin|dtheta| e^x."""
        E = rotation_matrix(q_meas) @ rotation_matrix(q_true).T
        v = 0.5 * np.array([E[1, 2] - E[2, 1], E[2, 0] - E[0, 2], E[0, 1] - E[1, 0]])
        s = float(np.linalg.norm(v))
        return v if s == 0.0 else v * (math.asin(min(1.0, s)) / s)


class AngleSensor(SampledSensor):
    """Angle sensor on n axes: theta_m = theta + b + sigma n_k (module docstring).

    Inputs:  theta[1..n] rad (``theta`` for n = 1)
    Outputs: theta_m[1..n] rad (held measurement), t_next_sample s
    Parameters: sigma (rad), bias[1..n] (rad), sample_period (s), seed
    """

    model_name = "AngleSensor"
    description = "Single-axis attitude sensor: angle with white noise and bias, sampled, seeded"

    def __init__(self, n_axes: int = 1):
        n = self.n = self.n_measured = int(n_axes)
        inputs = channels("theta", n, "rad", "true angle")
        outputs = channels("theta_m", n, "rad", "measured angle (held between samples)")
        params = scalar("sigma", 0.0, "rad", "1-sigma white noise") + channels("bias", n, "rad", "constant bias")
        names = [v.name for v in inputs]
        super().__init__(inputs, outputs, params, {v.name: [names[i]] for i, v in enumerate(outputs)})

    def initialize_sensor(self, t0: float) -> None:
        self.sigma = self.p("sigma")
        if self.sigma < 0:
            raise ValueError(f"{self.model_name}: sigma = {self.sigma:g} rad must be >= 0")
        self.bias = self.p_vector("bias") if self.n > 1 else np.array([self.p("bias")])
        self.noise = self.sigma * self.stream.draw(self.n)

    def measure(self, u) -> np.ndarray:
        return np.asarray(u[0:self.n], dtype=float) + self.bias + self.noise

    def next_sample(self) -> None:
        self.noise = self.sigma * self.stream.draw(self.n)

    def extra_state(self) -> list:
        return self.noise.tolist()

    def set_extra_state(self, values) -> None:
        self.noise = np.array(values, dtype=float)
