"""001 section 5: the published observer and controller gains, verbatim, and our values for the
constants 001 leaves out (marked "not in 001").

Observer 001 (12), (14), (15): "Lambda = 5diag{1, 1, 1}, lambda_1 = 0.5, lambda_2 = 0.6 and
lambda_3 = 0.8".

Controller 001 (30)-(36): "a = b = diag{1, 1, 1}, alpha_1 = diag{0.01, 0.01, 0.01},
alpha_2 = diag{0.99, 0.99, 0.99}, beta_1 = diag{0.9, 0.9, 0.9}, beta_2 = diag{0.8, 0.8, 0.8},
r = 5/7, epsilon_1 = 1.5diag{1, 1, 1} and epsilon_2 = 2.8diag{1, 1, 1}. In addition, the adaptive
parameters are selected as rho = 0.3."

Not in 001 (our readings, see README.md): epsilon and mu of (15), K(0), the observer's initial
values, c of (27), Upsilon_hat(0), the fractional discretisation, memory and start-up, whether
sign(s) is smoothed. ``FAST_OBSERVER`` is our documented gain choice that estimates the fault
torque within the run (the printed lambda_1, lambda_2 need 1e3-7e3 s, README section "Observer").
"""
import numpy as np

# -- observer, 001 section 5 (printed) ---------------------------------------------------------
LAMBDA = np.array([5.0, 5.0, 5.0])  # 1/s
LAMBDA_1 = 0.5
LAMBDA_2 = 0.6
LAMBDA_3 = 0.8

# -- observer, not in 001 ------------------------------------------------------------------------
EPSILON = 1e-4  # rad/s, boundary of ||omega~|| in (15)
MU = 1e-4  # N.m, floor of K in (15) ("very small")
K_INIT = 1e-4  # N.m, K(0) (small: a large K(0) holds omega~ in a sliding mode and freezes (14))

# our gain choice for fault estimation within the run (not in 001): all slow modes of the
# linearised bias-error system faster than ~1.8 s (README, "Observer")
FAST_OBSERVER = {"lambda_1": 2000.0, "lambda_2": 2000.0}

# -- controller, 001 section 5 (printed) ---------------------------------------------------------
A = np.array([1.0, 1.0, 1.0])
B = np.array([1.0, 1.0, 1.0])
ALPHA_1 = np.array([0.01, 0.01, 0.01])
ALPHA_2 = np.array([0.99, 0.99, 0.99])
BETA_1 = np.array([0.9, 0.9, 0.9])
BETA_2 = np.array([0.8, 0.8, 0.8])
R = 5.0 / 7.0
EPS_1 = np.array([1.5, 1.5, 1.5])  # rad/s2
EPS_2 = np.array([2.8, 2.8, 2.8])
RHO = 0.3

# -- controller, not in 001 ---------------------------------------------------------------------
C = 0.0  # 1/s, backstepping gain of (27)
FO_MEMORY_FULL = 1000.0  # s: longer than any run, i.e. the full RL memory of (21) from t0
