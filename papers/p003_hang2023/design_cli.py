"""`ftcsim design hang2023-tsfdo` / `ftcsim verify hang2023-tsfdo`: the command-line side of
``design.py`` (003 Theorem 1 (3.4))."""
import numpy as np

from . import design as dh


def run_design(alpha=None):
    r = dh.design(alpha=alpha)
    return r, (f"alpha = {r['performance']['alpha']:.4g}, beta = {r['performance']['beta']:.4g}, "
               f"L1 = {np.round(r['gains']['L1'], 4).tolist()}; solver {r['solver']}")


def gains_from_file(get) -> dict:
    return {"L1": get("gains.L1", (2, 2))}


def verify_report(gains=None, source="003 section 4 (published, signs as read)"):
    L1 = dh.L1_PUBLISHED if gains is None else gains["L1"]
    rep = dh.verify(L1)
    return rep["all_hold"], (f"verify hang2023-tsfdo ({source}): error-matrix abscissae "
                             f"{np.round(rep['abscissa'], 4).tolist()}"), rep["holds"]
