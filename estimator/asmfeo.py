"""Adaptive sliding-mode fault-estimation observer (ASMFEO), 001 (12), (14), (15).

Plant model (001 (11)): omega' = -J^-1 omega x J omega + J^-1 M U e + J^-1 M u_f + J^-1 d, with
U = diag(u_c) the commanded wheel torques, e the wheel effectiveness and u_f the wheel bias.

Observer, 001 (12) (omega~ = omega - omega_hat, sign elementwise, sign(0) = 0):

    omega_hat' = Lambda omega~ - J^-1 omega_hat x J omega_hat + J^-1 M U e_hat + J^-1 M uf_hat
                 + J^-1 K sign(omega~)
Adaptive laws, 001 (14):   e_hat' = lambda_1 U^T M^T J^-T omega~,   uf_hat' = lambda_2 M^T J^-T omega~
Gain adaptation, 001 (15): K' = lambda_3 ||J^-1|| ||omega~|| sign(||omega~|| - epsilon)  if K > mu,
                           K' = mu                                                     if K <= mu

Readings chosen (001 is silent on these; all are parameters):

* ||.|| is the Euclidean norm of vectors and the induced 2-norm of J^-1.
* The observer uses the nominal J and M; it knows neither Delta J nor T_d (they are the d of (11)).
* U is built from the commanded torques u_c (the controller's output, as sent to the plant).
* The branch of (15) is evaluated at the current K of every RK4 stage.
* Initial values omega_hat(t0) = ``omega_hat_init``, e_hat(t0) = ``e_hat_init`` (1: healthy),
  uf_hat(t0) = ``uf_hat_init`` (0), K(t0) = ``K_init``. The observer state is not projected
  (001 has no projection); consumers clip e_hat where they need to (controller/fontsm.py).
* Sampling (``sampling_mode``), as in estimator/fafeo.py: the paper's observer is continuous, but
  omega is only known at communication points. Mode 1 (default) holds the innovation omega~
  sampled at t_k over the step, so sign(omega~), Lambda omega~ and the rates of (14) are constant
  over the step and the observer's own model carries omega_hat inside it; mode 0 holds omega.
* Command paired with the innovation in the effectiveness law (14) (``command_pairing``). The
  innovation omega~(t_k) is the model error accumulated over [t_k-1, t_k], i.e. under the command
  u_c(t_k-1) that was applied over that step; (14) read literally on the sampled data multiplies
  it by U(t_k), the command about to be applied. When u_c alternates sign from step to step (a
  sign(s) law chattering at the communication step, 001's controller as printed),
  U(t_k) ~ -U(t_k-1) reverses the gradient of (14) and e_hat drifts away from e (measured in the
  001 demo: e_hat_2 1.000 -> 1.007 with e_2 = 0.6). ``command_pairing`` = 1 uses U(t_k-1) in (14),
  the command that produced the innovation (the sampled-data form of the gradient); 0 (default)
  keeps U(t_k) (the literal sampled reading). The propagation (12) always uses the command applied
  over the step, u_c(t_k). At the first step (no earlier command) both use u_c(t_0); the previous
  command is part of the state.

Output ``fault_torque_hat`` = M((E_hat - I) u_c + uf_hat) is the estimate of the equivalent body
fault torque M((E - I) u_c + u_f): per-wheel e and u_f are not separately identifiable from
omega alone (the null space of M and the product U e), the torque is.

Integration: fixed-step RK4, internal step <= ``h_max``.

Inputs:  omega[1..3] measured body rate, rad/s;  u_c[1..N] commanded wheel torques, N.m
Outputs: omega_hat[1..3] rad/s, e_hat[1..N] 1, uf_hat[1..N] N.m, K N.m,
         fault_torque_hat[1..3] N.m (depends directly on u_c)
"""
from __future__ import annotations

import math

import numpy as np

from estimator.kernels import asmfeo as _kernel
from plant import kernels
from plant.block import Block, scalar, vector
from plant.integrate import h_max_parameter, rk4_step, substeps
from plant.rigid_wheels import check_distribution, check_inertia, wheel_count, wheel_parameters


def _sign(x: np.ndarray) -> np.ndarray:
    return np.sign(x)  # sign(0) = 0


class ASMFEO(Block):
    model_name = "ASMFEO"
    description = "Adaptive sliding-mode fault-estimation observer, 001 (12), (14), (15)"

    def __init__(self, n_wheels: int = 4):
        n = self.n = wheel_count(n_wheels)
        inputs = vector("omega", 3, "rad/s", "measured body rate") + vector(
            "u_c", n, "N.m", "commanded wheel torques (the controller's output)"
        )
        outputs = (
            vector("omega_hat", 3, "rad/s", "estimate of the body rate")
            + vector("e_hat", n, "1", "estimate of the wheel effectiveness")
            + vector("uf_hat", n, "N.m", "estimate of the wheel bias")
            + scalar("K", 0.0, "N.m", "adaptive switching gain K(t) of 001 (15)")
            + vector("fault_torque_hat", 3, "N.m", "estimated equivalent fault torque M((E_hat - I) u_c + uf_hat)")
        )
        params = (
            vector("Lambda", 3, "1/s", "diagonal of the observer gain Lambda, 001 (12)", [1.0] * 3)
            + scalar("lambda_1", 1.0, "1", "effectiveness adaptation rate lambda_1 of 001 (14) (SI units implied)")
            + scalar("lambda_2", 1.0, "1", "bias adaptation rate lambda_2 of 001 (14) (SI units implied)")
            + scalar("lambda_3", 1.0, "1", "switching-gain adaptation rate lambda_3 of 001 (15) (SI units implied)")
            + scalar("epsilon", 1e-4, "rad/s", "boundary of ||omega~|| in 001 (15)")
            + scalar("mu", 1e-4, "N.m", "floor of K in 001 (15) ('very small')")
            + scalar("K_init", 1e-3, "N.m", "K(t0)")
            + wheel_parameters(n, model=True)
            + vector("omega_hat_init", 3, "rad/s", "omega_hat(t0)")
            + vector("e_hat_init", n, "1", "e_hat(t0)", [1.0] * n)
            + vector("uf_hat_init", n, "N.m", "uf_hat(t0)")
            + h_max_parameter(0.001)
            + scalar("sampling_mode", 1, "1", "inside a step hold 1: the innovation omega - omega_hat, 0: omega")
            + scalar("command_pairing", 0, "1",
                     "command U in the e_hat law (14): 0 u_c(t_k) (literal), 1 u_c(t_k-1), the one that produced omega~(t_k)")
        )
        feed = {f"fault_torque_hat[{i}]": [f"u_c[{j + 1}]" for j in range(n)] for i in (1, 2, 3)}
        super().__init__(inputs, outputs, params, feed)
        self.x = np.zeros(4 + 2 * n)
        self.u_prev = np.zeros(n)  # command of the previous step (command_pairing = 1)
        self.has_prev = False

    def initialize(self, t0: float) -> None:
        J = self.p_matrix("J")
        check_inertia(J, "J")
        M = self.p_matrix("M")
        check_distribution(M, "M")
        lam = self.p_vector("Lambda")
        if not np.all(lam > 0):
            raise ValueError(f"Lambda: every diagonal entry must be > 0, got {lam.tolist()}")
        for name in ("lambda_1", "lambda_2", "lambda_3", "epsilon", "mu", "K_init", "h_max"):
            if not self.p(name) > 0:
                raise ValueError(f"{name}: must be > 0 (001 (14)-(15)), got {self.p(name):g}")
        mode = self.p("sampling_mode")
        if mode not in (0.0, 1.0):
            raise ValueError(f"sampling_mode: must be 0 or 1, got {mode:g}")
        self.hold_innovation = mode == 1.0
        pairing = self.p("command_pairing")
        if pairing not in (0.0, 1.0):
            raise ValueError(f"command_pairing: must be 0 or 1, got {pairing:g}")
        self.pair_previous = pairing == 1.0
        Ji = np.linalg.inv(J)
        self.J, self.Ji, self.M = J, Ji, M
        self.B = Ji @ M  # J^-1 M
        self.Bt = self.B.T.copy()  # M^T J^-T
        self.Ji_norm = float(np.linalg.norm(Ji, 2))
        self.Lambda = lam
        self.l1, self.l2, self.l3 = self.p("lambda_1"), self.p("lambda_2"), self.p("lambda_3")
        self.eps, self.mu = self.p("epsilon"), self.p("mu")
        self.h_max = self.p("h_max")
        self._kernels = kernels.enabled()  # estimator/kernels/asmfeo.py for the held-innovation step
        self._prm = _kernel.params(l1=self.l1, l2=self.l2, l3=self.l3, ji_norm=self.Ji_norm, eps=self.eps, mu=self.mu)
        self.x = np.concatenate(
            [self.p_vector("omega_hat_init"), self.p_vector("e_hat_init"), self.p_vector("uf_hat_init"), [self.p("K_init")]]
        )
        self.u_prev = np.zeros(self.n)
        self.has_prev = False

    # -- 001 (12), (14), (15) --------------------------------------------------------------------
    def _deriv(self, x: np.ndarray, w_tilde, omega_held, u_c: np.ndarray, u_law=None) -> np.ndarray:
        """001 (12), (14), (15) with the innovation ``w_tilde`` (or omega_held - omega_hat), the command
        ``u_c`` applied over the step and ``u_law`` (default ``u_c``) in the effectiveness law (14)."""
        n = self.n
        u_law = u_c if u_law is None else u_law
        wh = x[0:3]
        e_hat, uf_hat, K = x[3 : 3 + n], x[3 + n : 3 + 2 * n], x[-1]
        wt = w_tilde if w_tilde is not None else omega_held - wh
        J = self.J
        hw = J @ wh
        gyro = np.array([wh[1] * hw[2] - wh[2] * hw[1], wh[2] * hw[0] - wh[0] * hw[2], wh[0] * hw[1] - wh[1] * hw[0]])
        wh_dot = self.Lambda * wt - self.Ji @ gyro + self.B @ (u_c * e_hat + uf_hat) + (K * self.Ji) @ _sign(wt)  # 001 (12)
        g = self.Bt @ wt
        nw = math.sqrt(float(wt @ wt))
        if K > self.mu:  # 001 (15)
            K_dot = self.l3 * self.Ji_norm * nw * (1.0 if nw > self.eps else (-1.0 if nw < self.eps else 0.0))
        else:
            K_dot = self.mu
        return np.concatenate((wh_dot, self.l1 * u_law * g, self.l2 * g, [K_dot]))  # 001 (14)

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        n = self.n
        omega = np.array(u[0:3], dtype=float)
        u_c = np.array(u[3 : 3 + n], dtype=float)
        u_law = self.u_prev if (self.pair_previous and self.has_prev) else u_c  # command_pairing
        steps, dt = substeps(h, self.h_max)
        if self.hold_innovation and self._kernels:
            x = _kernel.advance_held(self.x, omega - self.x[0:3], u_c, u_law, steps, dt, self.J, self.Ji, self.B,
                                     self.Lambda, self._prm)
        elif self.hold_innovation:
            x = self._advance_held_innovation(omega - self.x[0:3], u_c, steps, dt, u_law)
        else:
            x = self.x

            def f(x, _stage):  # inputs held: the same at every stage
                return self._deriv(x, None, omega, u_c, u_law)

            for _ in range(steps):
                x = rk4_step(f, x, dt)
        if not np.all(np.isfinite(x)):
            raise FloatingPointError(f"non-finite observer state at t = {t + h:.6g} s")
        self.x = x
        self.u_prev = u_c
        self.has_prev = True

    def _advance_held_innovation(self, wt: np.ndarray, u_c: np.ndarray, steps: int, dt: float, u_law=None) -> np.ndarray:
        """RK4 of ``_deriv`` for a held innovation omega~ (sampling_mode 1), written out: with omega~
        held, the rates of (14) are constant, so e_hat, uf_hat move linearly and their term in (12)
        is affine in time; only the gyroscopic term and K (branch of (15)) need the stages."""
        n = self.n
        x = self.x
        u_law = u_c if u_law is None else u_law
        e_hat, uf_hat = x[3 : 3 + n], x[3 + n : 3 + 2 * n]
        g = self.Bt @ wt
        e_dot, uf_dot = self.l1 * u_law * g, self.l2 * g  # 001 (14), constant over the step
        c1 = (self.B @ (u_c * e_dot + uf_dot)).tolist()  # d/dt of J^-1 M (U e_hat + uf_hat)
        lin = self.Lambda * wt + self.B @ (u_c * e_hat + uf_hat)  # at the start of the step
        sgn = (self.Ji @ np.sign(wt)).tolist()  # J^-1 sign(omega~)
        nw = math.sqrt(float(wt @ wt))
        kd_up = self.l3 * self.Ji_norm * nw * (1.0 if nw > self.eps else (-1.0 if nw < self.eps else 0.0))
        mu = self.mu
        (j11, j12, j13), (j21, j22, j23), (j31, j32, j33) = self.J.tolist()
        (i11, i12, i13), (i21, i22, i23), (i31, i32, i33) = self.Ji.tolist()
        l1, l2, l3 = lin.tolist()
        s1, s2, s3 = sgn
        d1, d2, d3 = c1

        def f(tau, w1, w2, w3, K):
            h1 = j11 * w1 + j12 * w2 + j13 * w3
            h2 = j21 * w1 + j22 * w2 + j23 * w3
            h3 = j31 * w1 + j32 * w2 + j33 * w3
            g1, g2, g3 = w2 * h3 - w3 * h2, w3 * h1 - w1 * h3, w1 * h2 - w2 * h1
            return (
                l1 + tau * d1 - (i11 * g1 + i12 * g2 + i13 * g3) + K * s1,  # 001 (12)
                l2 + tau * d2 - (i21 * g1 + i22 * g2 + i23 * g3) + K * s2,
                l3 + tau * d3 - (i31 * g1 + i32 * g2 + i33 * g3) + K * s3,
                kd_up if K > mu else mu,  # 001 (15)
            )

        w1, w2, w3 = x[0:3].tolist()
        K = float(x[-1])
        for k in range(steps):
            t0 = k * dt
            a = f(t0, w1, w2, w3, K)
            b = f(t0 + 0.5 * dt, w1 + 0.5 * dt * a[0], w2 + 0.5 * dt * a[1], w3 + 0.5 * dt * a[2], K + 0.5 * dt * a[3])
            c = f(t0 + 0.5 * dt, w1 + 0.5 * dt * b[0], w2 + 0.5 * dt * b[1], w3 + 0.5 * dt * b[2], K + 0.5 * dt * b[3])
            d = f(t0 + dt, w1 + dt * c[0], w2 + dt * c[1], w3 + dt * c[2], K + dt * c[3])
            q = dt / 6.0
            w1 += q * (a[0] + 2.0 * (b[0] + c[0]) + d[0])
            w2 += q * (a[1] + 2.0 * (b[1] + c[1]) + d[1])
            w3 += q * (a[2] + 2.0 * (b[2] + c[2]) + d[2])
            K += q * (a[3] + 2.0 * (b[3] + c[3]) + d[3])
        H = steps * dt
        return np.concatenate(([w1, w2, w3], e_hat + H * e_dot, uf_hat + H * uf_dot, [K]))

    def _fault_torque_hat(self, u: np.ndarray) -> np.ndarray:
        n = self.n
        u_c = np.asarray(u[3 : 3 + n], dtype=float)
        e_hat, uf_hat = self.x[3 : 3 + n], self.x[3 + n : 3 + 2 * n]
        return self.M @ ((e_hat - 1.0) * u_c + uf_hat)

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        return np.concatenate((self.x, self._fault_torque_hat(u)))

    def feedthrough_outputs(self, t: float, u: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``y`` from ``outputs_at`` with fault_torque_hat (the only output that depends on u_c)
        recomputed for a new command: the state outputs are evaluated once per exchange."""
        y[self.x.size :] = self._fault_torque_hat(u)
        return y

    def get_state(self) -> list:
        """[omega_hat, e_hat, uf_hat, K, previous command (n), has a previous command (0/1)]."""
        return self.x.tolist() + self.u_prev.tolist() + [1.0 if self.has_prev else 0.0]

    def set_state(self, state) -> None:
        s = np.array(state, dtype=float)
        m = 4 + 2 * self.n
        self.x = s[:m].copy()
        if s.size == m:  # a state without the previous command (before command_pairing existed)
            self.u_prev, self.has_prev = np.zeros(self.n), False
        else:
            self.u_prev, self.has_prev = s[m : m + self.n].copy(), bool(s[m + self.n])
