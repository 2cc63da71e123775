"""Paper 004 section 4 (and what it leaves out): numpy-only data, SI units.

"printed" = exactly as the seed text shows it; "reading" = our interpretation of garbled text;
"ours" = a value the paper does not give (it refers to "Ref. [24]", which we do not have).
README.md lists every entry with its reason.
"""
import math

import numpy as np

# -- plant (printed) ------------------------------------------------------------------------
# Same hub inertia J as 000; its own coupling delta (three entries differ from 000's) and modes.
XU2024 = {
    "J": np.array([[350.0, 3.0, 4.0], [3.0, 270.0, 10.0], [4.0, 10.0, 190.0]]),
    "delta": np.array(
        [
            [6.45637, 1.27814, 2.15629],
            [-1.25619, 0.91756, -1.67264],
            [1.11687, 2.48901, -0.83674],
            [1.23637, -2.6581, -1.12503],
        ]
    ),
    "omega_n": np.array([0.7681, 1.1038, 1.8733, 2.5496]),
    "zeta": np.array([0.0056, 0.0086, 0.013, 0.025]),
}

# d(t) of section 4 (printed, N.m), as bias + sum_k a_cos cos(w t) + a_sin sin(w t), 2 terms per axis:
#   d1 = -0.2 + 0.1 cos(0.06 t) - 0.1 cos(0.8 t)   ("0.06" as printed; 0.6 would match the others)
#   d2 =  0.2 + 0.2 sin(0.6 t)  - 0.1 cos(0.4 t)
#   d3 = -0.2 + 0.15 sin(0.5 t) - 0.1 sin(0.8 t)
DISTURBANCE = {
    "bias": np.array([-0.2, 0.2, -0.2]),
    "a_cos": np.array([[0.1, -0.1], [0.0, -0.1], [0.0, 0.0]]),
    "a_sin": np.array([[0.0, 0.0], [0.2, 0.0], [0.15, -0.1]]),
    "freq": np.array([[0.06, 0.8], [0.6, 0.4], [0.5, 0.8]]),
}

# -- T-S model (printed points; rule/membership pairing a reading) ----------------------------
OPERATING_POINTS = np.array([
    [0.0] * 6,
    [1.0, 1.0, 1.0, 0.55, 0.55, 0.55],
    [-1.0, -1.0, -1.0, -0.55, -0.55, -0.55],
])
MEMBERSHIP = {
    "z_half_width": np.array([1.0, 1.0, 1.0, 0.55, 0.55, 0.55]),  # domains printed in section 4
    "z_slope": np.array([1.0, 1.0, 1.0, 1.818, 1.818, 1.818]),  # 1.818 printed (1/0.55 = 1.8181...)
}
# Rule i uses, on every premise, the triangle peaking at its operating point: rule 1 (P1 = 0)
# M^1 (peak 0), rule 2 (P2 = +) the printed M^3 (peak +b), rule 3 (P3 = -) the printed M^2
# (peak -b). "literal" keeps the printed index pairing (rule 2 with M^2, peak -b, although A_2
# is taken at +b).
RULE_PEAKS = {
    "matched": np.array([[0.0] * 6, [1.0] * 6, [-1.0] * 6]),
    "literal": np.array([[0.0] * 6, [-1.0] * 6, [1.0] * 6]),
}

# -- sensor network (printed) -------------------------------------------------------------------
NETWORK = {
    "Theta": np.array([[-0.8, 0.3, 0.5], [0.5, -1.0, 0.5], [0.7, 0.6, -1.3]]),
    "L_gain": np.array([0.8, 0.5, 0.9]),  # L_1 = 0.8 I, L_2 = 0.5 I, L_3 = 0.9 I
}

# -- actuator faults (printed; v ours) -------------------------------------------------------------
# Case I normal F_1 = I, G_1 = 0; Case II partial loss F_2 = diag(0.7, 0.8, 0.6), G_2 = 0;
# Case III bias, printed "F_1 = I, G_1 = I" (a label typo for F_3 = I, G_3 = I).
FAULT_MODES = {
    "F": np.array([[1.0, 1.0, 1.0], [0.7, 0.8, 0.6], [1.0, 1.0, 1.0]]),
    "G": np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]),
    "v": np.array([0.1, 0.1, 0.1]),  # ours: v(t) is not printed; constant 0.1 N.m per axis
}

# -- Markov rates (printed) ---------------------------------------------------------------------------
PI_1 = np.array([[-1.7, 0.9, 0.8], [1.0, -5.0, 4.0], [1.6, 1.1, -2.7]])  # (53)
PI_2 = np.array([[-5.0, 2.0, 3.0], [0.1, -0.5, 0.4], [1.0, 1.0, -2.0]])  # (53)
RATE_VERTICES = np.stack([PI_1, PI_2])  # Pi(t) = cos^2(t) Pi_1 + sin^2(t) Pi_2, (52)
R0 = 1  # ours: the initial mode is not printed
# Remark 3, (12)-(13): a two-state example (Fig. 1)
REMARK3_VERTICES = np.stack([np.array([[-3.0, 3.0], [2.0, -2.0]]), np.array([[-4.0, 4.0], [3.0, -3.0]])])

# -- initial state ------------------------------------------------------------------------------------
X0_PRINTED = np.array([2.0, -1.5, 1.0, -2.0, 1.0, -2.0])  # [omega (rad/s), q part]; |q part| = 3


def x0_gibbs_quaternion(x0=X0_PRINTED):
    """Reading for the nonlinear plant (ours): the printed q part g as a Gibbs vector q_v/q0,
    q = [1, g] / sqrt(1 + g^T g) = [1, -2, 1, -2] / sqrt(10)."""
    g = np.asarray(x0[3:], dtype=float)
    return np.concatenate(([1.0], g)) / math.sqrt(1.0 + float(g @ g))


# -- sampling (ours: "the same as Ref. [24]") -----------------------------------------------------------
SAMPLING = {"tau_min": 0.05, "tau_max": 0.1, "sample_quantum": 0.001}

# -- Theorem 2 scalars ----------------------------------------------------------------------------------
PRINTED_SCALARS = {"gamma": 0.1, "eps1": 1.0, "eps2": -0.1}
# ours (not printed); eps2 = +0.1: the printed -0.1 is provably infeasible (design.eps2_certificate)
DESIGN_SCALARS = {
    "alpha": 0.1, "T": 10.0, "c1": 1.0, "tau_M": SAMPLING["tau_max"], "gamma": 0.1, "eps1": 1.0, "eps2": 0.1,
    "eta": (1.0, 1.0, 1.0), "d_hat": 0.0, "rho_mm": 0.1, "average": 0.25, "m_s": 1.0,
}
PUBLISHED_C2 = {"one_mode": 6.0114, "three_modes": 5.7741, "ref24": 5.4}
