"""Published gains of 002 Tables 1-2 (numpy-free data: V1, W, K and the cost bound J*).

Transcribed verbatim. K of Table 2 is used by the scenarios; W V1^-1 from Table 1 differs from it by
rounding (V1 and W printed with 4 decimals): by +0.02 % / -0.23 % (omega_hat = 1), -1.3 % / -1.3 %
(0.5) and +5.8 % / +5.6 % (0.2) on (K1, K2); see ``tests/papers/p002_zhang2014``."""

# 002 Tables 1-2, as printed
PUBLISHED = {
    1.0: {"V1": [[0.1179, -0.0105], [-0.0123, 0.0022]], "W": [[0.0319, -0.0302]],
          "K": [[-2.3129, -24.8248]], "J_star": 11.7992},
    0.5: {"V1": [[0.1173, -0.0104], [-0.0122, 0.0022]], "W": [[0.0639, -0.0606]],
          "K": [[-4.6242, -49.7914]], "J_star": 11.8874},
    0.2: {"V1": [[0.1046, -0.0083], [-0.0095, 0.0015]], "W": [[0.1299, -0.1162]],
          "K": [[-11.0067, -134.4086]], "J_star": 11.0721},
}

CASES = (1.0, 0.5, 0.2)  # design effectiveness omega_hat of Tables 1-2, in table order
