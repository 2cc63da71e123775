"""001 section 5: the rigid spacecraft, its wheels, uncertainty, disturbance, initial state and
fault profile (numpy only, SI). Quotes are the paper's; every reading is marked.

* "J = [30 5.3 6.4; 5.3 27 10; 6.4 10 19] kg.m2", "M = [1 0 0 1/sqrt3; 0 1 0 1/sqrt3; 0 0 1 1/sqrt3]"
  (three orthogonal wheels and one skew wheel, N = 4).
* "Delta J = diag{sin(0.1t), 2sin(0.2t), sin(0.3t)}" (kg.m2 implied).
* "T_d = 0.001[sin(t), 3sin(t), 5sin(t)]^T N.m".
* "sigma(0) = [-0.6, 0.5, 0.5]^T", "omega_0 = [0.9, 0.6, -0.4]^T". No units are printed.
  Reading: rad and rad/s (the kinematics and every power law of the controller are in rad).
* sigma_d = 0 ("the expected reference attitude angle command sigma_d is assumed to be zero").
* Faults: "The first actuator occurs a bias fault u_f1 = 0.04 N.m after t = 20 s, and the second
  actuator decreases 40% control effectiveness after t = 20 s, the third actuator work normal."
  Readings: steps at 20 s (onset inclusive); "decreases 40%" -> e_2 = 0.6; wheel 4, not
  mentioned, is healthy. So e = [1, 0.6, 1, 1], u_f = [0.04, 0, 0, 0] N.m from 20 s.
* Run length and step are not given. Reading: 60 s at a 1 ms communication step (the fault is at
  20 s and Table 1's stabilisation time is 28 s).
"""
import math

import numpy as np

S3 = 1.0 / math.sqrt(3.0)

ZHANG2019 = {
    "J": np.array([[30.0, 5.3, 6.4], [5.3, 27.0, 10.0], [6.4, 10.0, 19.0]]),
    "M": np.array([[1.0, 0.0, 0.0, S3], [0.0, 1.0, 0.0, S3], [0.0, 0.0, 1.0, S3]]),
}
N_WHEELS = 4

DJ_AMP = np.array([1.0, 2.0, 1.0])  # kg.m2
DJ_FREQ = np.array([0.1, 0.2, 0.3])  # rad/s
TD_AMP = np.array([0.001, 0.003, 0.005])  # N.m
TD_FREQ = np.array([1.0, 1.0, 1.0])  # rad/s

SIGMA0 = np.array([-0.6, 0.5, 0.5])  # rad, [nu, psi, gamma]
OMEGA0 = np.array([0.9, 0.6, -0.4])  # rad/s
SIGMA_D = np.zeros(3)

FAULT_ONSET = 20.0  # s
EFFECTIVENESS = np.array([1.0, 0.6, 1.0, 1.0])
BIAS = np.array([0.04, 0.0, 0.0, 0.0])  # N.m

STOP = 60.0  # s (reading)
STEP = 0.001  # s (reading)

PLANT_DEFAULTS = {
    "J": ZHANG2019["J"],
    "M": ZHANG2019["M"],
    "dJ_amp": DJ_AMP,
    "dJ_freq": DJ_FREQ,
    "Td_amp": TD_AMP,
    "Td_freq": TD_FREQ,
    "sigma_init": SIGMA0,
    "omega_init": OMEGA0,
    "effectiveness": EFFECTIVENESS,
    "effectiveness_onset": np.full(N_WHEELS, FAULT_ONSET),
    "bias": BIAS,
    "bias_onset": np.full(N_WHEELS, FAULT_ONSET),
    "h_max": STEP,
}
