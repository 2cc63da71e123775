"""Adaptive nonsingular terminal sliding-mode fault-tolerant control (ASMFTC), 003 (3.9)-(3.21), one axis.

With e = theta - theta_d, e' = theta' - theta_d', r = k1/k2 and sig(x)^a = sign(x) |x|^a:

    s      = e + N sig(e')^r                                                   003 (3.9)
    u      = -(k2/k1) J1 N^-1 sig(e')^(2-r) - d0_hat - f_hat - Phi sw(s)        003 (3.10) / (3.21)
    sw(s)  = sign(s)  (3.10)     or     s / (|s| + gamma3)  (3.21)
    Phi    = (1 + lambda_hat) delta   [or (lambda_hat - 1) delta]              003 (3.12)
    delta  = |(k2/k1) J1 N^-1 sig(e')^(2-r)| + |d0_hat| + |f_hat| + I0          003 (3.15)
    f_hat' = [-gamma2 f_hat] + r beta |e'|^(r-1) N s                           003 (3.11) / (3.20)
    lam'   = [-gamma1 lam] + alpha delta |s|                                   003 (3.13) / (3.19)
    J1     = J - F F^T                                                         003 (3.14)

(the bracketed leakage terms only with Remark 5's (3.19)-(3.20)). d0_hat comes from the TSFDO
(``estimator/tsfdo.py``); unconnected (0) it is the same controller without the observer.

003's extraction dropped every minus sign, norm bar and fraction bar (papers/p003_hang2023/README.md).
Readings, each selectable by a parameter; the defaults are the readings under which the closed loop
behaves as 003 claims (evidence: the closed-loop runs in papers/p003_hang2023/README.md and the tests):

* ``error_sign`` = +1 (default): e = theta - theta_d. 003 section 2 defines e = theta_d - theta, but its
  (3.16) uses e'' = +J1^-1 (torque), which holds only for theta - theta_d; with the literal sign
  (``error_sign`` = -1) the printed law feeds back +e and +e' and the loop diverges within seconds.
* ``phi_form`` = 1 (default): Phi = (1 + lambda_hat) delta, reading "Phi = delta + lambda_hat delta" as
  printed; 0: Phi = (lambda_hat - 1) delta (a leading minus lost), the form the proof of (3.17) needs.
  With 0, Phi vanishes for lambda_hat = 1 (no fault) and turns negative under the leaky law (3.19):
  the loop drifts away with (3.19)-(3.20).
* ``lambda_law`` = 0 (default): lam' as printed in (3.13)/(3.19), alpha delta |s|; 1: the form the
  proof uses, alpha delta r |s N |e'|^(r-1)|.
* ``switching``: 0 sign(s) of (3.10), 1 s / (|s| + gamma3) of (3.21) (003 Remark 6).
* ``leakage``: 0 the laws (3.11), (3.13); 1 Remark 5's (3.19), (3.20). 003 does not say which laws go
  with which control law; its scenarios here pair (3.10) with (3.11)+(3.13) and (3.21) with (3.19)+(3.20).
* Norms |.| of the pitch-axis scalars; N, f_hat scalar (003 writes the three-axis form).

Evidence (003's set-up: published observer gain, 0.5 ms exchange, factor 0.4 at 20 s, 60 s runs):
literal error sign: diverges within 1.4 s ((3.21)) / 0.6 s ((3.10)); (lambda_hat - 1) delta with
(3.19)-(3.20): theta 0.08 -> 0.83 rad ((3.10)) and -> 0.27 rad ((3.21)); (1 + lambda_hat) delta converges
with every law combination ((3.10): |theta| < 4e-6 rad over the last 10 s; (3.21) with gamma3 = 1 creeps
to 0.032 rad at 60 s). Proof-form lambda law with (lambda_hat - 1) delta: stuck at -0.024 rad.

Integration: f_hat, lambda_hat by RK4 with internal step <= ``h_max`` over the communication step,
inputs held (s, e' and d0_hat constant over the step); the outputs use the state at the
communication point.

Inputs:  theta (rad), theta_dot (rad/s), theta_d (rad), theta_d_dot (rad/s), d0_hat (N.m)
Outputs: u (N.m), s (rad), e_theta (rad), e_theta_dot (rad/s), f_hat (N.m), lambda_hat (1),
         Phi (N.m), delta (N.m)
"""
from __future__ import annotations

import math

import numpy as np

from plant.block import Block, scalar
from plant.integrate import h_max_parameter, substeps
from plant.pitch_axis import pitch_inputs, pitch_parameters


def sig(x: float, a: float) -> float:
    """sign(x) |x|^a."""
    return math.copysign(abs(x) ** a, x) if x != 0.0 else 0.0


class ASMFTC(Block):
    model_name = "ASMFTC"
    description = "Adaptive terminal sliding-mode FTC, 003 (3.9)-(3.15), (3.19)-(3.21), single axis"

    def __init__(self, n_modes: int = 2):
        n = self.n = int(n_modes)
        inputs = pitch_inputs() + scalar("d0_hat", 0.0, "N.m", "disturbance estimate (TSFDO; 0 without observer)")
        outputs = (
            scalar("u", 0.0, "N.m", "commanded control torque, 003 (3.10) or (3.21)")
            + scalar("s", 0.0, "rad", "terminal sliding variable, 003 (3.9)")
            + scalar("e_theta", 0.0, "rad", "attitude error")
            + scalar("e_theta_dot", 0.0, "rad/s", "rate error")
            + scalar("f_hat", 0.0, "N.m", "adaptive bound estimate, 003 (3.11) / (3.20)")
            + scalar("lambda_hat", 1.0, "1", "fault-factor estimate, 003 (3.13) / (3.19)")
            + scalar("Phi", 0.0, "N.m", "switching gain, 003 (3.12)")
            + scalar("delta", 0.0, "N.m", "003 (3.15)")
        )
        params = (
            pitch_parameters(n, "model; J1 = J - F F^T")
            + scalar("N", 1.0, "1", "sliding-surface gain N > 0, 003 (3.9)")
            + scalar("k1", 5.0, "1", "odd positive, 1 < k1/k2 < 2")
            + scalar("k2", 3.0, "1", "odd positive")
            + scalar("I0", 1.0, "N.m", "I0 > 0 of 003 (3.15)")
            + scalar("alpha", 1.0, "1", "adaptation gain of lambda_hat")
            + scalar("beta", 1.0, "1", "adaptation gain of f_hat")
            + scalar("gamma1", 1.0, "1/s", "leakage of lambda_hat, 003 (3.19)")
            + scalar("gamma2", 1.0, "1/s", "leakage of f_hat, 003 (3.20)")
            + scalar("gamma3", 1.0, "rad", "boundary width of s/(|s| + gamma3), 003 (3.21)")
            + scalar("switching", 1, "1", "0: sign(s) (3.10), 1: s/(|s| + gamma3) (3.21)")
            + scalar("leakage", 1, "1", "0: laws (3.11), (3.13); 1: (3.19), (3.20)")
            + scalar("phi_form", 1, "1", "1: Phi = (1 + lambda_hat) delta, 0: (lambda_hat - 1) delta")
            + scalar("lambda_law", 0, "1", "0: alpha delta |s| (as printed), 1: proof form")
            + scalar("error_sign", 1, "1", "+1: e = theta - theta_d (reading), -1: theta_d - theta (literal)")
            + scalar("f_hat_init", 0.0, "N.m", "initial f_hat")
            + scalar("lambda_hat_init", 1.0, "1", "initial lambda_hat (lambda = 1/(1 - sigma) = 1 healthy)")
            + h_max_parameter(1e-3)
        )
        err = ("theta", "theta_dot", "theta_d", "theta_d_dot")
        feed = {"u": err + ("d0_hat",), "s": err, "e_theta": ("theta", "theta_d"),
                "e_theta_dot": ("theta_dot", "theta_d_dot"), "Phi": ("theta_dot", "theta_d_dot", "d0_hat"),
                "delta": ("theta_dot", "theta_d_dot", "d0_hat")}
        super().__init__(inputs, outputs, params, feed)
        self.f_hat, self.lam = 0.0, 1.0

    # -- set-up -----------------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        name = self.model_name
        J, F = self.p("J"), self.p_vector("F")
        if not J > 0:
            raise ValueError(f"{name}: J (pitch inertia) must be > 0 kg.m2, got {J:g}")
        self.J1 = J - float(F @ F)  # 003 (3.14)
        if not self.J1 > 0:
            raise ValueError(f"{name}: J1 = J - F F^T = {self.J1:g} kg.m2 must be > 0")
        k1, k2 = self.p("k1"), self.p("k2")
        for k, v in (("k1", k1), ("k2", k2)):
            if not (v > 0 and v == round(v) and int(round(v)) % 2 == 1):
                raise ValueError(f"{name}: {k} must be a positive odd integer (003 (3.9)), got {v:g}")
        if not 1.0 < k1 / k2 < 2.0:
            raise ValueError(f"{name}: 1 < k1/k2 < 2 is required (003 (3.9)), got k1/k2 = {k1 / k2:g}")
        self.r = k1 / k2
        self.N = self.p("N")
        for k in ("N", "I0", "alpha", "beta"):
            if not self.p(k) > 0:
                raise ValueError(f"{name}: {k} must be > 0, got {self.p(k):g}")
        for k in ("gamma1", "gamma2"):
            if self.p(k) < 0:
                raise ValueError(f"{name}: {k} must be >= 0, got {self.p(k):g}")
        opts = {"switching": (0, 1), "leakage": (0, 1), "phi_form": (0, 1), "lambda_law": (0, 1), "error_sign": (1, -1)}
        for k, allowed in opts.items():
            if self.p(k) not in allowed:
                raise ValueError(f"{name}: {k} must be one of {allowed}, got {self.p(k):g}")
        self.smooth = self.p("switching") == 1
        self.gamma3 = self.p("gamma3")
        if self.smooth and not self.gamma3 > 0:
            raise ValueError(f"{name}: gamma3 must be > 0 with switching = 1 (3.21), got {self.gamma3:g}")
        leak = self.p("leakage") == 1
        self.g1 = self.p("gamma1") if leak else 0.0
        self.g2 = self.p("gamma2") if leak else 0.0
        self.phi_plus = self.p("phi_form") == 1
        self.proof_lambda = self.p("lambda_law") == 1
        self.sgn = self.p("error_sign")
        self.I0, self.alpha, self.beta = self.p("I0"), self.p("alpha"), self.p("beta")
        self.ceq = (k2 / k1) * self.J1 / self.N  # (k2/k1) J1 N^-1
        self.h_max = self.p("h_max")
        if not self.h_max > 0:
            raise ValueError(f"{name}: h_max must be > 0 s, got {self.h_max:g}")
        self.f_hat, self.lam = self.p("f_hat_init"), self.p("lambda_hat_init")

    # -- the law ------------------------------------------------------------------------------
    def errors(self, u):
        """(e, e', s) from the inputs, 003 (3.9)."""
        e = self.sgn * (u[0] - u[2])
        ed = self.sgn * (u[1] - u[3])
        return e, ed, e + self.N * sig(ed, self.r)

    def law(self, u, f_hat: float, lam: float):
        """(u, s, e, e', Phi, delta) for the inputs and the adaptive states."""
        e, ed, s = self.errors(u)
        d0 = float(u[4])
        ueq = self.ceq * sig(ed, 2.0 - self.r)
        delta = abs(ueq) + abs(d0) + abs(f_hat) + self.I0  # 003 (3.15)
        phi = (1.0 + lam) * delta if self.phi_plus else (lam - 1.0) * delta  # 003 (3.12)
        if self.smooth:
            sw = s / (abs(s) + self.gamma3)  # 003 (3.21)
        else:
            sw = 0.0 if s == 0.0 else math.copysign(1.0, s)  # s / ||s|| of (3.10)
        cmd = -ueq - d0 - f_hat - phi * sw  # 003 (3.10) / (3.21)
        return cmd, s, e, ed, phi, delta

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        cmd, s, e, ed, phi, delta = self.law(u, self.f_hat, self.lam)
        return np.array([cmd, s, e, ed, self.f_hat, self.lam, phi, delta])

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        e, ed, s = self.errors(u)
        r, N = self.r, self.N
        grad = r * abs(ed) ** (r - 1.0) * N  # (k1/k2) diag{e'^(k1/k2 - 1)} N (even power: |e'|^(2/3))
        f_drive = self.beta * grad * s  # 003 (3.11)
        s_norm = abs(grad * s) if self.proof_lambda else abs(s)
        a_s = self.alpha * s_norm
        base = self.ceq * abs(ed) ** (2.0 - r) + abs(float(u[4])) + self.I0  # delta without |f_hat|
        g1, g2 = self.g1, self.g2

        def deriv(f, lam):
            return -g2 * f + f_drive, -g1 * lam + a_s * (base + abs(f))  # (3.20), (3.19) [leak 0: (3.11), (3.13)]

        steps, dt = substeps(h, self.h_max)
        f, lam = self.f_hat, self.lam
        for _ in range(steps):
            a1, b1 = deriv(f, lam)
            a2, b2 = deriv(f + 0.5 * dt * a1, lam + 0.5 * dt * b1)
            a3, b3 = deriv(f + 0.5 * dt * a2, lam + 0.5 * dt * b2)
            a4, b4 = deriv(f + dt * a3, lam + dt * b3)
            f += dt / 6.0 * (a1 + 2.0 * (a2 + a3) + a4)
            lam += dt / 6.0 * (b1 + 2.0 * (b2 + b3) + b4)
        if not (math.isfinite(f) and math.isfinite(lam)):
            raise FloatingPointError(f"{self.model_name}: adaptive states not finite at t = {t + h:.6g} s")
        self.f_hat, self.lam = f, lam

    def get_state(self) -> list:
        return [self.f_hat, self.lam]

    def set_state(self, state) -> None:
        self.f_hat, self.lam = float(state[0]), float(state[1])
