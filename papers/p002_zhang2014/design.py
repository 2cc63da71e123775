"""Robust H-infinity fault-tolerant state feedback of 002 Theorem 2, (22), and its checks.

Plant: 002 (8), x = [theta, theta'], u^F = omega u, omega = omega_hat (1 + L) (002 (7)),
design model from :mod:`plant.pitch_axis`. Gain K = W V1^-1 (002 Theorem 2), cost bound
J* = x0^T V1^-T P_hat V1^-1 x0 (002 (23)).

Readings (002 is silent or inconsistent here):

* Uncertainty level. 002 applies its Lemma 1 with L^T L <= I, i.e. omega anywhere in
  [0, 2 omega_hat]. At omega = 0 the plant is a double integrator with no input, which no gain
  stabilises, so (22) as printed cannot be feasible (the theorem would certify asymptotic
  stability at omega = 0). We use the bound |L| <= j of 002 (7) (j = (w_max - w_min)/(w_max +
  w_min), 002 (6)) by scaling N = [W 0 ...] to j N: the last block column of (22) carries j W^T.
  The guaranteed interval is omega in [omega_hat (1 - j), omega_hat (1 + j)].
* The published V1, W of Table 1 satisfy (22) (P_hat, delta free, kappa searched) for j up to
  ``PUBLISHED_J_MAX`` (about 0.78 for each omega_hat), i.e. for omega in [0.22 omega_hat,
  1.78 omega_hat], and not for the printed j = 1. ``DEFAULT_J`` = 0.75 (omega in [0.25 omega_hat,
  1.75 omega_hat]) keeps a margin below that boundary: it is the interval under which
  ``ftcsim verify zhang2014-hinf`` checks the published gains (all checks hold there; at j = 0.9
  their H-infinity bound fails below omega = 0.18 omega_hat) and our designs' default, so that
  ours and the published gains are certified for the same interval (``--j`` selects another).
* kappa is not given: it is searched on a log grid (then refined by golden section when the
  best point is interior); every value tried is recorded with its J*.
* Objective: 002 gives J* for a feasible point. We minimise a convex upper bound t of J*:
  V1 P_hat^-1 V1^T >= V1 + V1^T - P_hat gives the sufficient LMI
  [[t, x0^T], [x0, V1 + V1^T - P_hat]] >= 0; J* itself is then computed exactly.
* The design is invariant under omega_hat: (W, delta) -> (W / omega_hat, delta / omega_hat)
  maps solutions onto each other, so J* is the same for every omega_hat and K scales as
  1 / omega_hat (the published K roughly do too).
"""
from __future__ import annotations

import math

import cvxpy as cp
import numpy as np

import lmi
from lmi.search import grid_then_golden
from lmi.verify import _has_imag_eig, hinf_norm, spectral_abscissa, summarize
from plant.block import structured_values
from plant.pitch_axis import closed_loop_cost, flexible_model, rigid_model, simulate

from .gains import CASES, PUBLISHED
from .parameters import GAMMA as ZHANG2014_GAMMA
from .parameters import X0 as ZHANG2014_X0
from .parameters import ZHANG2014
from .parameters import R as ZHANG2014_R
from .parameters import Z as ZHANG2014_Z

FMU_MODEL = "Zhang2014Hinf"  # the controller FMU (papers/p002_zhang2014/blocks.py: controller)
FMU_SLOTS = len(CASES)  # gain slots K[c, 1..2], case_omega_hat[c] of that FMU
DEFAULT_J = 0.75  # see the module docstring
PUBLISHED_J = DEFAULT_J  # interval used to verify the published gains
PUBLISHED_J_MAX = 0.78  # largest j (2 digits) with (22) feasible for the published V1, W (tests check 0.75)
DEFAULT_KAPPAS = tuple(float(k) for k in np.logspace(-4, 0, 9))

def lmi22(omega_hat, kappa, j=DEFAULT_J, gamma=ZHANG2014_GAMMA, Z=ZHANG2014_Z, R=ZHANG2014_R,
          params=ZHANG2014, margin=1e-6, V1=None, W=None):
    """The LMI problem of 002 (22) (+ P_hat > 0). V1, W given: only P_hat, delta are unknown."""
    A, B, C = rigid_model(params["J"], params["F"])
    wh, k = float(omega_hat), float(kappa)
    p = lmi.LMIProblem(f"002 Theorem 2 (22), omega_hat={wh:g}, kappa={k:g}")
    P = p.symmetric("P_hat", 2)
    V = p.matrix("V1", 2, 2) if V1 is None else np.asarray(V1, float)
    Wm = p.matrix("W", 1, 2) if W is None else np.asarray(W, float).reshape(1, 2)
    d = p.scalar("delta")
    d1 = cp.reshape(d, (1, 1), order="F")
    I1 = np.eye(1)
    Z0 = lambda r, c: np.zeros((r, c))  # noqa: E731
    X11 = V.T @ A.T + A @ V + wh * (Wm.T @ B.T) + wh * (B @ Wm)  # 002 Xi_11
    X12 = P - V + k * (V.T @ A.T) + k * wh * (Wm.T @ B.T)  # 002 Xi_12
    X22 = -k * (V + V.T)  # 002 Xi_22
    M = lmi.sym_blocks([
        [X11, X12, B, V.T @ C.T, V.T, wh * Wm.T, wh * (B @ d1), j * Wm.T],
        [None, X22, k * B, Z0(2, 2), Z0(2, 2), Z0(2, 1), k * wh * (B @ d1), Z0(2, 1)],
        [None, None, -gamma**2 * I1, Z0(1, 2), Z0(1, 2), Z0(1, 1), Z0(1, 1), Z0(1, 1)],
        [None, None, None, -np.eye(2), Z0(2, 2), Z0(2, 1), Z0(2, 1), Z0(2, 1)],
        [None, None, None, None, -np.linalg.inv(Z), Z0(2, 1), Z0(2, 1), Z0(2, 1)],
        [None, None, None, None, None, -np.linalg.inv(R), wh * d1, Z0(1, 1)],
        [None, None, None, None, None, None, -d1, Z0(1, 1)],
        [None, None, None, None, None, None, None, -d1],
    ])
    p.negative_definite("(22)", M, margin)
    p.positive_definite("P_hat > 0", P, margin)
    p.constrain(d >= 0)  # delta > 0 is implied by the -delta I blocks of (22)
    return p, P, V, Wm


def _solve_case(omega_hat, kappa, j, x0, margin, solvers, **kw):
    p, P, V, W = lmi22(omega_hat, kappa, j, margin=margin, **kw)
    t = p.scalar("t")
    x0 = np.asarray(x0, float).reshape(1, 2)
    tt = cp.reshape(t, (1, 1), order="F")
    # convex upper bound of J*: V1 P^-1 V1^T >= V1 + V1^T - P (our reading, see module doc)
    p.positive_definite("J* bound", lmi.sym_blocks([[tt, x0], [None, V + V.T - P]]), 1e-9)
    sol = p.solve(t, solvers=solvers)
    Vv, Wv, Pv = sol["V1"], sol["W"], sol["P_hat"]
    Vi = np.linalg.inv(Vv)
    K = Wv @ Vi
    J_star = float((x0 @ Vi.T @ Pv @ Vi @ x0.T).item())
    return sol, K, J_star


def design_case(omega_hat, j=DEFAULT_J, kappas=DEFAULT_KAPPAS, x0=ZHANG2014_X0, margin=1e-6, refine=8):
    """Design K for one omega_hat with a kappa line search; returns a result dict."""
    table = []

    def value(k):
        try:
            _, _, J = _solve_case(omega_hat, k, j, x0, margin, ("CLARABEL",))
            table.append({"kappa": k, "J_star": J})
            return J
        except lmi.LMIError as exc:
            table.append({"kappa": k, "J_star": None, "error": str(exc).split(";")[0]})
            return math.inf

    best, J_best, _ = grid_then_golden(value, kappas, iterations=refine)
    if not math.isfinite(J_best):
        raise lmi.LMIInfeasible(f"002 (22), omega_hat={omega_hat:g}, j={j:g}: infeasible for every kappa tried "
                                f"{list(kappas)}", {"kappa_search": table})
    sol, K, J_star = _solve_case(omega_hat, best, j, x0, margin, ("CLARABEL", "SCS"))
    return {
        "omega_hat": float(omega_hat), "j": float(j), "kappa": float(best),
        "interval": [float(omega_hat * (1 - j)), float(omega_hat * (1 + j))],
        "K": K, "V1": sol["V1"], "W": sol["W"], "P_hat": sol["P_hat"], "delta": float(sol["delta"]),
        "J_star": J_star, "J_star_bound": float(sol["t"]),
        "solver": sol.record, "kappa_search": sorted(table, key=lambda r: r["kappa"]),
    }


# ---------------------------------------------------------------------------------------
# independent verification


def cost_exact(K, omega, x0=ZHANG2014_X0, Z=ZHANG2014_Z, R=ZHANG2014_R, params=ZHANG2014, flexible=False):
    """J_c of 002 (11) from a Lyapunov equation (rigid model (8) with w = 0, or the full model)."""
    import scipy.linalg as sla

    Acl, Q = closed_loop_cost(K, omega, params, Z, R, flexible)
    n = Acl.shape[0]
    if spectral_abscissa(Acl) >= 0:
        return math.inf
    Pc = sla.solve_continuous_lyapunov(Acl.T, -Q)
    z0 = np.zeros(n)
    z0[:2] = x0
    return float(z0 @ Pc @ z0)


def verify(K, J_star, omega_hat, j=DEFAULT_J, gamma=ZHANG2014_GAMMA, x0=ZHANG2014_X0, params=ZHANG2014,
           n_grid=21, simulate_cost=True, t_final=None, h=0.02) -> dict:
    """Check a gain K against 002's guarantees over omega in [omega_hat(1-j), omega_hat(1+j)].

    Holds-items: rigid closed loop (8) Hurwitz over the grid; flexible closed loop Hurwitz;
    ||(sI - A - B omega K)^-1 B||_inf < gamma (rigid, C = I); J_c (Lyapunov, w = 0) <= J*;
    simulated J_c (RK4, full flexible model, omega = omega_hat) <= J*. Also reports the smallest
    omega > 0 for which the H-infinity bound holds (bisection), useful when the interval fails.
    """
    K = np.asarray(K, float).reshape(1, 2)
    A, B, C = rigid_model(params["J"], params["F"])
    Af, Bf, _ = flexible_model(params["J"], params["F"], params["omega"], params["xi"])
    lo, hi = omega_hat * (1 - j), omega_hat * (1 + j)
    grid = np.linspace(max(lo, 1e-6), hi, n_grid)
    rows = []
    for om in grid:
        Acl = A + om * B @ K
        Kz = np.zeros((1, Af.shape[0]))
        Kz[0, :2] = K
        rows.append({
            "omega": float(om),
            "abscissa_rigid": spectral_abscissa(Acl),
            "abscissa_flexible": spectral_abscissa(Af + om * Bf @ Kz),
            "hinf": hinf_norm(Acl, B, C)["norm"],
            "J_c": cost_exact(K, om, x0, params=params),
        })
    worst = {
        "abscissa_rigid": max(r["abscissa_rigid"] for r in rows),
        "abscissa_flexible": max(r["abscissa_flexible"] for r in rows),
        "hinf": max(r["hinf"] for r in rows),
        "J_c": max(r["J_c"] for r in rows),
    }

    def hinf_ok(om):  # ||G||_inf < gamma iff A_cl Hurwitz and the gamma-Hamiltonian has no imaginary eigenvalue
        Acl = A + om * B @ K
        return spectral_abscissa(Acl) < 0 and not _has_imag_eig(Acl, B, C, gamma)[0]

    # smallest effectiveness with ||G||_inf < gamma (monotone for these loops; bisection to 1e-7)
    a, b = 1e-6, max(hi, 1.0)
    if hinf_ok(b):
        for _ in range(25):
            m = 0.5 * (a + b)
            a, b = (a, m) if hinf_ok(m) else (m, b)
        omega_min_hinf = b
    else:
        omega_min_hinf = None
    report = {
        "omega_hat": float(omega_hat), "j": float(j), "interval": [float(lo), float(hi)], "K": K,
        "J_star": float(J_star), "gamma": float(gamma), "worst": worst,
        "omega_min_for_hinf": omega_min_hinf,
        "J_c_nominal_lyapunov": cost_exact(K, omega_hat, x0, params=params),
        "J_c_nominal_flexible_lyapunov": cost_exact(K, omega_hat, x0, params=params, flexible=True),
    }
    holds = [
        ("stable (rigid) over interval", worst["abscissa_rigid"] < 0),
        ("stable (flexible) over interval", worst["abscissa_flexible"] < 0),
        ("hinf < gamma over interval", worst["hinf"] < gamma),
        ("J_c <= J* over interval", worst["J_c"] <= J_star),
    ]
    if simulate_cost:
        slow = max(-spectral_abscissa(A + omega_hat * B @ K), 1e-3)
        tf = t_final or min(2000.0, 15.0 / slow)
        sim = simulate(K, omega_hat, x0, params, ZHANG2014_Z, ZHANG2014_R, t_final=tf, h=h, flexible=True)
        report["J_c_simulated"] = sim["J_c"]
        report["simulation"] = {"t_final": tf, "h": h, "model": "flexible 6-state, RK4"}
        holds.append(("simulated J_c <= J*", sim["J_c"] <= J_star))
    report["holds"] = dict(holds)
    report.update(summarize(holds))
    return report


def published_certificate(omega_hat, j=DEFAULT_J, kappas=DEFAULT_KAPPAS, x0=ZHANG2014_X0):
    """Is (22) feasible with the published V1, W (P_hat, delta free)? Smallest J* it certifies."""
    pub = PUBLISHED[omega_hat]
    out = []
    x0 = np.asarray(x0, float)
    Vi = np.linalg.inv(np.asarray(pub["V1"]))
    c = Vi @ x0
    for k in kappas:
        p, P, _, _ = lmi22(omega_hat, k, j, V1=pub["V1"], W=pub["W"])
        try:
            sol = p.solve(c @ P @ c, solvers=("CLARABEL",))
            out.append({"kappa": float(k), "feasible": True, "J_star_min": float(c @ sol["P_hat"] @ c)})
        except lmi.LMIError:
            out.append({"kappa": float(k), "feasible": False})
    return out


# ---------------------------------------------------------------------------------------
# command entry


def fmu_parameters(cases) -> dict:
    """The controller FMU's gain bank for the designed cases: K[c, 1..2] and case_omega_hat[c] for every
    slot (unused slots empty: case_omega_hat = 0, K = 0). Each scenario selects its case with the
    FMU parameter ``omega_hat``, so one file overrides the gains of all three 002 scenarios."""
    if len(cases) > FMU_SLOTS:
        raise ValueError(f"the {FMU_MODEL} FMU holds {FMU_SLOTS} gain cases, {len(cases)} were designed")
    K = np.zeros((FMU_SLOTS, 2))
    w = np.zeros(FMU_SLOTS)
    for c, case in enumerate(cases):
        K[c] = np.asarray(case["K"]).reshape(-1)
        w[c] = case["omega_hat"]
    return {FMU_MODEL: {**structured_values("K", K), **structured_values("case_omega_hat", w)}}


def design(omega_hats=CASES, j=DEFAULT_J, kappas=DEFAULT_KAPPAS, verify_result=True, refine=8) -> dict:
    """Design every case, verify it, and (all checks passed) write the parameter file.

    ``fmu_parameters`` holds every case's gain (:func:`fmu_parameters`): ``ftcsim run
    papers/p002_zhang2014/scenarios/zhang2014_hinf_w05.toml --gains FILE`` then runs the omega_hat = 0.5
    gain, and likewise for the other cases."""
    if len(omega_hats) > FMU_SLOTS:  # an LMIError: the CLI reports it as a failed design, writes nothing
        raise lmi.LMIError(f"002 design: at most {FMU_SLOTS} omega_hat cases fit the {FMU_MODEL} FMU's gain "
                           f"slots, got {len(omega_hats)}")
    cases = [design_case(w, j, kappas, refine=refine) for w in omega_hats]
    checks_ok = True
    for c in cases:
        if verify_result:
            c["verify"] = verify(c["K"], c["J_star"], c["omega_hat"], j)
            checks_ok &= c["verify"]["all_hold"]
    first = cases[0]
    result = {
        "design": "zhang2014-hinf",
        "source": "002 Theorem 2, (22)-(23)",
        "settings": {"gamma": ZHANG2014_GAMMA, "Z": ZHANG2014_Z, "R": ZHANG2014_R, "x0": ZHANG2014_X0, "j": j,
                     "kappa_grid": list(kappas)},
        "performance": {f"J_star[omega_hat={c['omega_hat']:g}]": c["J_star"] for c in cases},
        "published": {f"J_star[omega_hat={w:g}]": PUBLISHED[w]["J_star"] for w in omega_hats if w in PUBLISHED},
        "cases": cases,
        "solver": first["solver"]["solver"], "versions": first["solver"]["versions"],
        "tolerances": first["solver"]["tolerances"],
        "checks_passed": bool(checks_ok),
        "fmu_parameters": fmu_parameters(cases),
    }
    if not checks_ok:
        bad = [f"omega_hat={c['omega_hat']:g}: {', '.join(c['verify']['failed'])}" for c in cases
               if not c["verify"]["all_hold"]]
        raise lmi.LMIUnverified("002 design fails independent verification: " + "; ".join(bad), result)
    return result


def verify_published(omega_hats=CASES, j=PUBLISHED_J, **kw) -> dict:
    """:func:`verify` of the Table 2 gains with their printed J* over |L| <= j (default 0.75)."""
    return {w: verify(np.asarray(PUBLISHED[w]["K"]), PUBLISHED[w]["J_star"], w, j, **kw) for w in omega_hats}
