"""T-S fuzzy disturbance observer (TSFDO), 003 (3.1), for a single-axis (pitch) plant.

Disturbance model, 003 (2.6)-(2.7): rule j, w' = W_j w, d0 = V_j w, blended with normalised
memberships h_j (``plant/fuzzy.py``). Plant 003 (2.4): x = [theta, theta'], x' = A x + B0 (rho u + d0)
+ B1 d1, A = [[0, 1], [0, 0]], B0 = B1 = [0; (J - F F^T)^-1]. Observer, 003 (3.1):

    eps'  = sum_j h_j (W_j + L1 B0 V_j) (eps - L1 x) + L1 [A x + B0 u]
    w_hat = eps - L1 x
    d0_hat = sum_j h_j V_j w_hat

with u the commanded torque (the fault rho is unknown to the observer). Its error e_w = w - w_hat
obeys 003 (3.3), e_w' = sum_j h_j [(W_j + L1 B0 V_j) e_w - L1 B0 (1 - rho) u + L1 B1 d1]; so with a fast
gain d0_hat estimates the lumped torque d0 + d1 - (1 - rho) u, not d0 alone.

Readings chosen (003 is silent or garbled here; see papers/p003_hang2023/README.md):

* Gain, rule matrices, memberships: parameters (``L1[i,j]``, ``W[r,i,j]``, ``V[r,1,j]``,
  ``mf_center[r]``, ``mf_sigma2[r]``); 003's numbers reach the block through
  ``papers/p003_hang2023/blocks.py``.
* Premise z1 of the memberships (003 never defines it): ``premise`` = 0 theta (default), 1 theta',
  2 w_hat_1, taken at the communication point and held over the step.
* Initial value: eps(t0) = ``w_hat_init`` + L1 x(t0), i.e. w_hat(t0) = w_hat_init (default 0); set from
  the first measurement the block sees ("priming" at the first ``advance``; the primed flag is
  part of the state).
* Sampling (``sampling_mode``): the observer is continuous; in co-simulation x is known at the
  communication points only. Mode 1 (default) replaces x inside the step by the observer's own
  prediction x_hat' = A x_hat + B0 (u + d0_hat), x_hat(t_k) = x_k; then w_hat' = sum_j h_j W_j w_hat
  inside the step and the correction -L1 (x_k - x_hat(t_k^-)) acts at the sampling instants.
  Mode 0 holds x = x_k over the step (the continuous observer fed a zero-order-held measurement).
* Integration in the coordinates (w_hat, x_hat) (w_hat = eps - L1 x_hat): an exact linear change of
  variables of (3.1), under which RK4 gives the same result, without the stiff cancellation between
  eps and L1 x (|L1| ~ 2e4 for the published gain).
* Step-size limit: in mode 1 the observer error e_w = w - w_hat at the communication points obeys
  e_w(t_k+1) = D(h) e_w(t_k) + (terms in w, x) for a disturbance from the blended exosystem, with D(h)
  from the block's own RK4 stages (:func:`sampled_error_map`); u cancels. To first order in h the
  correction is d0_hat+ = d0_hat - (V L1 B0) h (d - d0_hat), stable for h < 2 / |V L1 B0|. For 003's
  published L1 the exact limit rho(D(h)) = 1 is 1.51 ms at the premise theta ~ 0 (1.19 ms for rule 1
  alone, 1.59 ms for rule 2), and the closed loop with plant and ASMFTC diverges between 1.508 and
  1.512 ms; for our designed L1 the map gives 204 ms and the loop diverges between 196.3 and 196.9 ms
  (the modal torque then depends on the command within a step). In mode 0 u does not cancel (the
  stiff error matrix relaxes inside the step), and the loop limit is 1.543-1.549 ms (published) and
  0.20-0.25 s (designed): the mode-1 map is a conservative proxy there. Measurements:
  papers/p003_hang2023/README.md. ``step_check`` = 2 (default) refuses a communication step h with
  h > ``step_fraction`` * limit (rho(D(h / step_fraction)) >= 1) at the current memberships, with a
  ValueError naming the limit; 1 only warns; 0 does not check. ``step_fraction`` = 0.95 keeps both
  gains' loops on the safe side of their measured limits. A warning names a rule whose own limit the
  step exceeds (the loop would diverge if the premise moved there). The check is repeated when the
  step or the memberships change (by more than 0.005).

Integration: RK4 with internal step <= ``h_max`` (s), inputs held (the RK4 loop runs compiled,
``plant/kernels/common.py: rk4_affine``, when kernels are on; the numpy loop is the reference); the memberships are frozen over
the step. Mode 0 integrates the stiff error matrix W_j + L1 B0 V_j (fastest pole -1651 1/s with the
published L1): RK4 needs h_max * 1651 < 2.78, i.e. h_max < 1.7 ms; ``initialize`` refuses an h_max
outside RK4's stability region for the gain in use. Mode 1's integration is not stiff (its
eigenvalues are those of W_j and of A).

Inputs:  theta (rad), theta_dot (rad/s)   measured x
         u (N.m)                          commanded torque
Outputs: d0_hat (N.m)                     sum_j h_j V_j w_hat (feedthrough from theta, theta_dot)
         w_hat[1..m] (1)                  exosystem state estimate
         membership[1..r] (1)             h_j at the communication point
"""
from __future__ import annotations

import warnings

import numpy as np

from plant import kernels
from plant.block import Block, Variable, rule_tensor, scalar, vector
from plant.fuzzy import Gaussian
from plant.integrate import h_max_parameter, rk4_step, substeps
from plant.kernels import common as _common
from plant.pitch_axis import pitch_inputs, pitch_parameters

RK4_REAL_LIMIT = 2.785  # RK4 is stable for real h*lambda in (-2.785, 0]


def sampled_error_map(Wb, Vb, L1, b0, h, steps, mode=1) -> np.ndarray:
    """D(h): the observer error e_w = w - w_hat from one communication point to the next, for a
    disturbance d = Vb w from the exosystem w' = Wb w (frozen blend), the double integrator
    x' = A x + B0 d, the observer (3.1) held over the step as the block does it (``mode`` 0 or 1) and
    ``steps`` RK4 substeps. Stable sampling iff the spectral radius of D is < 1. u cancels in e_w."""
    Wb = np.asarray(Wb, float)
    m = Wb.shape[0]
    Vb = np.asarray(Vb, float).reshape(1, m)
    L1 = np.asarray(L1, float).reshape(m, 2)
    A = np.array([[0.0, 1.0], [0.0, 0.0]])
    B0 = np.array([[0.0], [float(b0)]])
    M = Wb + L1 @ B0 @ Vb
    iw, ix, ie, iz = slice(0, m), slice(m, m + 2), slice(m + 2, 2 * m + 2), slice(2 * m + 2, 2 * m + 4)
    n = 2 * m + 4  # [w, x, eps, z]: z = x_k held (mode 0) or the prediction x_hat (mode 1)
    G = np.zeros((n, n))
    G[iw, iw] = Wb
    G[ix, ix] = A
    G[ix, iw] = B0 @ Vb
    G[ie, ie] = M
    G[ie, iz] = -M @ L1 + L1 @ A  # eps' = M (eps - L1 z) + L1 A z  (u = 0: it cancels in e_w)
    if mode == 1:  # x_hat' = A x_hat + B0 Vb (eps - L1 x_hat)
        G[iz, iz] = A - B0 @ Vb @ L1
        G[iz, ie] = B0 @ Vb
    dt = h / steps
    Gd = dt * G
    P = np.eye(n) + Gd @ (np.eye(n) + Gd @ (np.eye(n) / 2 + Gd @ (np.eye(n) / 6 + Gd / 24)))  # RK4 step
    Phi = np.linalg.matrix_power(P, steps)
    R = np.zeros((n, 2 * m + 2))  # [w, x, eps] -> [w, x, eps, x]
    R[: 2 * m + 2, : 2 * m + 2] = np.eye(2 * m + 2)
    R[iz, ix] = np.eye(2)
    K = Phi[: 2 * m + 2] @ R
    T = np.eye(2 * m + 2)  # [w, x, eps] <-> [w, x, e], e = w - eps + L1 x (T^-1 = T)
    T[ie, iw] = np.eye(m)
    T[ie, ix] = L1
    T[ie, ie] = -np.eye(m)
    return (T @ K @ T)[ie, ie]


class TSFDO(Block):
    model_name = "TSFDO"
    description = "T-S fuzzy disturbance observer, 003 (3.1), single axis"

    def __init__(self, n_rules: int = 2, n_w: int = 2, n_modes: int = 2):
        r, m, n = int(n_rules), int(n_w), int(n_modes)
        if r < 1 or m < 1 or n < 0:
            raise ValueError(f"{self.model_name}: n_rules >= 1, n_w >= 1, n_modes >= 0 required, got {r}, {m}, {n}")
        self.r, self.m, self.n = r, m, n
        inputs = pitch_inputs(target=False) + scalar("u", 0.0, "N.m", "commanded control torque")
        outputs = (
            scalar("d0_hat", 0.0, "N.m", "estimate of the modelled disturbance d0, 003 (3.1)")
            + vector("w_hat", m, "1", "estimate of the exosystem state w")
            + vector("membership", r, "1", "normalised membership h_j at the communication point")
        )
        params = (
            pitch_parameters(n, "model, for B0")
            + [Variable(f"L1[{i + 1},{j + 1}]", "1", "observer gain L1") for i in range(m) for j in range(2)]
            + rule_tensor("W", np.zeros((r, m, m)), "1/s", "exosystem matrix W_j, 003 (2.6)")
            + rule_tensor("V", np.zeros((r, 1, m)), "N.m", "output matrix V_j, 003 (2.6)")
            + vector("mf_center", r, "1", "centre of the Gaussian membership of rule j")
            + vector("mf_sigma2", r, "1", "variance sigma_j^2 of the Gaussian membership of rule j", [1.0] * r)
            + scalar("premise", 0, "1", "premise z1: 0 theta, 1 theta_dot, 2 w_hat[1]")
            + scalar("sampling_mode", 1, "1", "inside a step 1: predict x with the observer model, 0: hold x")
            + vector("w_hat_init", m, "1", "initial exosystem estimate")
            + h_max_parameter(5e-4)
            + scalar("step_check", 2, "1", "communication step above the stability limit: 2 error, 1 warning, 0 no check")
            + scalar("step_fraction", 0.95, "1", "fraction of the sampled-observer stability limit accepted as step")
        )
        x_in = ("theta", "theta_dot")
        feed = {v.name: x_in for v in outputs}
        super().__init__(inputs, outputs, params, feed)
        self.eps = np.zeros(m)
        self.primed = False
        self._warned = False
        self._last = None

    # -- set-up ---------------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        name = self.model_name
        J, F = self.p("J"), self.p_vector("F")
        if not J > 0:
            raise ValueError(f"{name}: J (pitch inertia) must be > 0 kg.m2, got {J:g}")
        je = J - float(F @ F)
        if not je > 0:
            raise ValueError(f"{name}: J - F F^T = {je:g} kg.m2 must be > 0")
        self.b0 = 1.0 / je
        self.B0 = np.array([0.0, self.b0])
        self.L1 = self.p_matrix("L1").reshape(self.m, 2)
        self.W = self.p_tensor("W").reshape(self.r, self.m, self.m)
        self.V = self.p_tensor("V").reshape(self.r, 1, self.m)
        self.mf = Gaussian(self.p_vector("mf_center"), self.p_vector("mf_sigma2"))  # checks sigma2 > 0
        self.premise = int(round(self.p("premise")))
        if self.premise not in (0, 1, 2):
            raise ValueError(f"{name}: premise must be 0 (theta), 1 (theta_dot) or 2 (w_hat[1]), got {self.p('premise'):g}")
        self.mode = int(round(self.p("sampling_mode")))
        if self.mode not in (0, 1):
            raise ValueError(f"{name}: sampling_mode must be 0 or 1, got {self.p('sampling_mode'):g}")
        self.h_max = self.p("h_max")
        if not self.h_max > 0:
            raise ValueError(f"{name}: h_max must be > 0 s, got {self.h_max:g}")
        self.check = int(round(self.p("step_check")))
        if self.check not in (0, 1, 2):
            raise ValueError(f"{name}: step_check must be 0, 1 or 2, got {self.p('step_check'):g}")
        # per rule: E_j = W_j + L1 B0 V_j (003 (3.3)), the blended error matrix is sum_j h_j E_j
        LB = self.L1 @ self.B0.reshape(2, 1)
        self.E = np.array([self.W[j] + LB @ self.V[j] for j in range(self.r)])
        m = self.m
        self._E_flat = self.E.reshape(self.r, -1)
        G1 = np.zeros((self.r, m + 2, m + 2))  # [[W_j, 0], [B0 V_j, A]] on z = [w_hat, x_hat]
        for j in range(self.r):
            G1[j, :m, :m] = self.W[j]
            G1[j, m + 1, :m] = self.b0 * self.V[j, 0]
            G1[j, m, m + 1] = 1.0
        self._G1_flat = G1.reshape(self.r, -1)
        self._g1 = np.zeros(m + 2)
        self._g1[m + 1] = self.b0
        self._V_flat = self.V[:, 0, :]
        self.fraction = self.p("step_fraction")
        if not 0.0 < self.fraction <= 1.0:
            raise ValueError(f"{name}: step_fraction must be in (0, 1], got {self.fraction:g}")
        self._checked = None  # (h, weights, weights as floats) of the last step-size check
        self._last = None  # (theta, theta_dot, eps, w_hat, weights) of the last outputs_at
        if self.mode == 0:
            fastest = max(max(abs(np.linalg.eigvals(Ej)).max() for Ej in self.E), 1e-300)
            if self.h_max * fastest > RK4_REAL_LIMIT:
                raise ValueError(f"{name}: h_max = {self.h_max:g} s is outside RK4's stability region for this gain "
                                 f"(fastest error pole {fastest:.4g} 1/s): use h_max <= {RK4_REAL_LIMIT / fastest:.3g} s")
        self._kernels = kernels.enabled()
        self.w_init = self.p_vector("w_hat_init")
        self.eps = self.w_init.copy()
        self.primed = False
        self._warned = False
        self._checked = None

    # -- helpers ----------------------------------------------------------------------------
    def _weights(self, x, w_hat) -> np.ndarray:
        z = (x[0], x[1], w_hat[0])[self.premise]
        return self.mf.weights((z,))

    def _w_hat(self, x) -> np.ndarray:
        return self.eps - self.L1 @ x if self.primed else self.w_init

    def error_radius(self, h: float, weights) -> float:
        """Spectral radius of the sampled (mode 1) error map D(h) for the memberships ``weights``."""
        w = np.asarray(weights, float)
        steps, _ = substeps(h, self.h_max)
        D = sampled_error_map(np.tensordot(w, self.W, axes=1), w @ self._V_flat, self.L1, self.b0, h, steps, 1)
        return float(np.abs(np.linalg.eigvals(D)).max())

    def stability_limit(self, weights, h_hi: float = 1.0) -> float:
        """Largest communication step (s) below h_hi with rho(D(h)) < 1 for ``weights`` (bisection)."""
        lo, hi = 0.0, float(h_hi)
        if self.error_radius(hi, weights) < 1.0:
            return hi
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.error_radius(mid, weights) < 1.0 else (lo, mid)
        return lo

    def check_step(self, h: float, weights) -> None:
        """Refuse (step_check = 2) or warn (1) when h is above step_fraction times the stability limit."""
        if self.check == 0:
            return
        last = self._checked
        if last is not None and abs(last[0] - h) <= 1e-9 * h and \
                max(abs(a - b) for a, b in zip(last[2], weights.tolist())) <= 0.005:
            return  # same step (up to the host's time arithmetic) and nearly the same memberships
        self._checked = (h, np.array(weights, float), [float(w) for w in weights])
        probe = h / self.fraction
        too_big = self.error_radius(probe, weights) >= 1.0
        rules = np.eye(self.r)
        bad_rules = [j for j in range(self.r) if self.error_radius(probe, rules[j]) >= 1.0] if last is None else []
        if not too_big and not bad_rules:
            return
        lim = self.stability_limit(weights, 2.0 * probe)
        per_rule = ", ".join(f"rule {j + 1}: {1e3 * self.stability_limit(rules[j], 4.0 * probe):.4g} ms"
                             for j in range(self.r))
        accepted = f"{self.fraction:g} x limit = {1e3 * self.fraction * lim:.4g} ms"
        if too_big:
            verdict = "the sampled loop diverges" if h >= lim else "too close to it"
            msg = (f"{self.model_name}: communication step {1e3 * h:.4g} ms is above the accepted step {accepted} "
                   f"(stability limit {1e3 * lim:.4g} ms of this observer gain at the current memberships; limits "
                   f"per rule: {per_rule}): {verdict}. Use a smaller step (step_check = 0 runs anyway)")
            if self.check == 2:
                raise ValueError(msg)
        else:
            msg = (f"{self.model_name}: communication step {1e3 * h:.4g} ms is accepted at the current memberships "
                   f"(limit {1e3 * lim:.4g} ms, {accepted}) but exceeds the limit of rule(s) "
                   f"{', '.join(str(j + 1) for j in bad_rules)} alone ({per_rule}): the loop diverges if the "
                   f"premise moves there")
        if not self._warned:
            warnings.warn(msg, RuntimeWarning, stacklevel=2)
            self._warned = True

    # -- the contract -------------------------------------------------------------------------
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        x = np.array([u[0], u[1]])
        w_hat = self._w_hat(x)
        hj = self._weights(x, w_hat)
        # advance at this point with the same measurements computes the same w_hat and weights (from
        # the same eps): kept for it, exact
        self._last = (float(u[0]), float(u[1]), self.eps, w_hat, hj) if self.primed else None
        d0 = float(hj @ self._V_flat @ w_hat)  # 003 (3.1), third line
        return np.concatenate(([d0], w_hat, hj))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        x = np.array([u[0], u[1]])
        last = self._last
        if last is not None and last[2] is self.eps and last[0] == float(u[0]) and last[1] == float(u[1]):
            w_hat, hj = last[3], last[4]
        else:
            if not self.primed:
                self.eps = self.w_init + self.L1 @ x  # w_hat(t0) = w_hat_init
                self.primed = True
            w_hat = self.eps - self.L1 @ x
            hj = self._weights(x, w_hat)
        self._last = None
        self.check_step(h, hj)
        m = self.m
        # (3.1) integrated in the coordinates w_hat = eps - L1 x_tilde (an exact linear change of
        # variables; RK4 commutes with it), z' = G z + g with G, g constant over the step:
        if self.mode == 0:  # x_tilde = x_k held: w_hat' = sum_j h_j E_j w_hat + L1 (A x_k + B0 u)
            G = (hj @ self._E_flat).reshape(m, m)
            g = self.L1 @ np.array([x[1], self.b0 * float(u[2])])
            z = w_hat
        else:  # x_tilde = x_hat predicted: w_hat' = sum_j h_j W_j w_hat, x_hat' = A x_hat + B0 (u + d0_hat)
            G = (hj @ self._G1_flat).reshape(m + 2, m + 2)
            g = self._g1 * float(u[2])
            z = np.concatenate((w_hat, x))
        steps, dt = substeps(h, self.h_max)
        if self._kernels:  # plant/kernels/common.py: the same RK4 loop, compiled
            z = _common.rk4_affine(G, g, z, h, steps)
        else:
            def f(z, _stage):  # G, g held: the same at every stage
                return G @ z + g

            for _ in range(steps):
                z = rk4_step(f, z, dt)
        eps = z + self.L1 @ x if self.mode == 0 else z[:m] + self.L1 @ z[m:]
        if not np.all(np.isfinite(eps)):
            raise FloatingPointError(f"{self.model_name}: observer state not finite at t = {t + h:.6g} s")
        self.eps = eps

    def get_state(self) -> list:
        return self.eps.tolist() + [1.0 if self.primed else 0.0, 1.0 if self._warned else 0.0]

    def set_state(self, state) -> None:
        s = np.array(state, dtype=float)
        self.eps = s[: self.m].copy()
        self._last = None
        self.primed = bool(s[self.m] != 0.0)
        self._warned = bool(s[self.m + 1] != 0.0)
