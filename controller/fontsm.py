"""Backstepping + fractional-order nonsingular terminal sliding mode FE/FTC (FONTSM), 001 (23)-(36).

For the rigid spacecraft with Euler angles of plant/rigid_wheels.py (sigma' = G(sigma) omega,
2-3-1 sequence of plant/euler231.py) and N wheels through M:

    z1 = sigma - sigma_d,  z2 = omega - omega_d                                            001 (23)
    omega_d = -c z1 + G^-1(sigma) sigma_d'                                                 001 (27)
    s = z2 + a D^alpha1[sig(z1)^beta1] + b D^(alpha2 - 1)[sig(z1)^beta2]                   001 (30)
    u_cn = J^-1 omega x J omega - J^-1 M uf_hat - J^-1 Upsilon_hat                         001 (34)
    u_cm = -a D^(alpha1 + 1)[..] - b D^alpha2[..] - eps1 sign(s) - eps2 sig(s)^r            001 (35)
    u_c  = E_hat^2 M^T (J^-1 M E_hat^3 M^T)^-1 (u_cn + u_cm)                               001 (33)
    Upsilon_hat' = rho J^-T s                                                              001 (36)

with sig(x)^p = |x|^p sign(x) elementwise, a, b, alpha_i, beta_i, eps_i per axis (diagonal),
E_hat = diag(e_hat), uf_hat from the fault-estimation observer (estimator/asmfeo.py). If
E_hat = E the wheel torque J^-1 M E u_c equals u_cn + u_cm and s' follows the reaching law (32)
up to J^-1 (M uf~ + d - Upsilon_hat).

Readings (each a parameter; README of paper 001 gives the measurements behind them):

* ``pairing`` (default 1). G(0) is the permutation [[0,0,1],[0,1,0],[1,0,0]]: near sigma = 0,
  nu' ~ omega_3 and gamma' ~ omega_1. (30) as printed adds the FO terms of nu to omega_1 and those
  of gamma to omega_3; on s = 0 that gives nu' = -Phi(gamma), gamma' = -Phi(nu), whose mode
  nu - gamma grows: the printed law does not stabilise the printed plant (measured: divergence to
  the singularity in about 2.6 s). ``pairing`` = 1 orders the controller's z1 by the body axis each
  angle turns about: z1 = P (sigma - sigma_d), P = G(0)^-1 = [[0,0,1],[0,1,0],[1,0,0]], and uses
  G_c = P G in (24)-(28) (z1' = G_c omega, G_c(0) = I). All of 001's gains are equal on the three
  axes, so this changes no number. ``pairing`` = 0 is the literal reading.
* ``c`` (default 0): 001 never gives it. With c = 0, omega_d = 0 and (31), (35) are exact as
  printed (they omit the -omega_d' of (29)). For c > 0 the omega_d' of (29) is added to u_cm
  (computed analytically, sigma_d constant), and ``virtual_control`` chooses omega_d:
  1 (default) omega_d = G_c^-1 (-c z1), the form that gives (28); 0 the literal (27) -c z1.
* Fractional operators: Grünwald-Letnikov on the communication grid (controller/fractional.py),
  sampling period ``fo_step`` (equal to the communication step, see "Steps" below), t0 = the start of the run,
  memory ``fo_memory`` seconds (>= the run length: the full RL memory of (21)). Two GL sums per
  axis and step: A = D^alpha1 f1 and B = D^(alpha2-1) f2 = I^(1-alpha2) f2; the orders
  alpha1 + 1 and alpha2 are their backward differences (A_k - A_k-1)/h, (B_k - B_k-1)/h (exact
  GL identity). f1, f2 are formed from the current input sigma (direct feedthrough).
* Start-up (``fo_start``): strict GL (0) differentiates the jump of f from an implicit zero past
  at k = 0: D^(1+alpha1) f(t0) = h^-(1+alpha1) f(t0), a command of ~1e4 N.m at h = 1 ms (an
  impulse growing like 1/h). Default 1: the two derivative terms are 0 at k = 0 (s(t0) still uses
  the GL values); from k = 1 on both readings are the same formula.
* Switching: ``boundary_layer`` phi (rad/s) = 0 is sign(s) as printed; phi > 0 uses sat(s / phi).
* Estimates in (33): e_hat is clipped to [``e_hat_min``, ``e_hat_max``] (001 (5): 0 <= e <= 1)
  where it enters E_hat; if lambda_min(M E_hat^3 M^T) < ``alloc_min_eig`` (more than N - 3
  wheels estimated dead, Assumption 2.3) the block stops with an error.
* Upsilon_hat: Upsilon_hat(t + h) = Upsilon_hat + h rho J^-T s(t) (exact for inputs held over
  the step). Reading of "Upsilon = M uf_hat + d": Upsilon_hat then estimates what (39) needs,
  the residual M uf~ + d; (34) and (36) are implemented as printed.
* sign(0) = 0.
* Steps (issue 24). A step h is "the" step when |h - fo_step| <= :func:`step_tolerance`, i.e.
  1e-9 fo_step + 2 (k + 1) eps max(1, |t| + h) after k steps (eps = 2.2e-16): the worst rounding
  of a host that forms time by t += h (OMSimulator, Ecos) and clips its last step to the stop
  time; 7.6e-9 fo_step was measured after 25,000 steps of 1 ms, the bound is there 2.8e-7 fo_step
  and grows with the run length. A shorter step (a clipped last step, or steps that split a
  sample interval) is taken too: Upsilon_hat integrates over it, and the GL operators take their
  sample (the values at the start of the interval) once the steps complete fo_step, so they stay
  on the fo_step grid; outputs inside such an interval use the current inputs with the operators'
  last sample. A step that is longer than fo_step, or crosses the end of the sample interval,
  is refused (a ValueError: an FMI error status with that message).

Inputs:  sigma[1..3] rad, omega[1..3] rad/s, e_hat[1..N] 1 (start 1), uf_hat[1..N] N.m (start 0),
         sigma_d[1..3] rad (constant target, start 0). Unconnected estimates (e_hat = 1,
         uf_hat = 0) give the same law without fault estimation.
Outputs: u_c[1..N] N.m, s[1..3] rad/s, z1[1..3] rad (paper order sigma - sigma_d), z2[1..3] rad/s,
         Upsilon_hat[1..3] N.m.
State:   Upsilon_hat, the previous GL values A, B, the step count, and the GL histories of f1, f2.
"""
from __future__ import annotations

import math

import numpy as np

from controller.kernels import fontsm as _kernel
from plant import euler231, kernels
from plant.block import Block, scalar, vector
from plant.linalg3 import min_eig_sym3, solve_sym3
from plant.rigid_wheels import check_distribution, check_inertia, wheel_count, wheel_parameters

from .fractional import GLHistory

_EPS = float(np.finfo(float).eps)  # 2.2e-16: one rounding of a host's t += h is at most eps/2 |t|


def sig(x: float, p: float) -> float:
    """sig(x)^p = |x|^p sign(x) for a scalar (sign(0) = 0)."""
    return math.copysign(abs(x) ** p, x) if x else 0.0


class FONTSM(Block):
    model_name = "FONTSM"
    description = "Backstepping + fractional-order nonsingular terminal sliding-mode FE/FTC, 001 (23)-(36)"

    def __init__(self, n_wheels: int = 4):
        n = self.n = wheel_count(n_wheels)
        inputs = (
            vector("sigma", 3, "rad", "Euler angles [nu, psi, gamma]")
            + vector("omega", 3, "rad/s", "body rate")
            + vector("e_hat", n, "1", "estimated wheel effectiveness", [1.0] * n)
            + vector("uf_hat", n, "N.m", "estimated wheel bias")
            + vector("sigma_d", 3, "rad", "attitude target (constant between switches)")
        )
        outputs = (
            vector("u_c", n, "N.m", "commanded wheel torques, 001 (33)")
            + vector("s", 3, "rad/s", "sliding variable, 001 (30) (body-axis order)")
            + vector("z1", 3, "rad", "attitude error sigma - sigma_d, 001 (23)")
            + vector("z2", 3, "rad/s", "rate error omega - omega_d, 001 (23)")
            + vector("Upsilon_hat", 3, "N.m", "adaptive estimate of 001 (36)")
        )
        params = (
            wheel_parameters(n, model=True)
            + vector("a", 3, "1", "diagonal of a, 001 (30)", [1.0] * 3)
            + vector("b", 3, "1", "diagonal of b, 001 (30)", [1.0] * 3)
            + vector("alpha_1", 3, "1", "fractional order alpha_1, 001 (30)", [0.5] * 3)
            + vector("alpha_2", 3, "1", "fractional order alpha_2 (0 < alpha_2 < 1), 001 (30)", [0.5] * 3)
            + vector("beta_1", 3, "1", "power beta_1, 001 (30)", [0.5] * 3)
            + vector("beta_2", 3, "1", "power beta_2, 001 (30)", [0.5] * 3)
            + scalar("r", 0.5, "1", "reaching-law power 0 < r < 1, 001 (32)")
            + vector("eps_1", 3, "rad/s2", "diagonal of eps_1 (switching gain), 001 (32)", [1.0] * 3)
            + vector("eps_2", 3, "1", "diagonal of eps_2 (power-law gain), 001 (32)", [1.0] * 3)
            + scalar("rho", 1.0, "1", "adaptation rate of Upsilon_hat, 001 (36)")
            + scalar("c", 0.0, "1/s", "backstepping gain of 001 (27) (not given by 001: 0)")
            + scalar("pairing", 1, "1", "1: z1 ordered by body axis (P sigma), 0: literal 001 (30)")
            + scalar("virtual_control", 1, "1", "for c > 0: 1 omega_d = G_c^-1(-c z1) (gives (28)), 0 literal (27)")
            + scalar("boundary_layer", 0.0, "rad/s", "0: sign(s) as printed; > 0: sat(s / boundary_layer)")
            + scalar("fo_step", 0.001, "s", "sampling period of the GL operators (= the communication step)")
            + scalar("fo_memory", 1000.0, "s", "GL memory length (>= run length: full memory)")
            + scalar("fo_start", 1, "1", "1: no derivative kick at the first sample, 0: strict GL")
            + scalar("e_hat_min", 0.0, "1", "lower clip of e_hat in the allocation 001 (33)")
            + scalar("e_hat_max", 1.0, "1", "upper clip of e_hat in the allocation 001 (33)")
            + scalar("alloc_min_eig", 1e-9, "1", "smallest admissible lambda_min(M E_hat^3 M^T)")
            + vector("Upsilon_init", 3, "N.m", "Upsilon_hat(t0)")
        )
        sig_in = [f"sigma[{i}]" for i in (1, 2, 3)]
        sd_in = [f"sigma_d[{i}]" for i in (1, 2, 3)]
        om_in = [f"omega[{i}]" for i in (1, 2, 3)]
        est_in = [f"e_hat[{j + 1}]" for j in range(n)] + [f"uf_hat[{j + 1}]" for j in range(n)]
        feed = {f"u_c[{j + 1}]": sig_in + om_in + est_in + sd_in for j in range(n)}
        feed.update({f"s[{i}]": sig_in + om_in + sd_in for i in (1, 2, 3)})
        feed.update({f"z1[{i}]": sig_in + sd_in for i in (1, 2, 3)})
        feed.update({f"z2[{i}]": sig_in + om_in + sd_in for i in (1, 2, 3)})
        super().__init__(inputs, outputs, params, feed)
        self._version = 0
        self._cache_key = None

    # -- set-up -------------------------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        J = self.p_matrix("J")
        check_inertia(J, "J")
        M = self.p_matrix("M")
        check_distribution(M, "M")
        self.J, self.M, self.Ji = J, M, np.linalg.inv(J)
        self.JiT = self.Ji.T.copy()
        self.a, self.b = self.p_vector("a"), self.p_vector("b")
        self.alpha_1, self.alpha_2 = self.p_vector("alpha_1"), self.p_vector("alpha_2")
        self.beta_1, self.beta_2 = self.p_vector("beta_1"), self.p_vector("beta_2")
        self.r = self.p("r")
        self.eps_1, self.eps_2 = self.p_vector("eps_1"), self.p_vector("eps_2")
        self.rho, self.c = self.p("rho"), self.p("c")
        if not np.all((self.alpha_2 > 0) & (self.alpha_2 < 1)):
            raise ValueError(f"alpha_2: each order must lie in (0, 1) (001 (30)), got {self.alpha_2.tolist()}")
        if not np.all((self.alpha_1 > -1) & (self.alpha_1 < 1)):
            raise ValueError(f"alpha_1: each order must lie in (-1, 1), got {self.alpha_1.tolist()}")
        for name in ("beta_1", "beta_2"):
            v = self.p_vector(name)
            if not np.all(v > 0):
                raise ValueError(f"{name}: each power must be > 0, got {v.tolist()}")
        if not 0 < self.r < 1:
            raise ValueError(f"r: must lie in (0, 1) (001 (32)), got {self.r:g}")
        for name in ("eps_1", "eps_2"):
            v = self.p_vector(name)
            if not np.all(v >= 0):
                raise ValueError(f"{name}: each gain must be >= 0, got {v.tolist()}")
        if self.rho < 0 or self.c < 0:
            raise ValueError(f"{'rho' if self.rho < 0 else 'c'}: must be >= 0")
        for name in ("pairing", "virtual_control", "fo_start"):
            if self.p(name) not in (0.0, 1.0):
                raise ValueError(f"{name}: must be 0 or 1, got {self.p(name):g}")
        self.pairing = self.p("pairing") == 1.0
        self.virtual_literal = self.p("virtual_control") == 0.0
        self.strict_start = self.p("fo_start") == 0.0
        self.phi = self.p("boundary_layer")
        if self.phi < 0:
            raise ValueError(f"boundary_layer: must be >= 0 (0: sign), got {self.phi:g}")
        self.h = self.p("fo_step")
        if not self.h > 0:
            raise ValueError(f"fo_step: must be > 0, got {self.h:g}")
        mem = self.p("fo_memory")
        if not mem > 0:
            raise ValueError(f"fo_memory: the fractional memory length must be > 0 s, got {mem:g}")
        L = int(math.floor(mem / self.h + 1e-9))
        if L < 1:
            raise ValueError(f"fo_memory: {mem:g} s is shorter than one sample (fo_step = {self.h:g} s)")
        self.e_min, self.e_max = self.p("e_hat_min"), self.p("e_hat_max")
        if not 0 <= self.e_min < self.e_max:
            raise ValueError(f"e_hat_min, e_hat_max: need 0 <= e_hat_min < e_hat_max, got {self.e_min:g}, {self.e_max:g}")
        self.min_eig = self.p("alloc_min_eig")
        self.P = euler231.PAIRING if self.pairing else np.eye(3)
        self.hist_1 = GLHistory(self.alpha_1, L)  # D^alpha_1 of sig(z1)^beta_1
        self.hist_2 = GLHistory(self.alpha_2 - 1.0, L)  # D^(alpha_2 - 1) = I^(1 - alpha_2) of sig(z1)^beta_2
        self._hp1 = (self.h ** (-self.alpha_1)).tolist()  # h^-alpha_1
        self._hp2 = (self.h ** (1.0 - self.alpha_2)).tolist()  # h^-(alpha_2 - 1)
        self.upsilon = self.p_vector("Upsilon_init")
        self._ups = self.upsilon.tolist()
        self.A_prev = [0.0, 0.0, 0.0]
        self.B_prev = [0.0, 0.0, 0.0]
        self._Jl = J.tolist()
        self._a, self._b = self.a.tolist(), self.b.tolist()
        self._eps_1, self._eps_2 = self.eps_1.tolist(), self.eps_2.tolist()
        self._beta_1, self._beta_2 = self.beta_1.tolist(), self.beta_2.tolist()
        self.k = 0
        self._partial = 0.0  # time taken so far in the current sample interval (steps shorter than fo_step)
        self._pending = None  # (f1, f2, A, B) at the start of that interval, pushed when it completes
        self._kernels = kernels.enabled() and self.c == 0.0  # controller/kernels/fontsm.py: the law for c = 0
        self._kprm = _kernel.params(pairing=float(self.pairing), strict_start=float(self.strict_start), started=0.0,
                                    h=self.h, r=self.r, phi=self.phi, e_min=self.e_min, e_max=self.e_max)
        self._touch()

    def _touch(self):
        self._version += 1
        self._cache_key = None

    # -- the law ----------------------------------------------------------------------------------
    def _terms(self, u: np.ndarray):
        key = (self._version, np.asarray(u, dtype=float).tobytes())
        if key != self._cache_key:  # outputs_at and advance see the same inputs: compute once
            self._cache = self._compute(u)
            self._cache_key = key
        return self._cache

    def _virtual(self, sigma, omega, z1):
        """omega_d and omega_d' (sigma_d constant); zero for c = 0."""
        if self.c == 0.0:
            return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        c, P = self.c, self.P
        if self.virtual_literal:  # 001 (27) as printed: omega_d = -c z1
            Gc = P @ euler231.G(sigma)
            return (-c * z1).tolist(), (-c * (Gc @ omega)).tolist()
        Gc_inv = euler231.G_inv(sigma) @ P  # (P G)^-1 = G^-1 P (P^-1 = P)
        sigma_dot = np.array(euler231.rates(sigma, omega))
        Gc_inv_dot = euler231.G_inv_dot(sigma, sigma_dot) @ P
        # d/dt(G_c^-1 z1) = G_c^-1' z1 + G_c^-1 G_c omega
        return (-c * (Gc_inv @ z1)).tolist(), (-c * (Gc_inv_dot @ z1 + omega)).tolist()

    def _compute(self, u: np.ndarray):
        """Everything the law needs at (t_k, inputs): plain floats for the 3-vectors (numpy's
        per-call overhead dominates at this size), numpy for the GL sums and the allocation."""
        if self._kernels:
            return self._compute_kernel(u)
        n = self.n
        uu = u.tolist() if isinstance(u, np.ndarray) else list(u)
        sigma, omega = uu[0:3], uu[3:6]
        e_in = np.array(uu[6 : 6 + n])
        uf_hat = np.array(uu[6 + n : 6 + 2 * n])
        sigma_d = uu[6 + 2 * n : 9 + 2 * n]
        z1_paper = [sigma[i] - sigma_d[i] for i in range(3)]  # 001 (23)
        z1 = [z1_paper[2], z1_paper[1], z1_paper[0]] if self.pairing else z1_paper
        omega_d, omega_d_dot = self._virtual(np.array(sigma), np.array(omega), np.array(z1))
        z2 = [omega[i] - omega_d[i] for i in range(3)]  # 001 (23)
        b1, b2 = self._beta_1, self._beta_2
        f1 = [sig(z1[i], b1[i]) for i in range(3)]
        f2 = [sig(z1[i], b2[i]) for i in range(3)]
        p1 = self.hist_1.past_sum().tolist()
        p2 = self.hist_2.past_sum().tolist()
        A = [self._hp1[i] * (f1[i] + p1[i]) for i in range(3)]  # GL D^alpha_1 f1
        B = [self._hp2[i] * (f2[i] + p2[i]) for i in range(3)]  # GL I^(1 - alpha_2) f2
        h = self.h
        if self.k > 0:
            dA = [(A[i] - self.A_prev[i]) / h for i in range(3)]  # D^(alpha_1 + 1) f1, 001 (22)
            dB = [(B[i] - self.B_prev[i]) / h for i in range(3)]  # D^alpha_2 f2
        elif self.strict_start:
            dA, dB = [x / h for x in A], [x / h for x in B]
        else:
            dA = dB = [0.0, 0.0, 0.0]
        a, b, e1, e2, r, phi = self._a, self._b, self._eps_1, self._eps_2, self.r, self.phi
        s = [z2[i] + a[i] * A[i] + b[i] * B[i] for i in range(3)]  # 001 (30)
        if phi > 0:
            sw = [max(-1.0, min(1.0, x / phi)) for x in s]
        else:
            sw = [(x > 0) - (x < 0) for x in s]
        srt = [sig(x, r) for x in s]
        u_cm = [-a[i] * dA[i] - b[i] * dB[i] - e1[i] * sw[i] - e2[i] * srt[i] + omega_d_dot[i] for i in range(3)]  # 001 (35)
        (j11, j12, j13), (j21, j22, j23), (j31, j32, j33) = self._Jl
        w1, w2, w3 = omega
        h1, h2, h3 = j11 * w1 + j12 * w2 + j13 * w3, j21 * w1 + j22 * w2 + j23 * w3, j31 * w1 + j32 * w2 + j33 * w3
        gyro = (w2 * h3 - w3 * h2, w3 * h1 - w1 * h3, w1 * h2 - w2 * h1)
        muf = (self.M @ uf_hat).tolist()
        ups = self._ups
        rest = [gyro[i] - muf[i] - ups[i] for i in range(3)]
        # J (u_cn + u_cm) with u_cn = J^-1 (omega x J omega - M uf_hat - Upsilon_hat), 001 (34)
        v = [rest[0] + j11 * u_cm[0] + j12 * u_cm[1] + j13 * u_cm[2],
             rest[1] + j21 * u_cm[0] + j22 * u_cm[1] + j23 * u_cm[2],
             rest[2] + j31 * u_cm[0] + j32 * u_cm[1] + j33 * u_cm[2]]
        e = np.clip(e_in, self.e_min, self.e_max)
        Q = (self.M * e**3) @ self.M.T  # M E_hat^3 M^T
        q11, q12, q13, _, q22, q23, _, _, q33 = Q.ravel().tolist()
        lam = min_eig_sym3(q11, q12, q13, q22, q23, q33)
        if not lam >= self.min_eig:
            raise FloatingPointError(
                f"allocation 001 (33) singular: lambda_min(M E_hat^3 M^T) = {lam:.3g} < alloc_min_eig = {self.min_eig:g} "
                f"(e_hat used = {np.round(e, 4).tolist()}; Assumption 2.3 allows at most N - 3 failed wheels)"
            )
        y = solve_sym3(q11, q12, q13, q22, q23, q33, v[0], v[1], v[2])  # (J^-1 M E^3 M^T)^-1 = (M E^3 M^T)^-1 J
        u_c = (e**2) * (self.M.T @ np.array(y))  # 001 (33)
        return u_c, np.array(s), np.array(z1_paper), np.array(z2), f1, f2, A, B

    def _compute_kernel(self, u: np.ndarray):
        """``_compute`` through the kernel (c = 0): same values, same types for the callers."""
        n = self.n
        self._kprm[_kernel.STARTED] = 1.0 if self.k > 0 else 0.0
        g = np.array([self._hp1, self._hp2, self._beta_1, self._beta_2, self._a, self._b, self._eps_1, self._eps_2,
                      self.A_prev, self.B_prev])
        out = _kernel.law(np.asarray(u, dtype=float), self.hist_1.past_sum(), self.hist_2.past_sum(), self._kprm, g,
                          self.J, self.M, self.upsilon)
        lam = out[n + 21]
        if not lam >= self.min_eig:
            e = np.clip(np.asarray(u[6 : 6 + n], dtype=float), self.e_min, self.e_max)
            raise FloatingPointError(
                f"allocation 001 (33) singular: lambda_min(M E_hat^3 M^T) = {lam:.3g} < alloc_min_eig = {self.min_eig:g} "
                f"(e_hat used = {np.round(e, 4).tolist()}; Assumption 2.3 allows at most N - 3 failed wheels)"
            )
        v = out[n:].tolist()
        return (out[:n], out[n : n + 3], out[n + 3 : n + 6], out[n + 6 : n + 9], v[9:12], v[12:15], v[15:18], v[18:21])

    # -- the contract ---------------------------------------------------------------------------------
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        u_c, s, z1, z2 = self._terms(u)[:4]
        return np.concatenate((u_c, s, z1, z2, self.upsilon))

    def step_tolerance(self, t: float, h: float) -> float:
        """How far a step may differ from ``fo_step`` and still be the step (s): see "Steps" above."""
        return 1e-9 * self.h + 2.0 * (self.k + 1) * _EPS * max(1.0, abs(t) + abs(h))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        tol = self.step_tolerance(t, h)
        if self._pending is None and abs(h - self.h) <= tol:  # the usual step: one GL sample
            _, s, _, _, f1, f2, A, B = self._terms(u)
            self.upsilon = self.upsilon + self.h * self.rho * (self.JiT @ s)  # 001 (36), exact for held inputs
            self._ups = self.upsilon.tolist()
            self._sample(f1, f2, A, B)
            return
        done = self._partial + h
        if not (h > 0.0 and done <= self.h + tol):
            where = f" after {self._partial:g} s of the sample interval" if self._pending is not None else ""
            raise ValueError(
                f"fo_step = {self.h:g} s but the communication step is {h:g} s{where}: the fractional operators are "
                f"sampled every fo_step; set fo_step to the communication step (steps may be shorter, never longer)"
            )
        _, s, _, _, f1, f2, A, B = self._terms(u)
        if self._pending is None:
            self._pending = (f1, f2, A, B)  # the operators' values at the start of the sample interval
        self.upsilon = self.upsilon + h * self.rho * (self.JiT @ s)  # 001 (36) over the shorter step
        self._ups = self.upsilon.tolist()
        self._partial = done
        if abs(done - self.h) <= tol:
            self._sample(*self._pending)
        else:
            self._touch()

    def _sample(self, f1, f2, A, B) -> None:
        """Close a sample interval: push the GL samples taken at its start."""
        self.hist_1.push(f1)
        self.hist_2.push(f2)
        self.A_prev, self.B_prev = list(A), list(B)
        self.k += 1
        self._partial, self._pending = 0.0, None
        self._touch()

    def get_state(self) -> list:
        h1, h2 = self.hist_1.samples(), self.hist_2.samples()
        head = self.upsilon.tolist() + list(self.A_prev) + list(self.B_prev) + [float(self.k), float(len(h1))]
        pending = [1.0, *(x for part in self._pending for x in part)] if self._pending is not None else [0.0] * 13
        return head + h1.ravel().tolist() + h2.ravel().tolist() + [self._partial] + pending

    def set_state(self, state) -> None:
        s = np.array(state, dtype=float)
        self.upsilon, self.A_prev, self.B_prev = s[0:3].copy(), s[3:6].tolist(), s[6:9].tolist()
        self._ups = self.upsilon.tolist()
        self.k = int(s[9])
        m = int(s[10])
        self.hist_1.set_samples(s[11 : 11 + 3 * m])
        self.hist_2.set_samples(s[11 + 3 * m : 11 + 6 * m])
        tail = s[11 + 6 * m :].tolist() or [0.0, 0.0]  # without the tail (older states): no interval in progress
        self._partial = float(tail[0])
        self._pending = (tail[2:5], tail[5:8], tail[8:11], tail[11:14]) if tail[1] else None
        self._touch()
