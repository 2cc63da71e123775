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
