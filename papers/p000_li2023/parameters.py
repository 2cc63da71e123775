"""Paper 000 section 5: the flexible spacecraft and the simulation set-up (numpy only, SI).

``LI2023`` is the parameter set ``parameter_set = "li2023"`` of the scenarios: hub inertia
``J`` (kg m^2), rigid/flexible coupling ``delta`` (n x 3, as printed), modal natural frequencies
``omega_n`` (rad/s) and damping ratios ``zeta`` (1) of the first four modes.

Set-up of 000 section 5.2 / Table 1 (readings in README.md): q_v(0) = (0.3, 0.2, -0.4) with
q_0 > 0, omega(0) = (0.02, -0.03, 0.01) rad/s, modes at rest; misalignment Delta a, Delta b in
degrees; the target q_dv = (0.3, 0.2, -0.4) until 80 s, then (0.2, -0.1, -0.1).
"""
import math

import numpy as np

LI2023 = {
    "J": np.array([[350.0, 3.0, 4.0], [3.0, 270.0, 10.0], [4.0, 10.0, 190.0]]),
    "delta": np.array(
        [
            [6.45637, 1.27814, 2.15629],
            [-1.25819, 0.91756, -1.67264],
            [1.11687, 2.48901, 0.83674],
            [1.23637, -2.65810, -1.12530],
        ]
    ),
    "omega_n": np.array([1.5362, 2.2076, 3.7466, 3.7466]),
    "zeta": np.array([0.0056, 0.0086, 0.013, 0.013]),
}

Q_D1 = np.array([math.sqrt(1 - 0.29), 0.3, 0.2, -0.4])  # 000 Table 1, 0-80 s (also q(0))
Q_D2 = np.array([math.sqrt(1 - 0.06), 0.2, -0.1, -0.1])  # 000 Table 1, from 80 s
T_SWITCH = 80.0  # s
OMEGA_INIT = np.array([0.02, -0.03, 0.01])  # rad/s
MISALIGN_A = np.array([0.2, 0.1, 0.1])  # deg
MISALIGN_B = np.array([0.15, 0.1, 0.1])  # deg
U_MAX = 5.0  # N.m
OMEGA_BOX = 0.7  # rad/s, half-width of the T-S operating box [-0.7, 0.7]^3 (000 section 5)
FAULT_ONSET = 40.0  # s, 000 (66)
FAULT_STEPS = (40.0, 70.0, 100.0)  # 000 (66): f2 jumps 0 -> 1, 1 -> 0, 0 -> 1.5 N.m
