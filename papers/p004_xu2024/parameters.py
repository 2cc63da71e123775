"""Paper 004 section 4: the flexible spacecraft parameter set (numpy only, SI).

Same hub inertia J as 000; its own coupling delta (three entries differ from 000's) and modes."""
import numpy as np

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
