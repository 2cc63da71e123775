"""Fuzzy adaptive fault-estimation observer (FAFEO), 000 (16)-(17), in the PI form of 000 (22).

Observer, 000 (16) (C = I, y = omega, Gamma = I):

    x_hat' = sum_i b_i {A_i x_hat + B Gamma (u + f_hat) + D_2i d2_hat + K_i (y - y_hat)},  y_hat = x_hat

Adaptive laws, 000 (17):

    f_hat'  = Proj[ sum_i b_i {F_1i e_y + theta_1 F_2 e_y'} ]        (projection onto [f_min, f_max])
    w_hat'  = sum_i b_i {A_d2 w_hat + B_d2 y + G_1i e_y + theta_2 G_2 e_y'}
    d2_hat  = A_d1 w_hat + B_d1 y,   ||d2_hat||_1 <= d_max          (d2 = [eta; eta_dot], w = [eta; eta_dot + delta omega])

PI form (000 (22)), so that y is never differentiated. Because sum_i b_i = 1, theta_1 F_2 and
theta_2 G_2 are common to all rules, and the integrator states

    zeta_f = f_hat - theta_1 F_2 e_y,     zeta_w = w_hat - theta_2 G_2 e_y,      e_y = y - x_hat

obey  zeta_f' = sum_i b_i F_1i e_y  and  zeta_w' = A_d2 w_hat + B_d2 y + sum_i b_i G_1i e_y,
which need no y'. The block integrates x = [x_hat (3), zeta_f (3), zeta_w (2n)] and forms
f_hat = zeta_f + theta_1 F_2 e_y and w_hat = zeta_w + theta_2 G_2 e_y. Consequently f_hat and
d2_hat depend directly on the input omega (declared in ``feedthrough``); nothing depends
directly on u (u only enters x_hat').

Readings chosen (the paper is silent or ambiguous on these):

* Premise variables: b_i(z) uses the measured omega (the input), 000 (8)-(10) with z = x = omega
  and y = x. Memberships as in ``plant/ts_fuzzy.py`` (linear, saturated outside the box); since
  A(omega), D_2(omega) are affine in omega, sum b_i A_i = A(clip(omega)) and likewise for D_2.
  Inside one communication step omega is held, so b_i and all blended matrices are constant.
* Initial values: x_hat(t0) = ``omega_hat_init``, f_hat(t0) = ``f_hat_init`` (default 0) and
  d2_hat(t0) = ``d2_hat_init`` (default 0). The PI integrators need e_y(t0) to give exactly these
  values (the "- theta_1 F_2 C e_x(t0)" term of 000 (22)): they are set from the first measurement
  the block sees ("priming", at the first ``advance``; ``outputs_at`` before that returns the
  initial values without changing the state). The primed flag is part of the state.
* Projection in the PI form: f_hat = clip(zeta_f + theta_1 F_2 e_y, f_min, f_max) per component,
  and conditional-integration anti-windup: zeta_f_i stops integrating while the unclipped
  f_hat_i is at or beyond a bound and F_1 e_y pushes it further out (the Proj of 000 (17) applied
  to the integral part). The x_hat equation uses the clipped f_hat.
* ||d2_hat||_1 <= d_max: when the 1-norm exceeds d_max, d2_hat is scaled onto the 1-norm ball
  (direction kept). This bounded d2_hat is what the block outputs and what drives x_hat'; the
  internal w_hat is not clipped (A_d2 is stable, so it cannot wind up).
* Gamma = I (000 section 5): B Gamma = B.

Integration: fixed-step RK4 with internal step <= ``h_max``; inputs held over the step. The
error dynamics of the published gains have eigenvalues of modulus < 15 1/s (the pole region
O(-10, 10) of 000 section 5.2), so h_max = 10 ms is well inside RK4's stability region
(|h lambda| < 0.15) and accurate to far below the sampling effects.

Inputs:  omega[1..3]  measured body rate y, rad/s
         u[1..3]      command applied by the controller, N.m
Outputs: omega_hat[1..3]  estimate of omega, rad/s
         f_hat[1..3]      actuator fault estimate, N.m
         d2_hat[1..2n]    estimate of [eta; eta_dot] (1, 1/s)
"""
from __future__ import annotations

import math

import numpy as np

from plant.block import Block, Variable, matrix, scalar, split_name, vector
from plant.flexible import N_MODES, modal_matrices
from plant.parameters import LI2023
from plant.ts_fuzzy import OMEGA_BOX

from . import li2023_gains as G


# -- helpers shared with the controllers ------------------------------------------------------
def rule_tensor(base: str, values, unit: str = "1", description: str = ""):
    """Variables ``base[r,i,j]`` (1-based; r = rule) for an (r, m, k) array of rule matrices."""
    a = np.asarray(values, dtype=float)
    return [
        Variable(f"{base}[{r + 1},{i + 1},{j + 1}]", unit, description, float(a[r, i, j]))
        for r in range(a.shape[0])
        for i in range(a.shape[1])
        for j in range(a.shape[2])
    ]


def p_tensor(block: Block, base: str) -> np.ndarray:
    """Parameters ``base[r,i,j]`` of ``block`` as an (r, m, k) array."""
    entries = [
        (split_name(v.name)[1], block.param_values[k])
        for k, v in enumerate(block.parameters)
        if split_name(v.name)[0] == base
    ]
    shape = tuple(max(ix[d] for ix, _ in entries) for d in range(3))
    a = np.zeros(shape)
    for (r, i, j), x in entries:
        a[r - 1, i - 1, j - 1] = x
    return a


def fuzzy_weights(omega, box: float = OMEGA_BOX) -> np.ndarray:
    """b_i(omega) of ``plant.ts_fuzzy.memberships`` (same rule order), without the Python loop:
    the outer product of [M_+, M_-] over the three axes, raveled with axis 1 slowest."""
    p0 = min(max((omega[0] + box) / (2.0 * box), 0.0), 1.0)
    p1 = min(max((omega[1] + box) / (2.0 * box), 0.0), 1.0)
    p2 = min(max((omega[2] + box) / (2.0 * box), 0.0), 1.0)
    a = (p0, 1.0 - p0)
    b = (p1, 1.0 - p1)
    c = (p2, 1.0 - p2)
    return np.array([a[i] * b[j] * c[k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])


def project_l1(v: np.ndarray, bound: float) -> np.ndarray:
    """Scale ``v`` onto {||v||_1 <= bound} if it lies outside (direction kept)."""
    n1 = float(np.abs(v).sum())
    return v * (bound / n1) if n1 > bound else v


class FAFEO(Block):
    model_name = "FAFEO"
    description = "Fuzzy adaptive fault-estimation observer, 000 (16)-(17) in the PI form (22)"

    def __init__(self, n_modes: int = N_MODES):
        n = self.n = n_modes
        if n != LI2023["omega_n"].size:
            raise ValueError("the default parameter set has 4 modes")
        inputs = vector("omega", 3, "rad/s", "measured body rate y") + vector(
            "u", 3, "N.m", "command applied by the controller"
        )
        outputs = (
            vector("omega_hat", 3, "rad/s", "estimate of the body rate")
            + vector("f_hat", 3, "N.m", "actuator fault estimate")
            + vector("d2_hat", 2 * n, "1", "estimate of [eta; eta_dot]")
        )
        params = (
            rule_tensor("K", G.K, "1/s", "observer gain K_i, 000 A.1")
            + rule_tensor("F1", G.F1, "N.m.s", "fault-law gain F_1i, 000 A.1")
            + rule_tensor("G1", G.G1, "1", "vibration-law gain G_1i, 000 A.1")
            + matrix("F2", G.F2, "N.m.s", "fault-law proportional gain F_2, 000 (68)")
            + matrix("G2", G.G2, "1", "vibration-law proportional gain G_2, 000 (68)")
            + scalar("theta_1", G.THETA_1, "1", "000 (68)")
            + scalar("theta_2", G.THETA_2, "1", "000 (68)")
            + scalar("f_min", G.F_MIN, "N.m", "lower projection bound of f_hat")
            + scalar("f_max", G.F_MAX, "N.m", "upper projection bound of f_hat")
            + scalar("d_max", G.D_MAX, "1", "bound on ||d2_hat||_1")
            + matrix("J", LI2023["J"], "kg.m2", "hub inertia (model)")
            + matrix("delta", LI2023["delta"], "1", "coupling matrix (model)")
            + vector("omega_n", n, "rad/s", "modal natural frequency (model)", LI2023["omega_n"])
            + vector("zeta", n, "1", "modal damping ratio (model)", LI2023["zeta"])
            + scalar("omega_box", OMEGA_BOX, "rad/s", "T-S operating box half-width")
            + vector("omega_hat_init", 3, "rad/s", "initial omega estimate")
            + vector("f_hat_init", 3, "N.m", "initial fault estimate")
            + vector("d2_hat_init", 2 * n, "1", "initial [eta; eta_dot] estimate")
            + scalar("h_max", 0.01, "s", "largest internal RK4 step")
        )
        y_in = ("omega[1]", "omega[2]", "omega[3]")
        feed = {v.name: y_in for v in outputs if not v.name.startswith("omega_hat")}
        super().__init__(inputs, outputs, params, feed)
        self.x = np.zeros(6 + 2 * n)
        self.primed = False

    # -- set-up -------------------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        n = self.n
        J, delta = self.p_matrix("J"), self.p_matrix("delta")
        C, Kq = modal_matrices(self.p_vector("omega_n"), self.p_vector("zeta"))
        Jm = J - delta.T @ delta
        if np.any(np.linalg.eigvalsh(0.5 * (Jm + Jm.T)) <= 0):
            raise ValueError("FAFEO: J - delta^T delta must be positive definite")
        self.B = np.linalg.inv(Jm)  # 000 (9), Gamma = I
        self.J = J
        self.dTK = delta.T @ Kq
        self.dTC = delta.T @ C
        self.dT = delta.T.copy()
        I, Z = np.eye(n), np.zeros((n, n))
        self.Ad2 = np.block([[Z, I], [-Kq, -C]])  # 000 (9)
        self.Bd2 = np.vstack([-delta, C @ delta])
        self.Bd1 = np.vstack([np.zeros((n, 3)), -delta])  # A_d1 = I
        self.Kr = p_tensor(self, "K").reshape(8, 9)
        self.F1r = p_tensor(self, "F1").reshape(8, 9)
        self.G1r = p_tensor(self, "G1").reshape(8, 6 * n)
        self.Pf = self.p("theta_1") * self.p_matrix("F2")  # theta_1 F_2
        self.Pw = self.p("theta_2") * self.p_matrix("G2")  # theta_2 G_2
        self.f_min, self.f_max = self.p("f_min"), self.p("f_max")
        if not self.f_min < self.f_max:
            raise ValueError("FAFEO: f_min must be < f_max")
        self.d_max = self.p("d_max")
        if not self.d_max > 0:
            raise ValueError("FAFEO: d_max must be > 0")
        self.box = self.p("omega_box")
        self.h_max = self.p("h_max")
        if not self.h_max > 0:
            raise ValueError("FAFEO: h_max must be > 0")
        self.x_init = self.p_vector("omega_hat_init")
        self.f_init = np.clip(self.p_vector("f_hat_init"), self.f_min, self.f_max)
        self.d2_init = project_l1(self.p_vector("d2_hat_init"), self.d_max)
        self.x = np.concatenate([self.x_init, np.zeros(3 + 2 * n)])
        self.primed = False
        self._M = np.zeros((6 + 2 * n, 6 + 2 * n))
        self._M[6:, 6:] = self.Ad2
        self._c = np.zeros(6 + 2 * n)

    def _prime(self, y: np.ndarray) -> None:
        """Integrator initial values giving f_hat(t0) = f_hat_init, d2_hat(t0) = d2_hat_init, 000 (22)."""
        e = y - self.x[0:3]
        self.x[3:6] = self.f_init - self.Pf @ e
        w0 = self.d2_init - self.Bd1 @ y  # w = d2 - B_d1 y (A_d1 = I)
        self.x[6:] = w0 - self.Pw @ e
        self.primed = True

    # -- model pieces at a held measurement -------------------------------------------------------
    def _blend(self, y: np.ndarray):
        """b_i(y), blended K, F_1, G_1, and A(y), D_2(y) of 000 (9)-(10) at clip(y)."""
        b = fuzzy_weights(y, self.box)
        Kb = (b @ self.Kr).reshape(3, 3)
        F1b = (b @ self.F1r).reshape(3, 3)
        G1b = (b @ self.G1r).reshape(2 * self.n, 3)
        w = np.clip(y, -self.box, self.box)
        wx = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
        Ay = -self.B @ wx @ self.J  # sum b_i A_i
        D2y = self.B @ np.hstack([self.dTK, self.dTC - wx @ self.dT])  # sum b_i D_2i
        return Kb, F1b, G1b, Ay, D2y

    def _estimates(self, x: np.ndarray, y: np.ndarray):
        """(unclipped f_hat, clipped f_hat, d2_hat) from the integrator state, PI form 000 (22)."""
        e = y - x[0:3]
        fu = x[3:6] + self.Pf @ e
        f = np.minimum(np.maximum(fu, self.f_min), self.f_max)
        d2 = project_l1(x[6:] + self.Pw @ e + self.Bd1 @ y, self.d_max)
        return fu, f, d2

    # -- the contract ------------------------------------------------------------------------------
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        if not self.primed:
            return np.concatenate((self.x_init, self.f_init, self.d2_init))
        y = u[0:3]
        _, f, d2 = self._estimates(self.x, y)
        return np.concatenate((self.x[0:3], f, d2))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        y = np.array(u[0:3], dtype=float)
        uc = u[3:6]
        if not self.primed:
            self._prime(y)
        Kb, F1b, G1b, Ay, D2y = self._blend(y)
        B, Pf, Pw = self.B, self.Pf, self.Pw
        # Linear part z' = M z + c of the unprojected observer (derivation in the module docstring):
        # x_hat' = (A - B Pf - D2 Pw - K) x_hat + B zeta_f + D2 zeta_w + B u + (B Pf + D2 Pw + D2 Bd1 + K) y
        # zeta_f' = F1 (y - x_hat);  zeta_w' = A_d2 (zeta_w + Pw (y - x_hat)) + B_d2 y + G1 (y - x_hat)
        M, c = self._M, self._c
        D2Pw = D2y @ Pw
        M[0:3, 0:3] = Ay - B @ Pf - D2Pw - Kb
        M[0:3, 3:6] = B
        M[0:3, 6:] = D2y
        M[3:6, 0:3] = -F1b
        AdPw = self.Ad2 @ Pw
        M[6:, 0:3] = -AdPw - G1b
        c[0:3] = B @ uc + (B @ Pf + D2Pw + D2y @ self.Bd1 + Kb) @ y
        c[3:6] = F1b @ y
        c[6:] = (AdPw + self.Bd2 + G1b) @ y
        f_min, f_max, d_max = self.f_min, self.f_max, self.d_max
        Bd1y = self.Bd1 @ y

        def deriv(z):
            dz = M @ z + c
            e = y - z[0:3]
            fu = z[3:6] + Pf @ e
            d2u = z[6:] + Pw @ e + Bd1y
            n1 = float(np.abs(d2u).sum())
            if n1 > d_max:  # ||d2_hat||_1 <= d_max, 000 (17): correct the x_hat' term
                dz[0:3] += D2y @ (d2u * (d_max / n1 - 1.0))
            lo = fu < f_min
            hi = fu > f_max
            if lo.any() or hi.any():  # Proj of 000 (17): clipped f_hat in x_hat', anti-windup in zeta_f
                f = np.minimum(np.maximum(fu, f_min), f_max)
                dz[0:3] += B @ (f - fu)
                stop = (hi & (dz[3:6] > 0.0)) | (lo & (dz[3:6] < 0.0))
                dz[3:6][stop] = 0.0
            return dz

        steps = max(1, math.ceil(h / self.h_max - 1e-9))
        dt = h / steps
        z = self.x
        for _ in range(steps):
            k1 = deriv(z)
            k2 = deriv(z + (0.5 * dt) * k1)
            k3 = deriv(z + (0.5 * dt) * k2)
            k4 = deriv(z + dt * k3)
            z = z + (dt / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
        self.x = z

    def get_state(self) -> list:
        return self.x.tolist() + [1.0 if self.primed else 0.0]

    def set_state(self, state) -> None:
        s = np.array(state, dtype=float)
        self.x = s[:-1].copy()
        self.primed = bool(s[-1] != 0.0)
