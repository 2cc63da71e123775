"""`ftcsim design xu2024-ftc` / `ftcsim verify xu2024-ftc`: the command-line side of ``design.py``
(004 Theorem 2 (45)-(50), the nonhomogeneous case)."""
import numpy as np

from . import design as dx


def run_design(alpha=None, T=None, rho_mm=None, eps2=None):
    options = {k: v for k, v in (("alpha", alpha), ("T", T), ("rho_mm", rho_mm), ("eps2", eps2)) if v is not None}
    r, lines = dx.design(**options)
    # the file names the design `ftcsim verify` checks it with (design_case's "xu2024-ftc-nonhomogeneous" was
    # refused by `verify xu2024-ftc`, issue 20); "case" keeps which of design.CASES it is
    return {**r, "design": "xu2024-ftc"}, " | ".join(lines)


def gains_from_file(get) -> dict:
    """The mode- and rule-dependent gains K (modes, rules, 3, 6) of a design file."""
    K = get("gains.K")
    shape = np.shape(K) if isinstance(K, list) else ()
    if len(shape) != 4 or shape[2:] != (3, 6):
        get("gains.K", "array of shape (modes, rules, 3, 6)")
    return {"K": get("gains.K", shape)}


def verify_report(gains=None, source="our stored design (papers/p004_xu2024/designed_gains.py)"):
    from .gains import DESIGNED

    K = np.asarray(DESIGNED["K"] if gains is None else gains["K"], float)
    rep = dx.verify(K, dx.case_setup("nonhomogeneous"))
    worst = float(np.max(rep["sampled_radius_max"]))
    return rep["all_hold"], (f"verify xu2024-ftc ({source}): worst local abscissa {float(np.max(rep['local_abscissa'])):.4g}, "
                             f"worst sampled-loop radius {worst:.4g}"), rep["holds"]
