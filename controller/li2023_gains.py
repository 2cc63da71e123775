"""Published gains of the fuzzy adaptive sliding-mode FTC, 000 Appendix A.2, and of the
AISMC baseline, 000 section 5.3 (b).

* ``K_C`` (8, 3, 3): K_c^i, rule i = 1..8 at ``K_C[i-1]``, virtual control v of 000 (40);
  also used by the AISMC baseline (000 (70)-(71) say its K_c^i come from ref. [21], which
  we do not have: we reuse A.2, as the issue asks).
* ``GAMMA_2``, ``MU``, ``PHI_2``, ``EPS_2``: design data of Theorem 2 (not used at run time).
  (phi_2, eps_2) is printed as (20, 20); a disc centred at +20 lies in the right half-plane, and the
  eigenvalues of A_i + B K_c^i (about -0.11 +- 1.3j and -0.12) lie in O(-20, 20): the sign of phi_2
  was evidently lost. ``PHI_2`` keeps the printed value; tests/test_fasmc.py checks the O(-20, 20) reading.
* ``BETA``, ``VARSIGMA`` (bound on ||v||_2), ``SIGMA_1``, ``SIGMA_2``, ``SIGMA_2_PRIME``: 000 (39), (40), (64).
* ``AISMC_BETA``, ``AISMC_SIGMA``, ``AISMC_SIGMA_PRIME``: 000 (70)-(71).
"""
import math

import numpy as np

# 000 A.2: K_c^i, i = 1..8
K_C = np.array(
    [
        # K_c^1
        [
            [-34.7440,   1.1063,   1.0937],
            [  1.4111, -33.8341,  -0.8464],
            [  0.3764,  -0.5589, -20.8476],
        ],
        # K_c^2
        [
            [-35.4191,   0.5616,   0.7990],
            [  1.4483, -33.8696,  -1.6043],
            [  0.1094,  -1.6136, -20.9780],
        ],
        # K_c^3
        [
            [-31.9910,   0.9290,   0.8885],
            [  1.5486, -33.8368,  -1.0351],
            [  1.9635,  -0.6481, -19.9350],
        ],
        # K_c^4
        [
            [-32.5344,   0.5510,   0.5865],
            [  1.2052, -33.8601,  -1.4684],
            [  1.6329,  -1.2981, -20.0662],
        ],
        # K_c^5
        [
            [-35.0347,  -0.6622,   0.8585],
            [ -0.0102, -34.0008,  -0.8408],
            [  0.0632,  -0.9848, -21.1602],
        ],
        # K_c^6
        [
            [-35.2320,  -1.2476,   1.2101],
            [  0.0100, -33.8693,  -1.6387],
            [  0.8286,  -2.0212, -21.1286],
        ],
        # K_c^7
        [
            [-32.1281,  -0.5289,   0.6218],
            [  0.2065, -34.0080,  -1.0504],
            [  1.5953,  -1.1829, -20.1715],
        ],
        # K_c^8
        [
            [-32.2891,  -0.9208,   0.9916],
            [ -0.1776, -33.8574,  -1.4950],
            [  2.2599,  -1.8550, -20.1519],
        ],
    ]
)

GAMMA_2 = 1.7919  # 000 A.2
MU = 0.1  # 000 A.2, bound on ||s(0)||_2 used in (43)
PHI_2, EPS_2 = 20.0, 20.0  # 000 A.2, pole region O(phi_2, eps_2) as printed
BETA = 2.0  # 000 A.2, 1/s, s = omega_e + beta q_ev (39)
VARSIGMA = 5.0 * math.sqrt(3.0)  # 000 A.2, bound on ||v||_2 (44)
SIGMA_1 = 0.2  # 000 A.2, (64)
SIGMA_2 = 0.15  # 000 A.2, (64)
SIGMA_2_PRIME = 1e-4  # 000 A.2, (64)

# 000 section 5.3 (b), AISMC baseline (70)-(71)
AISMC_BETA = 2.0
AISMC_SIGMA = 0.002
AISMC_SIGMA_PRIME = 0.01
