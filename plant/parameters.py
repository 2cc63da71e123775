"""Named physical parameter sets of the flexible spacecraft.

Each set gives the hub inertia ``J`` (kg·m²), the rigid/flexible coupling ``delta``
(n x 3, kg^(1/2)·m/s²... as printed in the papers), the modal natural frequencies
``omega_n`` (rad/s) and damping ratios ``zeta`` (1).
"""
import numpy as np

# 000 section 5: J0, delta and the first four modes.
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

def _xu2024():
    from papers.p004_xu2024.parameters import XU2024

    return XU2024


PARAMETER_SETS = {"li2023": LI2023, "xu2024": _xu2024()}


def parameter_set(name: str) -> dict:
    """Return a copy of the named set; ``KeyError`` lists the known names."""
    if name not in PARAMETER_SETS:
        raise KeyError(f"unknown parameter set '{name}' (known: {', '.join(PARAMETER_SETS)})")
    return {k: np.array(v, copy=True) for k, v in PARAMETER_SETS[name].items()}


def structured_parameters(name: str) -> dict:
    """The named set as structured scalar parameter names (``J[1,2]``, ``omega_n[3]``)."""
    s = parameter_set(name)
    out = {}
    for key in ("J", "delta"):
        a = s[key]
        for i in range(a.shape[0]):
            for j in range(a.shape[1]):
                out[f"{key}[{i + 1},{j + 1}]"] = float(a[i, j])
    for key in ("omega_n", "zeta"):
        for i, x in enumerate(s[key]):
            out[f"{key}[{i + 1}]"] = float(x)
    return out
