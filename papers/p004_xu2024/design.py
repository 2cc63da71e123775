"""004 Theorem 2, (45)-(50): finite-time sampled-data fuzzy FTC gains K_rj minimising c2.

The closed loop is 004 (16): x' = sum_i sum_j h_i(x(t)) h_j(x(t_k)) [A_i x + B F_r K_rj M_s x(t_k)
+ B G_r v + H d~], r(t) a Markov chain with rates Pi(t) = sum_l alpha_l(t) Pi^(l). Theorem 2 gives,
when (45)-(50) hold, E[x^T H x] < c2 on [0, T] for every initial segment with x^T H x, x'^T H x'
<= c1 and int_0^T w^T w <= w_bar (w = [v; d~]), plus mean-square exponential stability and an
H-infinity bound gamma. We MINIMISE c2: c2 enters only (50), on its larger side, so every c2 above
the minimum is feasible and "the maximum allowable upper bound of c2" (004 section 4) has no
meaning; the minimum c2* is the tightest bound the theorem certifies (reading R21).

Readings (README.md has the reasons; switches keep the literal forms):
* U1 = U2 = U (the proof's "U1 = eps1 U, U2 = eps2 U" does not give the printed phi12, phi22);
  Ubar = U^-1, Pbar = Ubar^T P Ubar (and Q, R, W likewise), Y_rj = K_rj Ubar, valid because
  M_s C_i = m_s I (C_i = I, L_l = l_l I); m_s = 0 (004's printed network) is refused.
* phi22 = tau_M Rbar - eps2 (Ubar + Ubar^T) + Wbar (printed "- eps2 Ubar^T").
* the C^T C term: Schur block [Ubar^T; 0] / -I (printed "eps1^2 Ubar^T C^T C Ubar" is not an LMI).
* phi15 = eps1 D_r, phi25 = eps2 D_r, D_r = [B G_r, H] on w = [v; d~] (printed as a sum "H + B G").
* Z_ij = diag(z_ijk I_3) (R9: needed for the bound on the membership mismatch); the mismatch
  |h_j(x(t_k)) - h_j(x(t))| <= rho_mm scales Ybar (R14; the paper has rho_mm = 1).
* (45) averages the four Omega terms (``average`` = 0.25, R10; printed "/2": 0.5).
* the Pdot term is enforced for both signs of every v_n (R11); tau(t) enters through
  y = e^{0.5 alpha tau} at y in {1, e^{0.5 alpha tau_M}} (Algorithm 1; ``tau_vertex = "paper"``),
  or rigorously with -y^2 replaced by -y (y >= 1; ``"affine"``).
* V4's derivative: d/dp(e^{0.5 alpha (t-p)} x(p)) at p = t is x' - 0.5 alpha x, which adds
  0.25 alpha^2 Wbar to phi11 and -0.5 alpha Wbar to phi12; the paper drops them
  (``v4_alpha_terms = True`` keeps them, the default; False is the printed form).
* eps2 must be > 0: the printed eps2 = -0.1 makes (45) and (47) contradictory
  (:func:`eps2_certificate`), so the design refuses eps2 <= 0.
* (49) bounds R (not A_i^T R A_i as (22) defines mu3): as printed (R19).

Numerics: Y_rj = s Yt_rj and Z_ij = s^2 Zt_ij with s = ``gain_scale`` (congruence of the Schur
block by diag(I, I/s)): Yt and Zt are O(1) while B ~ 1/300. Every LMI is checked by its
eigenvalues after the solve (``lmi`` layer); :func:`verify` checks the gains independently.
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import asdict, dataclass, field

import cvxpy as cp
import numpy as np
import scipy.linalg as sla

import lmi
from lmi.verify import spectral_abscissa, summarize
from plant.block import structured_values
from plant.markov import check_vertices
from plant.multisine import multisine_energy
from plant.ts_attitude import local_model

from . import parameters as P

FMU_MODEL = "Xu2024SampledFTC"
CASES = ("one_mode", "three_homogeneous", "nonhomogeneous")


# ---------------------------------------------------------------------------------------
# set-up


@dataclass
class Setup:
    """Everything Theorem 2 needs. Arrays: A (p,6,6), B (6,3), F and G (N,3) diagonals,
    vertices (Z,N,N) rate matrices, v (Z-1,) bounds on |alpha_l'|; H (6,6) the FTSDB weight."""

    A: np.ndarray
    B: np.ndarray
    F: np.ndarray
    G: np.ndarray
    vertices: np.ndarray
    v: np.ndarray
    alpha: float = 0.1
    T: float = 10.0
    c1: float = 1.0
    gamma: float = 0.1
    eps1: float = 1.0
    eps2: float = 0.1
    tau_M: float = 0.1
    eta: tuple = (1.0, 1.0, 1.0)
    d_hat: float = 0.0
    w_bar: float = 1.0
    m_s: float = 1.0
    rho_mm: float = 0.1
    average: float = 0.25
    tau_vertex: str = "paper"
    v4_alpha_terms: bool = True
    H: np.ndarray = field(default_factory=lambda: np.eye(6))
    margin: float = 1e-6
    gain_scale: float = 300.0
    label: str = ""

    @property
    def N(self):
        return self.F.shape[0]

    @property
    def p(self):
        return self.A.shape[0]

    @property
    def Z(self):
        return self.vertices.shape[0]

    def check(self) -> None:
        """One clear ValueError per bad input (names the quantity and the reason)."""
        if self.m_s == 0.0:
            raise ValueError("004 sensor network: m_s = I_qm^T (Theta (x) I) L = 0, so K_rj does not enter (14) "
                             "or Theorem 2 (every K term carries M_s): no gain can be designed. The printed Theta "
                             "and L give exactly this; use network_mode = 1 (M_s = I) or another network")
        if not math.isfinite(self.m_s):
            raise ValueError(f"m_s = {self.m_s} must be finite")
        if self.eps2 <= 0.0:
            raise ValueError(f"eps2 = {self.eps2:g} <= 0: {eps2_certificate(self.eps2, self.eta[0])}")
        for name in ("alpha", "T", "c1", "gamma", "tau_M", "gain_scale", "margin"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} = {getattr(self, name)!r} must be > 0 (Theorem 2)")
        if any(not e > 0 for e in self.eta):
            raise ValueError(f"eta = {self.eta}: eta_1..3 must be > 0 (Theorem 2, (51))")
        if not 0 < self.rho_mm <= 1:
            raise ValueError(f"rho_mm = {self.rho_mm} must lie in (0, 1] (|h_j(x(t_k)) - h_j(x(t))| <= rho_mm)")
        if self.d_hat < 0 or self.w_bar < 0:
            raise ValueError("d_hat and w_bar must be >= 0")
        if self.tau_vertex not in ("paper", "affine"):
            raise ValueError(f"tau_vertex = {self.tau_vertex!r}: 'paper' or 'affine'")
        if self.average <= 0:
            raise ValueError(f"average = {self.average} must be > 0")
        check_vertices(self.vertices, "rate vertices")
        if self.vertices.shape[1] != self.N:
            raise ValueError(f"rate vertices are {self.vertices.shape[1]}x{self.vertices.shape[1]} for {self.N} modes")
        if np.asarray(self.v).size != self.Z - 1 or np.any(np.asarray(self.v) < 0):
            raise ValueError(f"v = {np.ravel(self.v).tolist()}: needs Z - 1 = {self.Z - 1} bounds >= 0 (004 (11))")
        H = np.asarray(self.H, float)
        if H.shape != (6, 6) or not np.allclose(H, H.T) or np.linalg.eigvalsh(H)[0] <= 0:
            raise ValueError("H must be a symmetric positive definite 6x6 matrix")


def disturbance_energy(T: float, v=P.FAULT_MODES["v"]) -> float:
    """w_bar = int_0^T (||d||^2 + ||v||^2) dt with 004's d(t) and the bias v on for the whole
    horizon (an upper bound of int w^T w for every mode path of the T-S loop, where d~ = d)."""
    d = P.DISTURBANCE
    return multisine_energy(0.0, T, d["bias"], d["a_cos"], d["a_sin"], d["freq"]) + T * float(np.sum(np.square(v)))


def case_setup(case: str, rules=(0, 1, 2), **overrides) -> Setup:
    """The three designs of 004 section 4 with our scalars (parameters.DESIGN_SCALARS):

    * ``one_mode``: Case I only (F_1 = I, G_1 = 0), N = 1 (no coupling term; 004: "Pi(t) = Pi_1,
      focusing solely on Case I"), Z = 1;
    * ``three_homogeneous``: Cases I-III with Pi_1 (Z = 1);
    * ``nonhomogeneous``: Cases I-III with (52)-(53): Z = 2, v_1 = 1 (|alpha_1'| = |sin 2t|).

    ``rules`` selects operating points (a reduced instance for tests: fewer (45) blocks).
    ``overrides`` replace any Setup field (alpha, T, eps2, rho_mm, m_s, ...)."""
    if case not in CASES:
        raise ValueError(f"case = {case!r} unknown (known: {', '.join(CASES)})")
    s = dict(P.DESIGN_SCALARS)
    s["eta"] = tuple(s["eta"])
    A, B = local_model(P.XU2024["J"], P.XU2024["delta"], P.OPERATING_POINTS[list(rules)],
                       overrides.pop("sqrt_reading", True))
    F, G = P.FAULT_MODES["F"], P.FAULT_MODES["G"]
    if case == "one_mode":
        F, G, V, v = F[:1], G[:1], np.zeros((1, 1, 1)), np.zeros(0)
    elif case == "three_homogeneous":
        V, v = P.PI_1[None], np.zeros(0)
    else:
        V, v = P.RATE_VERTICES, np.ones(1)
    T = overrides.get("T", s["T"])
    kw = {k: s[k] for k in ("alpha", "T", "c1", "gamma", "eps1", "eps2", "tau_M", "eta", "d_hat", "rho_mm",
                            "average", "m_s")}
    kw["w_bar"] = disturbance_energy(T)
    kw.update(overrides)
    return Setup(A=A, B=B, F=np.asarray(F, float), G=np.asarray(G, float), vertices=np.asarray(V, float),
                 v=np.asarray(v, float), label=case, **kw)


def eps2_certificate(eps2: float, eta1: float = 1.0) -> str:
    """Why eps2 <= 0 is infeasible (a proof, not a solver status).

    (45) < 0 implies its principal block (2,2) < 0: tau_M Rbar + Wbar - eps2 (Ubar + Ubar^T) < 0.
    (47) < 0 with eta1 > 0 implies, by its Schur complement, Ubar + Ubar^T > (Pbar + (eta1^2/mu1)
    H^-1) / eta1 > 0. With Rbar, Wbar > 0 and eps2 <= 0 the left side of the first inequality
    is then positive definite: contradiction. So no point satisfies (45) and (47) together."""
    if eps2 > 0:
        return f"eps2 = {eps2:g} > 0: no contradiction"
    return ("(45) block (2,2) needs tau_M Rbar + Wbar - eps2 (Ubar + Ubar^T) < 0, while (47) with eta1 = "
            f"{eta1:g} > 0 forces Ubar + Ubar^T > 0 and Rbar, Wbar > 0: with eps2 = {eps2:g} <= 0 that block is "
            "positive definite, so (45)-(47) have no solution (004 prints eps2 = -0.1; we read +0.1)")


def c2_lower_bound(s: Setup) -> float:
    """A bound every feasible point obeys: (46)-(47) give H < P_r^l < mu1 H, so mu1 > 1 and
    (50) gives c2 > e^{alpha T} (c1 + gamma^2 w_bar). Any c2 at or below it is infeasible."""
    return math.exp(s.alpha * s.T) * (s.c1 + s.gamma**2 * s.w_bar)


def psi_terms(alpha: float, tau_M: float):
    """psi' = (e^{alpha tau_M} - 1)/alpha, psi'' = e^{alpha tau_M}/alpha^2 - 1/alpha^2 - tau_M/alpha (50)."""
    e = math.exp(alpha * tau_M)
    return (e - 1.0) / alpha, e / alpha**2 - 1.0 / alpha**2 - tau_M / alpha


# ---------------------------------------------------------------------------------------
# the LMIs


def theorem2(s: Setup):
    """Build (45)-(50) over the lmi layer. Returns (problem, variables dict)."""
    s.check()
    N, p, Z, n, nu = s.N, s.p, s.Z, 6, 3
    A, B, H = s.A, s.B, np.asarray(s.H, float)
    pr = lmi.LMIProblem(f"004 Theorem 2 (45)-(50), {s.label or 'custom'}: N={N}, p={p}, Z={Z}")
    Pb = [[pr.symmetric(f"P{r + 1}_{l + 1}", n) for l in range(Z)] for r in range(N)]
    Qb, Rb, Wb = pr.symmetric("Q", n), pr.symmetric("R", n), pr.symmetric("W", n)
    Ub = pr.matrix("U", n, n)
    Yt = [[pr.matrix(f"Y{r + 1}_{j + 1}", nu, n) for j in range(p)] for r in range(N)]
    pairs = [(i, j) for i in range(p) for j in range(i, p)]
    zt = {(i, j): [pr.scalar(f"z{i + 1}{j + 1}_{k + 1}") for k in range(p)] for i, j in pairs}
    mu = [pr.scalar(f"mu{k}") for k in (1, 2, 3)]
    c2 = pr.scalar("c2")
    sc, m_s, e1, e2, tau, al = s.gain_scale, s.m_s, s.eps1, s.eps2, s.tau_M, s.alpha
    cW = math.pi**2 / (4.0 * tau**2)
    ys = [1.0, math.exp(0.5 * al * tau)]
    D = [np.hstack([B * s.G[r], B]) for r in range(N)]  # D_r = [B G_r, H_i] with H_i = B (6 x 6)
    I6 = np.eye(n)
    sign_vectors = list(itertools.product((-1.0, 1.0), repeat=Z - 1))
    Bbar = B  # (B_i + B_j)/2: B is the same for every rule
    # X in the Schur block, scaled by s: [eps1 B; eps2 B; 0] [I_3 ... I_3]  (30 x 3p)
    Xs = sc * np.vstack([e1 * Bbar, e2 * Bbar, np.zeros((18, nu))]) @ np.hstack([np.eye(nu)] * p)
    E1U = cp.vstack([Ub.T, np.zeros((24, n))])  # [Ubar^T; 0]: Schur column of Ubar^T C^T C Ubar

    def omega(r, i, j, l, sv, y, pdot):
        """(Omega_ij^{ls} + Omega_ji^{ls} + Omega_ij^{sl} + Omega_ji^{sl}) / 4 at y (30 x 30): Omega is
        affine in A_i, Y_rj, P_r^l and bilinear in (Pi^(s), P^l), so the average is one Omega built
        from (A_i + A_j)/2, (Y_ri + Y_rj)/2, (P_r^l + P_r^s)/2 and the averaged coupling."""
        Pl = 0.5 * (Pb[r][l] + Pb[r][sv]) if l != sv else Pb[r][l]
        Yav = 0.5 * (Yt[r][i] + Yt[r][j]) if i != j else Yt[r][i]
        Aav = 0.5 * (A[i] + A[j])
        BFY = m_s * sc * (B * s.F[r]) @ Yav  # m_s B F_r Y
        coup = 0
        for h in range(N):
            for a, b in ((sv, l), (l, sv)):  # pi^(a)_rh P_h^b, averaged over the two orders
                if s.vertices[a][r, h] != 0.0:
                    coup = coup + (0.5 * s.vertices[a][r, h]) * Pb[h][b]
        AU = Aav @ Ub
        p11 = Qb - al * Pl - Rb / tau - cW * Wb + e1 * (AU + AU.T) + pdot + coup
        p12 = Pl - e1 * Ub + e2 * Ub.T @ Aav.T
        if s.v4_alpha_terms:
            p11 = p11 + 0.25 * al**2 * Wb
            p12 = p12 - 0.5 * al * Wb
        p33 = -2.0 * Rb / tau - (y * y if s.tau_vertex == "paper" else y) * cW * Wb
        return lmi.sym_blocks([
            [p11, p12, Rb / tau + y * cW * Wb + e1 * BFY, 0, e1 * D[r]],
            [None, tau * Rb - e2 * (Ub + Ub.T) + Wb, e2 * BFY, 0, e2 * D[r]],
            [None, None, p33, Rb / tau, 0],
            [None, None, None, -math.exp(al * tau) * Qb - Rb / tau, 0],
            [None, None, None, None, -s.gamma**2 * I6],
        ])

    count = 0
    for r in range(N):
        for sig in sign_vectors:
            # Pdot_r = sum_n alpha_n' (P_r^n - P_r^Z), alpha_n' at the vertex sig_n v_n (R11)
            pdot = 0
            for k, sg in enumerate(sig):
                pdot = pdot + sg * float(s.v[k]) * (Pb[r][k] - Pb[r][Z - 1])
            for (i, j) in pairs:
                Zt = cp.diag(cp.hstack([cp.hstack([zt[(i, j)][k]] * nu) for k in range(p)]))
                # Ybar / s = rho_mm E_3 [(m_s F_r Yt_r1)^T ... (m_s F_r Yt_rp)^T]   (30 x 3p)
                Ybar = cp.vstack([np.zeros((12, nu * p)),
                                  s.rho_mm * m_s * cp.hstack([Yt[r][k].T @ np.diag(s.F[r]) for k in range(p)]),
                                  np.zeros((12, nu * p))])
                for l in range(Z):
                    for sv in range(l, Z):
                        for y in ys:
                            Om = omega(r, i, j, l, sv, y, pdot)
                            if s.average != 0.25:  # the printed "/2" over four terms (R10)
                                Om = (4.0 * s.average) * Om
                            M = lmi.sym_blocks([[Om + Xs @ Zt @ Xs.T, Ybar, E1U],
                                                [None, -Zt, 0],
                                                [None, None, -I6]])
                            count += 1
                            tag = (f"r={r + 1} ij={i + 1}{j + 1} ls={l + 1}{sv + 1} y={y:.6g}"
                                   + (f" sign={''.join('+' if g > 0 else '-' for g in sig)}" if sig else ""))
                            pr.negative_definite(f"(45) {tag}", M, s.margin)
    for (i, j) in pairs:
        for k in range(p):
            pr.constrain(zt[(i, j)][k] >= s.margin)
    eta1, eta2, eta3 = s.eta
    for r in range(N):
        for l in range(Z):
            pr.negative_definite(f"(46) r={r + 1} l={l + 1}", lmi.sym_blocks([[-Pb[r][l], Ub.T @ H], [None, -H]]), s.margin)
            pr.negative_definite(f"(47) r={r + 1} l={l + 1}",
                                 lmi.sym_blocks([[Pb[r][l] - eta1 * (Ub + Ub.T), I6], [None, -(mu[0] / eta1**2) * H]]),
                                 s.margin)
            pr.positive_definite(f"P{r + 1}_{l + 1} > 0", Pb[r][l], s.margin)
    pr.negative_definite("(48)", lmi.sym_blocks([[Qb - eta2 * (Ub + Ub.T), I6], [None, -(mu[1] / eta2**2) * H]]), s.margin)
    pr.negative_definite("(49)", lmi.sym_blocks([[Rb - eta3 * (Ub + Ub.T), I6], [None, -(mu[2] / eta3**2) * H]]), s.margin)
    for name, X in (("Q > 0", Qb), ("R > 0", Rb), ("W > 0", Wb)):
        pr.positive_definite(name, X, s.margin)
    psi1, psi2 = psi_terms(al, tau)
    pr.constrain(s.c1 * mu[0] + s.c1 * mu[1] * psi1 + 2.0 * (s.c1 * mu[2] + s.d_hat) * psi2 + s.gamma**2 * s.w_bar
                 <= c2 * math.exp(-al * s.T))  # (50)
    for m in mu:
        pr.constrain(m >= s.margin)
    return pr, {"c2": c2, "n45": count}


def gains_from_solution(sol, s: Setup) -> np.ndarray:
    """K_rj = Y_rj Ubar^-1 (Y = s Yt), shape (N, p, 3, 6)."""
    U = sol["U"]
    Uinv = np.linalg.inv(U)
    return np.array([[s.gain_scale * sol[f"Y{r + 1}_{j + 1}"] @ Uinv for j in range(s.p)] for r in range(s.N)])


# ---------------------------------------------------------------------------------------
# independent checks


def local_abscissae(K, s: Setup) -> np.ndarray:
    """(N, p): max Re lambda(A_j + m_s B F_r K_rj), the continuous rule-j loop at its own point."""
    return np.array([[spectral_abscissa(s.A[j] + s.m_s * s.B @ np.diag(s.F[r]) @ K[r, j]) for j in range(s.p)]
                     for r in range(s.N)])


def sampled_radii(K, s: Setup, taus) -> np.ndarray:
    """(N, p, len(taus)): spectral radius of the sampled rule-j loop over one interval tau,
    x(t_k + tau) = [e^{A tau} + int_0^tau e^{A s} ds m_s B F_r K_rj] x(t_k) (frozen rule and mode).
    < 1 for every tau in [tau_min, tau_M] is necessary for the sampled loop at that point."""
    out = np.zeros((s.N, s.p, len(taus)))
    for r in range(s.N):
        for j in range(s.p):
            BK = s.m_s * s.B @ np.diag(s.F[r]) @ K[r, j]
            M = np.zeros((12, 12))
            M[:6, :6], M[:6, 6:] = s.A[j], BK
            for t, tau in enumerate(taus):
                E = sla.expm(M * tau)
                out[r, j, t] = float(np.max(np.abs(np.linalg.eigvals(E[:6, :6] + E[:6, 6:]))))
    return out


def verify(K, s: Setup, tau_min: float = P.SAMPLING["tau_min"], n_tau: int = 6) -> dict:
    """Independent of the LMIs: every local continuous rule loop Hurwitz and every frozen
    sampled rule loop contracting (spectral radius < 1) for tau on a grid of [tau_min, tau_M]."""
    K = np.asarray(K, float)
    taus = np.linspace(tau_min, s.tau_M, n_tau)
    ab = local_abscissae(K, s)
    rad = sampled_radii(K, s, taus)
    holds = [(f"mode {r + 1} rule {j + 1}: A_j + B F_r K_rj Hurwitz", ab[r, j] < 0) for r in range(s.N) for j in range(s.p)]
    holds += [(f"mode {r + 1} rule {j + 1}: sampled loop radius < 1 on [{tau_min:g}, {s.tau_M:g}] s",
               rad[r, j].max() < 1.0) for r in range(s.N) for j in range(s.p)]
    rep = {"local_abscissa": ab, "sampled_radius_max": rad.max(axis=2), "taus": taus, "holds": dict(holds)}
    rep.update(summarize(holds))
    return rep


# ---------------------------------------------------------------------------------------
# the design


BACKOFF = 1e-3  # the returned point may have c2 up to 0.1 % above the optimum, in exchange for margin


def solve(s: Setup, solvers=("CLARABEL", "SCS"), backoff: float = BACKOFF):
    """Build, solve min c2, verify every LMI; returns (K, solution, timings). The lmi layer
    follows the optimum by a solve that maximises the LMI margins with c2 <= (1 + backoff) c2*:
    the reported c2 is that of the returned, verified point."""
    t0 = time.perf_counter()
    pr, h = theorem2(s)
    t1 = time.perf_counter()
    sol = pr.solve(h["c2"], solvers=solvers, backoff=backoff)
    t2 = time.perf_counter()
    return gains_from_solution(sol, s), sol, {"build_s": t1 - t0, "solve_s": t2 - t1, "n_lmi_45": h["n45"],
                                              "n_lmi": len(pr.lmis)}


def design_case(case: str = "nonhomogeneous", rules=(0, 1, 2), solvers=("CLARABEL", "SCS"),
                backoff: float = BACKOFF, **overrides) -> dict:
    """Minimise c2 for one of :data:`CASES`; verify; returns the result, with ``fmu_parameters`` for the
    controller FMU (only for the full rule set; ``ftcsim design`` writes it)."""
    s = case_setup(case, rules, **overrides)
    K, sol, timing = solve(s, solvers, backoff)
    ver = verify(K, s)
    c2 = float(sol["c2"])
    result = {
        "design": f"xu2024-ftc-{case}", "source": "004 Theorem 2, (45)-(50)", "case": case, "rules": list(rules),
        "settings": {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in asdict(s).items()
                     if k not in ("A", "B")},
        "c2": c2, "c2_optimum": sol.record["attempts"][-1].get("optimum"), "backoff": backoff,
        "c2_lower_bound": c2_lower_bound(s), "published_c2": P.PUBLISHED_C2,
        "mu": [float(sol["mu1"]), float(sol["mu2"]), float(sol["mu3"])],
        "gains": {"K": K}, "solver": sol.solver, "status": sol.status, "versions": sol.record["versions"],
        "timing": timing, "lmi_checks_passed": all(c.passed for c in sol.checks), "n_lmi": len(sol.checks),
        "worst_lmi_margin": max((c.extreme_eigenvalue for c in sol.checks if c.sense == "<0"), default=None),
        "verify": ver, "checks_passed": bool(ver["all_hold"]),
    }
    if len(rules) == 3 and s.N == 3:
        result["fmu_parameters"] = {FMU_MODEL: structured_values("K", K)}
    if not ver["all_hold"]:
        raise lmi.LMIUnverified("004 design fails independent verification: " + ", ".join(ver["failed"]), result)
    return result


def design(**options):
    """``ftcsim design xu2024-ftc``: the nonhomogeneous case with ``options`` overriding our
    scalars (alpha, T, rho_mm, eps2, ...). Returns (result, summary lines)."""
    r = design_case("nonhomogeneous", **options)
    lines = [f"004 Theorem 2, nonhomogeneous case: c2* = {r['c2']:.6g} (published {P.PUBLISHED_C2['three_modes']}, "
             f"not comparable: see README), mu = {', '.join(f'{m:.4g}' for m in r['mu'])}",
             f"{r['n_lmi']} LMIs verified by eigenvalues (worst lambda_max {r['worst_lmi_margin']:.3g}); "
             f"solver {r['solver']} ({r['status']}) in {r['timing']['solve_s']:.0f} s",
             "independent checks: " + ("all hold" if r["checks_passed"] else ", ".join(r["verify"]["failed"]))]
    return r, lines


def verify_file(data, path=None):
    """``ftcsim verify xu2024-ftc``: check a design file's gains (or our stored gains when
    ``data`` is None) independently of the LMIs. Returns (ok, report lines)."""
    from .gains import DESIGNED

    K = np.asarray(DESIGNED["K"] if data is None else data["gains"]["K"], float)
    v = verify(K, case_setup("nonhomogeneous"))
    lines = [f"{name}: {'holds' if ok else 'FAILS'}" for name, ok in v["holds"].items()]
    return bool(v["all_hold"]), lines


def write_designed_gains(results: dict, path) -> None:
    """Write ``designed_gains.py`` (numpy-free Python literals) from ``design`` results per case,
    so that the FMUs and scenarios carry our gains with their provenance."""
    import datetime

    designs = {}
    for case, r in results.items():
        designs[case] = {
            "K": np.asarray(r["gains"]["K"]).tolist(), "c2": r["c2"], "mu": r["mu"],
            "settings": {k: r["settings"][k] for k in ("alpha", "T", "c1", "gamma", "eps1", "eps2", "tau_M", "eta",
                                                       "d_hat", "w_bar", "m_s", "rho_mm", "average", "tau_vertex",
                                                       "v4_alpha_terms", "margin", "gain_scale")},
            "provenance": {"solver": r["solver"], "status": r["status"], "lmi_checks_passed": r["lmi_checks_passed"],
                           "n_lmi": r["n_lmi"], "worst_lmi_margin": r["worst_lmi_margin"],
                           "verify_all_hold": r["checks_passed"], "timing": r["timing"], "versions": r["versions"],
                           "date": datetime.date.today().isoformat()},
        }
    lines = ['"""Our Theorem-2 gains (004 (45)-(50), papers/p004_xu2024/design.py), one entry per case.',
             "",
             "Generated by ``benchmarks/bench_xu2024.py --write-gains``; not the paper's numbers (those are in",
             "gains.py). K[r][j] is the 3x6 gain of mode r, rule j (N.m per unit of y = [omega, q_v]).",
             '"""', "DESIGNS = {"]
    for case, dsg in designs.items():
        lines.append(f"    {case!r}: {{")
        lines.append('        "K": [')
        for Kr in dsg["K"]:
            lines.append("            [")
            for Krj in Kr:
                lines.append("                [" + ", ".join("[" + ", ".join(repr(float(x)) for x in row) + "]"
                                                    for row in Krj) + "],")
            lines.append("            ],")
        lines.append("        ],")
        for k in ("c2", "mu", "settings", "provenance"):
            lines.append(f"        {k!r}: {dsg[k]!r},")
        lines.append("    },")
    lines.append("}")
    text = "\n".join(lines) + "\n"
    from pathlib import Path

    tmp = Path(str(path) + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)
