"""Paper 003 section 4: the pitch-axis flexible satellite and the disturbance exosystem (numpy only, SI).

Pitch inertia 6.14 kg m^2 (the middle entry of 003 (4.1), read as diag(5.5, 6.14, 2.18)),
H = [1.27806, 0.91758], n_1 = 3.17, n_2 = 7.38 rad/s, damping 0.001, 0.0016.

Exosystem (003 (4.x), printed "W1=[1250], W2=[0640], V1=[40], V2=[30]", signs lost in
extraction): W1 = [[-1, 2], [-5, 0]], W2 = [[0, 6], [-4, 0]], V1 = [4, 0], V2 = [3, 0]; see
``papers/p003_hang2023/design.py`` for why these signs.
"""
import numpy as np

HANG2023 = {"J": 6.14, "F": np.array([1.27806, 0.91758]), "omega": np.array([3.17, 7.38]),
            "xi": np.array([0.001, 0.0016])}
W = (np.array([[-1.0, 2.0], [-5.0, 0.0]]), np.array([[0.0, 6.0], [-4.0, 0.0]]))
V = (np.array([[4.0, 0.0]]), np.array([[3.0, 0.0]]))

# Gaussian memberships of 003 section 4 (A11 -> rule 1, A21 -> rule 2; printed "sigma21 = 0.5, sigma22 = 1"
# read as the variances sigma_1^2 = 0.5, sigma_2^2 = 1). The premise variable z1 is not defined by 003:
# ours is theta (estimator/tsfdo.py, premise = 0).
MF_CENTER = (1.5, 1.0)
MF_SIGMA2 = (0.5, 1.0)

# 003 section 4, as printed: N = 5, k1 = 5, k2 = 3, I0 = 0.5, alpha = beta = 1, gamma1 = gamma2 = gamma3 = 1
ASMFTC_GAINS = {"N": 5.0, "k1": 5.0, "k2": 3.0, "I0": 0.5, "alpha": 1.0, "beta": 1.0,
                "gamma1": 1.0, "gamma2": 1.0, "gamma3": 1.0}

# 003 (4.2), pitch component T_2y = 4.5e-5 (3 cos n0 t + 1.5 sin n0 t) N.m (exponent sign restored),
# orbit rate n0 = 0.0011 rad/s as printed (a 900 km orbit has 1.02e-3 rad/s).
DISTURBANCE = {"dist_amplitude": 4.5e-5, "dist_n0": 0.0011, "dist_cos": 3.0, "dist_sin": 1.5, "dist_const": 0.0}

# Loss of effectiveness of 003 section 4 (Figs. 9-10): rho = 1 until 20 s, then the "failure factor".
FAULT_ONSET = 20.0
FAULT_FACTORS = (0.4, 0.8, 1.0)

# Not given by 003 (ours): 002's initial state (same Liu-Guo-Zhang plant lineage), modes at rest.
X0 = (0.08, 0.04)  # theta(0) rad, theta'(0) rad/s

# The set under the plant block's parameter names (scenarios: parameter_set = "hang2023")
PARAMETER_SET = {"J": HANG2023["J"], "F": HANG2023["F"], "omega_n": HANG2023["omega"], "zeta": HANG2023["xi"]}
