"""Published gains of 004 section 4, verbatim, and the readings needed to use them (numpy only).

004 prints six 3x6 matrices labelled K11, K21, K31, K12, K22, K23 "based on the condition
specified in Equation (53)" (three modes, nonhomogeneous rates). Columns act on
y = [w1, w2, w3, q1, q2, q3]; units N.m per rad/s (w columns) and N.m (q columns).

Readings (R8, R8b of README.md):
* labels: 004 (14) writes K_rj with r the fault mode and j the rule. K11, K21, K31 are nearly
  equal (rule 1 for modes 1-3); K12, K22 and "K23" form a second family (rule 2): "K23" is read as
  K32 (mode 3, rule 2). ``k23_as = "K23"`` keeps the printed label (mode 2, rule 3).
* rule 3 (K13, K23, K33) is not printed: ``missing_rule3 = "copy_rule2"`` fills it with rule 2
  (a replay device, not the paper's), ``"zero"`` with zeros.
* signs: as printed, K21 and K31 destabilise the rule-1 model A_1 and every rule-2 gain is
  unstable at every operating point (``design.local_abscissae``). ``sign_fix = True`` negates
  K21(3,6), K31(3,6) (K11 has -45.4574 there), the (1,1) entry of the three rule-2 gains and
  K32(2,1): the documented correction that makes them stabilising. Never applied silently.
"""
import numpy as np

PUBLISHED = {  # label as printed -> matrix as printed
    "K11": np.array([[-152.2274, 29.9847, 12.2479, -45.5341, 5.7843, 2.0314],
                     [25.4123, -164.5127, -4.8521, 4.2974, -48.2479, 0.1147],
                     [14.5746, -7.2145, -72.1453, -5.4762, -0.7841, -45.4574]]),
    "K21": np.array([[-154.2149, 31.0146, 17.1142, -56.4046, 5.2194, 2.5448],
                     [26.1417, -162.2747, -5.3147, 4.9413, -56.0141, 0.7412],
                     [14.5172, -8.4547, -77.5314, -5.3118, -0.7468, 47.5741]]),
    "K31": np.array([[-151.1742, 30.1467, 18.1024, -59.1042, 4.9017, 2.9013],
                     [26.1417, -162.2747, -5.3147, 4.9413, -56.0141, 0.9014],
                     [12.1435, -8.4471, -76.1147, -6.2471, -0.7785, 45.9821]]),
    "K12": np.array([[180.5112, 90.5017, 41.1475, -54.4571, 5.8147, 2.2347],
                     [207.2431, -165.2114, -13.8141, 5.0464, -62.0117, 2.0013],
                     [0.1147, -25.1421, -102.1447, 3.2414, -1.2471, -30.9114]]),
    "K22": np.array([[175.1271, 88.5717, 40.7571, -55.0717, 4.9717, 3.4157],
                     [202.4317, -162.0174, -18.1470, 54.1654, -60.1074, 3.1710],
                     [1.0107, -21.2018, -12.4471, 4.0114, -2.0070, -19.1010]]),
    "K23": np.array([[177.4107, 85.0074, 47.5077, -50.7047, 7.1074, 4.1007],
                     [240.0311, -120.1277, -14.5701, 51.6051, -61.0071, 1.7170],
                     [1.1074, -20.0114, -14.4712, 41.0144, -0.0471, -11.0108]]),
}

# (mode, rule, row, column), 1-based, of the entries negated by sign_fix (after relabelling K23 -> K32)
SIGN_FIX_ENTRIES = ((2, 1, 3, 6), (3, 1, 3, 6), (1, 2, 1, 1), (2, 2, 1, 1), (3, 2, 1, 1), (3, 2, 2, 1))


def published_tensor(missing_rule3: str = "copy_rule2", k23_as: str = "K32", sign_fix: bool = False) -> np.ndarray:
    """K[r, j] (3 modes, 3 rules, 3, 6) from the printed matrices with the readings above."""
    if missing_rule3 not in ("copy_rule2", "zero"):
        raise ValueError(f"missing_rule3 = {missing_rule3!r}: 'copy_rule2' or 'zero'")
    if k23_as not in ("K32", "K23"):
        raise ValueError(f"k23_as = {k23_as!r}: 'K32' or 'K23'")
    K = np.full((3, 3, 3, 6), np.nan)
    for label, M in PUBLISHED.items():
        r, j = int(label[1]), int(label[2])
        if label == "K23" and k23_as == "K32":
            r, j = 3, 2
        K[r - 1, j - 1] = M
    if sign_fix:
        if k23_as != "K32":
            raise ValueError("sign_fix is defined for the K23 -> K32 relabelling")
        for r, j, a, b in SIGN_FIX_ENTRIES:
            K[r - 1, j - 1, a - 1, b - 1] *= -1.0
    for r in range(3):
        if np.isnan(K[r, 1]).any():  # only with k23_as = "K23": mode 3 has no rule-2 gain, use its rule 1
            K[r, 1] = K[r, 0]
        if np.isnan(K[r, 2]).any():
            K[r, 2] = K[r, 1] if missing_rule3 == "copy_rule2" else 0.0
    return K



def designed(case: str = "nonhomogeneous") -> dict:
    """Our designed gains for one case of ``design.CASES`` (004 Theorem 2 by ``design.py``,
    not the paper's): {"K": (N, 3, 3, 6), "c2": ..., "settings": ..., "provenance": ...},
    stored in ``designed_gains.py`` by ``benchmarks/bench_xu2024.py --write-gains``."""
    from .designed_gains import DESIGNS

    d = dict(DESIGNS[case])
    d["K"] = np.asarray(d["K"], dtype=float)
    return d


DESIGNED = designed()
