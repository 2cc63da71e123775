"""`ftcsim design zhang2014-hinf` / `ftcsim verify zhang2014-hinf`: the command-line side of
``design.py`` (002 Theorem 2 (22))."""
import numpy as np

from . import design as dz


def run_design(omega_hat=None, j=None, kappa=None):
    kw = {}
    if omega_hat:
        kw["omega_hats"] = tuple(omega_hat)
    if j is not None:
        kw["j"] = j
    if kappa:
        kw["kappas"] = tuple(sorted(kappa))
    r = dz.design(**kw)
    summary = "; ".join(f"omega_hat={c['omega_hat']:g}: J* = {c['J_star']:.4f}, kappa = {c['kappa']:.3g}, "
                        f"K = {np.round(c['K'], 4).tolist()}" for c in r["cases"])
    return r, f"{summary}; solver {r['solver']}"


def gains_from_file(get) -> dict:
    cases = get("cases")
    if not isinstance(cases, list) or not cases:
        get("cases", "non-empty list")
    return {"cases": [(get(f"cases.{i}.omega_hat", ()), get(f"cases.{i}.K", (1, 2)), get(f"cases.{i}.J_star", ()),
                       get(f"cases.{i}.j", ())) for i in range(len(cases))]}


def verify_report(gains=None, source="002 Table 2 (published)"):
    cases = ([(w, np.asarray(p["K"]), p["J_star"], dz.DEFAULT_J) for w, p in dz.PUBLISHED.items()]
             if gains is None else gains["cases"])
    ok, titles, holds = True, [], {}
    for w, K, J, j in cases:
        rep = dz.verify(K, J, w, j)
        titles.append(f"omega_hat = {w:g}, omega in [{rep['interval'][0]:.3g}, {rep['interval'][1]:.3g}]: max H-inf = "
                      f"{rep['worst']['hinf']:.4f} (gamma 2.5, holds for omega >= {rep['omega_min_for_hinf']:.3g}), "
                      f"J* = {J:.4f}, simulated J_c = {rep['J_c_simulated']:.4f}")
        holds.update({f"omega_hat={w:g}: {k}": v for k, v in rep["holds"].items()})
        ok &= rep["all_hold"]
    return ok, f"verify zhang2014-hinf ({source}): " + "; ".join(titles), holds
