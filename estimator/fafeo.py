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
* ||d2_hat||_1 <= d_max is a projection of the estimator state: after every internal RK4 step,
  if d2_hat = w_hat + B_d1 y lies outside the 1-norm ball, zeta_w is shifted so that d2_hat is
  scaled onto the ball (direction kept); inside a step d2_hat enters x_hat' unclipped. The output
  is scaled onto the ball too (y may have moved since the last step). We tried two other readings:
  clipping d2_hat only where it enters x_hat' (the internal w_hat keeps integrating) makes the
  loop nonlinear and, from x_hat(t0) = 0, leaves ||omega - omega_hat|| ~ 1e-4 rad/s for the whole
  pre-fault phase; clipping only the output converges, but 5x slower than the state projection.
  The state projection is the discrete-time form of a projection operator, so its effect depends
  (weakly) on ``h_max``.
* Gamma = I (000 section 5): B Gamma = B.
* Sampling (``sampling_mode``): the paper's observer is continuous; in co-simulation y is only
  known at communication points. Mode 1 (default) holds the innovation e_y = y - x_hat sampled
  at the communication point over the step (y is replaced by x_hat(tau) + e_y(t) inside the step),
  so the observer's own model carries the motion inside the step. Mode 0 holds y itself: the
  observer then compares its prediction with a stale measurement, a lag of about h/2, and at
  h = 10 ms ||omega - omega_hat|| reaches 2e-4 rad/s in the saturated manoeuvre at 80 s (4e-5
  rad/s with mode 1, the same as either mode at 1 ms). Both modes have the same feedthrough.
* Premise and blending: per rule, the observer in the PI states is affine, z' = M_i z + C_i y +
  [B u; 0; 0]; the block precomputes M_i, C_i and blends them with b_i (sum_i b_i = 1).

Integration: fixed-step RK4 with internal step <= ``h_max``; inputs held over the step.
``advance`` and ``outputs_at`` run the compiled kernels of ``estimator/kernels/fafeo.py`` when
kernels are on (``plant/kernels``); the numpy code below is the reference. The
error dynamics of the published gains have eigenvalues of modulus < 15 1/s (close to the pole
region O(-10, 10) of 000 section 5.2), so h_max = 10 ms keeps |h lambda| < 0.15, well inside
RK4's stability region. Replaying a closed-loop 10 ms input record, h_max = 10 ms differs from
h_max = 0.2 ms by < 3e-8 rad/s on omega_hat and < 2e-4 N.m on f_hat after 15 s (the fault
estimates' own errors are ~0.1 N.m); in the first seconds, while the projections switch (start
from omega_hat = 0), by up to 0.6 N.m on f_hat (projection events are first-order in the step);
h_max = 2.5 ms brings that to 0.09 N.m at about 3x the cost.

Inputs:  omega[1..3]  measured body rate y, rad/s
         u[1..3]      command applied by the controller, N.m
Outputs: omega_hat[1..3]  estimate of omega, rad/s
         f_hat[1..3]      actuator fault estimate, N.m
         d2_hat[1..2n]    estimate of [eta; eta_dot] (1, 1/s)
"""
from __future__ import annotations

import numpy as np

from estimator.kernels import fafeo as _kernel
from plant import kernels
from plant.block import Block, matrix, rule_tensor, scalar, vector
from plant.flexible import N_MODES, placeholder_model
from plant.integrate import h_max_parameter, rk4_step, substeps
from plant.ts_fuzzy import fuzzy_model, memberships


# -- helpers shared with the controllers ------------------------------------------------------
def project_l1(v: np.ndarray, bound: float) -> np.ndarray:
    """Scale ``v`` onto {||v||_1 <= bound} if it lies outside (direction kept)."""
    n1 = float(np.abs(v).sum())
    return v * (bound / n1) if n1 > bound else v


class FAFEO(Block):
    model_name = "FAFEO"
    description = "Fuzzy adaptive fault-estimation observer, 000 (16)-(17) in the PI form (22)"

    def __init__(self, n_modes: int = N_MODES, n_rules: int = 8):
        """``n_modes`` flexible modes (2n vibration states), ``n_rules`` = 8 T-S rules at the
        corners of the omega box (000 (10)). Gains default to zero and the model to the
        placeholder spacecraft: a paper's factory sets both (``papers/p000_li2023/blocks.py``)."""
        n = self.n = int(n_modes)
        r = self.n_rules = int(n_rules)
        if r != 8:
            raise ValueError(f"FAFEO: the T-S model has 8 rules (corners of the omega box), not {n_rules}")
        model = placeholder_model(n)
        inputs = vector("omega", 3, "rad/s", "measured body rate y") + vector(
            "u", 3, "N.m", "command applied by the controller"
        )
        outputs = (
            vector("omega_hat", 3, "rad/s", "estimate of the body rate")
            + vector("f_hat", 3, "N.m", "actuator fault estimate")
            + vector("d2_hat", 2 * n, "1", "estimate of [eta; eta_dot]")
        )
        params = (
            rule_tensor("K", np.zeros((r, 3, 3)), "1/s", "observer gain K_i, 000 (16)")
            + rule_tensor("F1", np.zeros((r, 3, 3)), "N.m.s", "fault-law gain F_1i, 000 (17)")
            + rule_tensor("G1", np.zeros((r, 2 * n, 3)), "1", "vibration-law gain G_1i, 000 (17)")
            + matrix("F2", np.zeros((3, 3)), "N.m.s", "fault-law proportional gain F_2, 000 (17)")
            + matrix("G2", np.zeros((2 * n, 3)), "1", "vibration-law proportional gain G_2, 000 (17)")
            + scalar("theta_1", 0.0, "1", "fault-law weight theta_1, 000 (17)")
            + scalar("theta_2", 0.0, "1", "vibration-law weight theta_2, 000 (17)")
            + scalar("f_min", -1.0, "N.m", "lower projection bound of f_hat")
            + scalar("f_max", 1.0, "N.m", "upper projection bound of f_hat")
            + scalar("d_max", 1.0, "1", "bound on ||d2_hat||_1")
            + matrix("J", model["J"], "kg.m2", "hub inertia (model)")
            + matrix("delta", model["delta"], "1", "coupling matrix (model)")
            + vector("omega_n", n, "rad/s", "modal natural frequency (model)", model["omega_n"])
            + vector("zeta", n, "1", "modal damping ratio (model)", model["zeta"])
            + scalar("omega_box", 1.0, "rad/s", "T-S operating box half-width")
            + vector("omega_hat_init", 3, "rad/s", "initial omega estimate")
            + vector("f_hat_init", 3, "N.m", "initial fault estimate")
            + vector("d2_hat_init", 2 * n, "1", "initial [eta; eta_dot] estimate")
            + h_max_parameter(0.01)
            + scalar("sampling_mode", 1, "1", "inside a step hold 1: the innovation y - omega_hat, 0: y")
        )
        y_in = ("omega[1]", "omega[2]", "omega[3]")
        feed = {v.name: y_in for v in outputs if not v.name.startswith("omega_hat")}
        super().__init__(inputs, outputs, params, feed)
        self.x = np.zeros(6 + 2 * n)
        self.primed = False

    # -- set-up -------------------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        n = self.n
        m = 6 + 2 * n
        J, delta = self.p_matrix("J"), self.p_matrix("delta")
        Jm = J - delta.T @ delta
        if np.any(np.linalg.eigvalsh(0.5 * (Jm + Jm.T)) <= 0):
            raise ValueError("FAFEO: J - delta^T delta must be positive definite")
        self.box = self.p("omega_box")
        if not self.box > 0:
            raise ValueError("FAFEO: omega_box must be > 0")
        # A_i, B, D_2i, A_d1 = I, B_d1, A_d2, B_d2 of 000 (9), built from the model parameters
        fm = fuzzy_model(J, delta, self.p_vector("omega_n"), self.p_vector("zeta"), self.box)
        B = fm.B  # Gamma = I
        Pf = self.p("theta_1") * self.p_matrix("F2")  # theta_1 F_2, 000 (68)
        Pw = self.p("theta_2") * self.p_matrix("G2")  # theta_2 G_2, 000 (68)
        Kr, F1r, G1r = self.p_tensor("K"), self.p_tensor("F1"), self.p_tensor("G1")
        # Per rule i, the unprojected observer in the PI states z = [x_hat, zeta_f, zeta_w] is
        # z' = M_i z + C_i y + [B u; 0; 0], from 000 (16)-(17) with f_hat = zeta_f + Pf e_y,
        # w_hat = zeta_w + Pw e_y, d2_hat = w_hat + B_d1 y, e_y = y - x_hat:
        #   x_hat'  = (A_i - B Pf - D_2i Pw - K_i) x_hat + B zeta_f + D_2i zeta_w + (B Pf + D_2i Pw + D_2i B_d1 + K_i) y + B u
        #   zeta_f' = F_1i (y - x_hat)
        #   zeta_w' = A_d2 zeta_w - (A_d2 Pw + G_1i) x_hat + (A_d2 Pw + B_d2 + G_1i) y
        # Since sum_i b_i = 1, the blended observer is z' = (sum b_i M_i) z + (sum b_i C_i) y + ...
        # Rows m..m+2 give the unclipped f_hat and rows m+3.. the unprojected d2_hat (rule-independent).
        R = fm.n_rules
        Mr = np.zeros((R, m + 3 + 2 * n, m))
        Cr = np.zeros((R, m + 3 + 2 * n, 3))
        AdPw = fm.Ad2 @ Pw
        for i in range(R):
            D2 = fm.D2[i]
            Mr[i, 0:3, 0:3] = fm.A[i] - B @ Pf - D2 @ Pw - Kr[i]
            Mr[i, 0:3, 3:6] = B
            Mr[i, 0:3, 6:m] = D2
            Mr[i, 3:6, 0:3] = -F1r[i]
            Mr[i, 6:m, 0:3] = -AdPw - G1r[i]
            Mr[i, 6:m, 6:m] = fm.Ad2
            Cr[i, 0:3] = B @ Pf + D2 @ Pw + D2 @ fm.Bd1 + Kr[i]
            Cr[i, 3:6] = F1r[i]
            Cr[i, 6:m] = AdPw + fm.Bd2 + G1r[i]
            Mr[i, m : m + 3, 0:3] = -Pf  # f_hat (unclipped) = zeta_f + Pf (y - x_hat)
            Mr[i, m : m + 3, 3:6] = np.eye(3)
            Cr[i, m : m + 3] = Pf
            Mr[i, m + 3 :, 0:3] = -Pw  # d2_hat = zeta_w + Pw (y - x_hat) + B_d1 y
            Mr[i, m + 3 :, 6:m] = np.eye(2 * n)
            Cr[i, m + 3 :] = Pw + fm.Bd1
        self._Mr = Mr.reshape(R, -1)
        self._Cr = Cr.reshape(R, -1)
        self._shape_M = Mr.shape[1:]
        self._shape_C = Cr.shape[1:]
        self._Lout = Mr[0, m:]  # (3 + 2n, m): rule-independent read-out of f_hat, d2_hat
        self._Pout = Cr[0, m:]
        self.B, self.Pf, self.Pw, self.Bd1 = B, Pf, Pw, fm.Bd1
        self.f_min, self.f_max = self.p("f_min"), self.p("f_max")
        if not self.f_min < self.f_max:
            raise ValueError("FAFEO: f_min must be < f_max")
        self.d_max = self.p("d_max")
        if not self.d_max > 0:
            raise ValueError("FAFEO: d_max must be > 0")
        self.h_max = self.p("h_max")
        if not self.h_max > 0:
            raise ValueError("FAFEO: h_max must be > 0")
        self.hold_innovation = int(round(self.p("sampling_mode"))) == 1
        self.x_init = self.p_vector("omega_hat_init")
        self.f_init = np.clip(self.p_vector("f_hat_init"), self.f_min, self.f_max)
        self.d2_init = project_l1(self.p_vector("d2_hat_init"), self.d_max)
        self.x = np.concatenate([self.x_init, np.zeros(3 + 2 * n)])
        self.primed = False
        self._kernels = kernels.enabled()
        self._Mr3, self._Cr3 = Mr, Cr  # (8, rows, m), (8, rows, 3) for the kernel
        self._prm = _kernel.params(omega_box=self.box, f_min=self.f_min, f_max=self.f_max, d_max=self.d_max,
                                   hold_innovation=1.0 if self.hold_innovation else 0.0)
        self._Lout, self._Pout = np.ascontiguousarray(self._Lout), np.ascontiguousarray(self._Pout)

    def _prime(self, y: np.ndarray) -> None:
        """Integrator initial values giving f_hat(t0) = f_hat_init, d2_hat(t0) = d2_hat_init, 000 (22)."""
        e = y - self.x[0:3]
        self.x[3:6] = self.f_init - self.Pf @ e
        w0 = self.d2_init - self.Bd1 @ y  # w = d2 - B_d1 y (A_d1 = I)
        self.x[6:] = w0 - self.Pw @ e
        self.primed = True

    # -- the contract ------------------------------------------------------------------------------
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        if not self.primed:
            return np.concatenate((self.x_init, self.f_init, self.d2_init))
        if self._kernels:
            return _kernel.outputs(self.x, np.asarray(u, dtype=float), self._Lout, self._Pout, self._prm)
        r = self._Lout @ self.x + self._Pout @ u[0:3]
        f = np.minimum(np.maximum(r[0:3], self.f_min), self.f_max)  # Proj of 000 (17)
        return np.concatenate((self.x[0:3], f, project_l1(r[3:], self.d_max)))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        y = np.array(u[0:3], dtype=float)
        if not self.primed:
            self._prime(y)
        steps, dt = substeps(h, self.h_max)
        if self._kernels:
            self.x = _kernel.advance(self.x, y, np.asarray(u, dtype=float), h, steps, self._Mr3, self._Cr3, self.B,
                                     self._prm)
            return
        m = self.x.size
        # premise z = measured omega, held over the step: b_i and the blended matrices are constant
        b = memberships(y, self.box)
        M = (b @ self._Mr).reshape(self._shape_M)
        C = (b @ self._Cr).reshape(self._shape_C)
        if self.hold_innovation:
            # sampled-data realisation: e_y = y - x_hat sampled at t and held, i.e. y is replaced by
            # x_hat(tau) + e_y(t) inside the step
            M[:, 0:3] += C
            c = C @ (y - self.x[0:3])
        else:  # y held: the continuous observer driven by the zero-order-held measurement
            c = C @ y
        c[0:3] += self.B @ u[3:6]  # B Gamma u, Gamma = I
        f_min, f_max, d_max = self.f_min, self.f_max, self.d_max
        B = self.B

        def deriv(z, _stage):  # inputs held: the same at every stage
            r = M @ z + c
            dz = r[0:m]
            fu = r[m : m + 3]
            if fu.min() < f_min or fu.max() > f_max:
                # Proj of 000 (17): clipped f_hat in x_hat', conditional integration of zeta_f
                f = np.minimum(np.maximum(fu, f_min), f_max)
                dz[0:3] += B @ (f - fu)
                stop = ((fu > f_max) & (dz[3:6] > 0.0)) | ((fu < f_min) & (dz[3:6] < 0.0))
                dz[3:6][stop] = 0.0
            return dz

        z = self.x
        for _ in range(steps):
            z = rk4_step(deriv, z, dt)
            # ||d2_hat||_1 <= d_max (000 (17)): project the estimator state back onto the ball
            d2u = (M[m + 3 :] @ z) + c[m + 3 :]
            n1 = float(np.abs(d2u).sum())
            if n1 > d_max:
                z[6:] += d2u * (d_max / n1 - 1.0)
        self.x = z

    def get_state(self) -> list:
        return self.x.tolist() + [1.0 if self.primed else 0.0]

    def set_state(self, state) -> None:
        s = np.array(state, dtype=float)
        self.x = s[:-1].copy()
        self.primed = bool(s[-1] != 0.0)
