"""Paper 002 section 4: the pitch-axis flexible spacecraft and the design data (numpy only, SI).

J = 35.72 kg m^2, F = [1.27814, 0.91756] (rigid-elastic coupling row), bending modes
w = 3.17, 7.38 rad/s with damping xi = 0.001, 0.015; initial state theta(0) = 0.08 rad,
theta'(0) = 0.04 rad/s; H-infinity level gamma = 2.5; cost weights Z, R of 002 (11).
"""
import numpy as np

ZHANG2014 = {"J": 35.72, "F": np.array([1.27814, 0.91756]), "omega": np.array([3.17, 7.38]),
             "xi": np.array([0.001, 0.015])}
X0 = np.array([0.08, 0.04])  # theta(0) rad, theta'(0) rad/s
GAMMA = 2.5
Z = np.array([[0.25, 0.1], [0.1, 0.5]])
R = np.array([[0.31]])

# The set under the plant block's parameter names (scenarios: parameter_set = "zhang2014")
PARAMETER_SET = {"J": ZHANG2014["J"], "F": ZHANG2014["F"], "omega_n": ZHANG2014["omega"], "zeta": ZHANG2014["xi"]}
