"""A small LMI layer over cvxpy: named strict LMIs, safe margins, solve, verify.

Why a layer: two cvxpy behaviours silently break LMI designs.

* ``X >> eps`` with a scalar ``eps`` broadcasts the scalar to a full matrix (``X - eps*ones``),
  it does not mean ``X - eps*I``: the "strict" inequality then admits singular ``X``.
* ``M >> 0`` accepts a non-symmetric ``M`` and constrains its symmetric part: a block typed
  with a wrong ``*`` entry goes unnoticed.

Here an LMI is written only through :meth:`LMIProblem.negative_definite` /
:meth:`LMIProblem.positive_definite`, which take a *float* margin and build ``margin*I``
themselves (a matrix, array or cvxpy expression as margin is a ``TypeError``), and which
reject a non-square or non-symmetric expression. :func:`sym_blocks` builds a symmetric block
matrix from its upper triangle (the ``*`` entries are filled by transposition).

Solving: Clarabel first; SCS as fallback with tightened tolerances (skipped when Clarabel
returns a clean infeasibility certificate, status "infeasible"). Whatever status the
solver reports, every named LMI is then evaluated numerically at the solution and its
extreme eigenvalue compared with its margin (:func:`check_lmis`). A design is accepted only
if all checks pass. Otherwise no status is trusted either way: :class:`LMIInfeasible` is raised
only with a dual certificate verified here (:meth:`LMIProblem.certify_infeasible`: positive
semidefinite multipliers, checked by eigenvalues, that bound the phase-1 value away from zero
over a stated box), naming the LMIs that conflict; without one, :class:`LMIUnverified` names
the LMI (e.g. ``(41) rule 3``) that failed its check.

Check rule: an LMI ``M < 0`` with margin ``m`` passes iff ``lambda_max(M) <= -accept*m``
(``M > 0``: ``lambda_min(M) >= accept*m``), ``accept = 0.5`` by default: the solver was asked
for the full margin, the check demands that at least half of it is really there, so solver
tolerances (~1e-8) pass and any real violation fails.
"""
from __future__ import annotations

import logging
import math
import numbers
import time
import warnings
from dataclasses import asdict, dataclass, field

import cvxpy as cp
import numpy as np

log = logging.getLogger("ftcsim.lmi")  # one line per solver call with its time (`ftcsim design` shows them)

DEFAULT_ACCEPT = 0.5

CLARABEL_OPTS = {"tol_gap_abs": 1e-8, "tol_gap_rel": 1e-8, "tol_feas": 1e-8, "max_iter": 300}
SCS_OPTS = {"eps_abs": 1e-9, "eps_rel": 1e-9, "max_iters": 50_000}

_OK = (cp.OPTIMAL, cp.OPTIMAL_INACCURATE)
_INFEASIBLE = (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE)


class LMIError(Exception):
    """A design failed. ``record`` holds what was tried (solvers, statuses, checks)."""

    def __init__(self, message, record=None):
        super().__init__(message)
        self.record = record or {}


class LMIInfeasible(LMIError):
    """The LMIs have no solution with their margins; the message names the binding LMIs."""


class LMIUnverified(LMIError):
    """A solver returned a point that fails the eigenvalue check of an LMI."""


# ---------------------------------------------------------------------------------------
# margins and symmetric blocks


def _margin(margin) -> float:
    """A strictness margin must be a positive real scalar (the layer builds margin*I)."""
    if isinstance(margin, bool) or not isinstance(margin, numbers.Real):
        raise TypeError(
            f"margin must be a positive float (got {type(margin).__name__}); the LMI layer builds "
            "margin*I itself, do not pass a matrix or an expression"
        )
    m = float(margin)
    if not math.isfinite(m) or m <= 0.0:
        raise ValueError(f"margin must be a positive finite float, got {margin!r}")
    return m


def _shape(x):
    return tuple(np.shape(x)) if not isinstance(x, cp.Expression) else tuple(x.shape)


def sym_blocks(upper):
    """Symmetric block matrix from its upper triangle.

    ``upper[i][j]`` for ``j >= i`` is a block (numpy array, cvxpy expression or the int 0 for
    a zero block); entries below the diagonal are ignored (write ``None`` or ``"*"``) and
    filled with the transpose of their mirror. Diagonal blocks must be square and symmetric
    (checked by :meth:`LMIProblem.negative_definite` on the whole matrix).
    """
    k = len(upper)
    if any(len(row) != k for row in upper):
        raise ValueError("sym_blocks needs a square list of block rows")
    sizes = [None] * k
    for i in range(k):
        for j in range(i, k):
            b = upper[i][j]
            if isinstance(b, numbers.Number) and b == 0:
                continue
            shp = _shape(b)
            if len(shp) == 1:
                shp = (shp[0], 1)
            if len(shp) != 2:
                raise ValueError(f"block ({i + 1},{j + 1}) is not a matrix")
            for idx, n in ((i, shp[0]), (j, shp[1])):
                if sizes[idx] is not None and sizes[idx] != n:
                    raise ValueError(f"block ({i + 1},{j + 1}): size {n} != {sizes[idx]} of block row/column {idx + 1}")
                sizes[idx] = n
    if any(s is None for s in sizes):
        raise ValueError("every block row needs at least one non-zero block to fix its size")

    def blk(i, j):
        b = upper[i][j] if j >= i else upper[j][i]
        if isinstance(b, numbers.Number) and b == 0:
            return np.zeros((sizes[i], sizes[j]))
        if len(_shape(b)) == 1:
            b = cp.reshape(b, (sizes[i], 1), order="F") if isinstance(b, cp.Expression) else np.reshape(b, (-1, 1))
        return b if j >= i else b.T

    return cp.bmat([[blk(i, j) for j in range(k)] for i in range(k)])


def _random_fill(variables, rng):
    for v in variables:
        x = rng.standard_normal(v.shape)
        if v.attributes.get("symmetric") or v.attributes.get("PSD") or v.attributes.get("NSD"):
            x = x + x.T
            if v.attributes.get("PSD"):
                x = x @ x.T
            if v.attributes.get("NSD"):
                x = -(x @ x.T)
        if v.attributes.get("nonneg") or v.attributes.get("pos"):
            x = np.abs(x) + 0.1
        if v.attributes.get("nonpos") or v.attributes.get("neg"):
            x = -np.abs(x) - 0.1
        v.value = x


def _check_symmetric(name, M):
    """Reject a non-square matrix, and one that is not symmetric for all variable values."""
    shp = _shape(M)
    if len(shp) != 2 or shp[0] != shp[1]:
        raise ValueError(f"LMI {name}: expression must be a square matrix, got shape {shp}")
    if not isinstance(M, cp.Expression):
        M = np.asarray(M, float)
        if not np.allclose(M, M.T, rtol=0.0, atol=1e-12 * (1.0 + np.abs(M).max())):
            raise ValueError(f"LMI {name}: constant matrix is not symmetric")
        return
    variables = M.variables()
    saved = [v.value for v in variables]
    rng = np.random.default_rng(12345)
    try:
        # An affine map is symmetric everywhere iff it is at 0 and at generic points.
        for trial in range(3):
            if trial == 0:
                for v in variables:
                    v.value = np.zeros(v.shape) if not (v.attributes.get("pos") or v.attributes.get("neg")) else None
                if any(v.value is None for v in variables):
                    continue
            else:
                _random_fill(variables, rng)
            val = np.asarray(M.value, float)
            asym = np.abs(val - val.T).max()
            if asym > 1e-9 * (1.0 + np.abs(val).max()):
                raise ValueError(
                    f"LMI {name}: expression is not symmetric (max |M - M^T| = {asym:.3g}); "
                    "build it with lmi.sym_blocks"
                )
    finally:
        for v, s in zip(variables, saved):
            v.value = s


# ---------------------------------------------------------------------------------------
# LMIs, checks


@dataclass
class LMI:
    """One named strict LMI: ``expr < -margin*I`` (sense '<0') or ``expr > margin*I`` ('>0')."""

    name: str
    rule: int | None
    sense: str
    expr: object
    margin: float

    @property
    def label(self) -> str:
        return self.name if self.rule is None else f"{self.name} rule {self.rule}"

    def constraint(self):
        n = self.expr.shape[0]
        E = self.margin * np.eye(n)  # the margin is always a matrix here
        M = (self.expr + self.expr.T) / 2 if isinstance(self.expr, cp.Expression) else self.expr
        return M << -E if self.sense == "<0" else M >> E


@dataclass
class CheckResult:
    """Eigenvalue check of one LMI at a numerical point."""

    label: str
    sense: str
    margin: float
    extreme_eigenvalue: float  # lambda_max for '<0', lambda_min for '>0'
    required: float  # bound the extreme eigenvalue must respect
    asymmetry: float
    passed: bool
    problem: str = ""


def evaluate(expr, values=None):
    """Numerical value of ``expr``; ``values`` maps variable name -> array (else current)."""
    if not isinstance(expr, cp.Expression):
        return np.asarray(expr, float)
    if values is None:
        return np.asarray(expr.value, float) if expr.value is not None else None
    variables = expr.variables()
    saved = [v.value for v in variables]
    try:
        for v in variables:
            if v.name() not in values:
                raise KeyError(f"no value given for variable '{v.name()}'")
            x = np.asarray(values[v.name()], float).reshape(v.shape)
            v.save_value(x)  # bypass the attribute projection: check what we were given
        return np.asarray(expr.value, float)
    finally:
        for v, s in zip(variables, saved):
            v.save_value(s)


def check_lmi(lmi: LMI, values=None, accept: float = DEFAULT_ACCEPT) -> CheckResult:
    """Evaluate one LMI numerically and compare its extreme eigenvalue with the margin."""
    M = evaluate(lmi.expr, values)
    if M is None or not np.all(np.isfinite(M)):
        return CheckResult(lmi.label, lmi.sense, lmi.margin, float("nan"), float("nan"), float("nan"), False,
                           "no finite value")
    asym = float(np.abs(M - M.T).max())
    Ms = (M + M.T) / 2
    eig = np.linalg.eigvalsh(Ms)
    if lmi.sense == "<0":
        ext, req = float(eig[-1]), -accept * lmi.margin
        ok = ext <= req
        why = "" if ok else f"lambda_max = {ext:.6g} > {req:.6g} (margin {lmi.margin:.3g})"
    else:
        ext, req = float(eig[0]), accept * lmi.margin
        ok = ext >= req
        why = "" if ok else f"lambda_min = {ext:.6g} < {req:.6g} (margin {lmi.margin:.3g})"
    scale = 1.0 + np.abs(M).max()
    if asym > 1e-8 * scale:
        ok, why = False, f"not symmetric at the solution (max |M - M^T| = {asym:.3g})"
    return CheckResult(lmi.label, lmi.sense, lmi.margin, ext, req, asym, bool(ok), why)


def check_lmis(lmis, values=None, accept: float = DEFAULT_ACCEPT):
    """Checks of all LMIs (list of :class:`CheckResult`)."""
    return [check_lmi(x, values, accept) for x in lmis]


# ---------------------------------------------------------------------------------------
# problem


def versions() -> dict:
    import clarabel
    import scs

    return {"cvxpy": cp.__version__, "clarabel": clarabel.__version__, "scs": scs.__version__,
            "numpy": np.__version__}


@dataclass
class LMISolution:
    """Accepted solution: variable values, objective, and the record of how it was obtained."""

    values: dict
    objective: float | None
    solver: str
    status: str
    checks: list
    record: dict = field(default_factory=dict)

    def __getitem__(self, name):
        return self.values[name]


class LMIProblem:
    """Collects named variables and strict LMIs; :meth:`solve` solves and verifies."""

    def __init__(self, title: str, certificate_box: float = 100.0):
        """``certificate_box``: the box |x_e| <= box over which an infeasibility certificate is
        stated (:meth:`certify_infeasible`); choose it above any meaningful solution's entries."""
        self.title = title
        self.certificate_box = float(certificate_box)
        self.lmis: list[LMI] = []
        self.extra = []  # plain (non-LMI) convex constraints, e.g. bounds on scalars
        self._vars: dict[str, cp.Variable] = {}

    # variables -------------------------------------------------------------------------
    def _register(self, name, v):
        if name in self._vars:
            raise ValueError(f"variable '{name}' defined twice")
        self._vars[name] = v
        return v

    def symmetric(self, name: str, n: int) -> cp.Variable:
        return self._register(name, cp.Variable((n, n), symmetric=True, name=name))

    def matrix(self, name: str, rows: int, cols: int) -> cp.Variable:
        return self._register(name, cp.Variable((rows, cols), name=name))

    def scalar(self, name: str, nonneg: bool = False) -> cp.Variable:
        return self._register(name, cp.Variable(nonneg=nonneg, name=name))

    # LMIs -----------------------------------------------------------------------------
    def _add(self, name, M, margin, rule, sense):
        m = _margin(margin)
        label = name if rule is None else f"{name} rule {rule}"
        if any(x.label == label for x in self.lmis):
            raise ValueError(f"LMI '{label}' defined twice")
        _check_symmetric(label, M)
        lmi = LMI(str(name), rule, sense, M, m)
        self.lmis.append(lmi)
        return lmi

    def negative_definite(self, name: str, M, margin: float, rule: int | None = None) -> LMI:
        """Add ``M < 0`` as ``M <= -margin*I``; ``margin`` is a float, ``M`` square symmetric."""
        return self._add(name, M, margin, rule, "<0")

    def positive_definite(self, name: str, M, margin: float, rule: int | None = None) -> LMI:
        """Add ``M > 0`` as ``M >= margin*I``; ``margin`` is a float, ``M`` square symmetric."""
        return self._add(name, M, margin, rule, ">0")

    def constrain(self, constraint):
        """A plain scalar/elementwise cvxpy constraint (not an LMI: no '>>' allowed here)."""
        if isinstance(constraint, cp.constraints.PSD):
            raise TypeError("matrix inequalities go through negative_definite/positive_definite")
        self.extra.append(constraint)

    # solving ----------------------------------------------------------------------------
    def _cvx(self, objective):
        obj = cp.Minimize(objective) if objective is not None else cp.Minimize(0)
        return cp.Problem(obj, [x.constraint() for x in self.lmis] + self.extra)

    def _values(self):
        return {n: (None if v.value is None else np.array(v.value, dtype=float)) for n, v in self._vars.items()}

    def check(self, values=None, accept: float = DEFAULT_ACCEPT):
        """Check every LMI at ``values`` (name -> array) or at the current variable values."""
        return check_lmis(self.lmis, values, accept)

    def solve(self, objective=None, solvers=("CLARABEL", "SCS"), accept: float = DEFAULT_ACCEPT,
              backoff: float = 1e-4, verbose: bool = False) -> LMISolution:
        """Solve (Clarabel, then SCS at tight tolerances), verify every LMI, return or raise.

        With an objective, the optimum found is followed by a back-off solve: the same LMIs,
        ``objective <= opt + backoff*|opt|`` and no objective, which returns a point
        inside the feasible set (an optimum sits on its boundary, where solver tolerances can
        eat the margin). The reported objective is the one of the returned point.
        """
        prob = self._cvx(objective)
        record = {"problem": self.title, "versions": versions(), "attempts": [],
                  "tolerances": {"CLARABEL": CLARABEL_OPTS, "SCS": SCS_OPTS}, "check_accept": accept,
                  "backoff": backoff if objective is not None else None}
        last_failed = None

        def run(p, solver, what="solve"):
            opts = CLARABEL_OPTS if solver == "CLARABEL" else SCS_OPTS if solver == "SCS" else {}
            t0 = time.perf_counter()
            log.info("%s: %s with %s (%d LMIs) ...", self.title, what, solver, len(self.lmis))
            try:
                with warnings.catch_warnings():  # "inaccurate" is recorded in the status instead
                    warnings.simplefilter("ignore", UserWarning)
                    p.solve(solver=solver, verbose=verbose, **opts)
                status = p.status
            except cp.error.SolverError as exc:
                status = f"solver error: {exc}"
            log.info("%s: %s with %s: %s in %.1f s", self.title, what, solver, status, time.perf_counter() - t0)
            return status

        cert = None
        for solver in solvers:
            if record["attempts"] and cert is None:
                # before a fallback solver: if the LMIs are provably infeasible, no solver can help
                cert = self.certify_infeasible(box=self.certificate_box)
                if cert.proves_infeasible:
                    record["attempts"].append({"solver": solver, "status": "skipped (infeasibility certified)"})
                    break
            attempt = {"solver": solver, "status": run(prob, solver)}
            if attempt["status"] not in _OK:
                record["attempts"].append(attempt)
                continue
            opt = float(prob.value)
            attempt["optimum"] = opt
            opt_vals = self._values()
            candidates = [opt_vals]
            if objective is not None and backoff:
                bound = opt + backoff * max(abs(opt), 1e-12)
                feas = self._backoff_problem(objective, bound)
                attempt["backoff_status"] = run(feas, solver, "back-off solve")
                if attempt["backoff_status"] in _OK:
                    candidates.insert(0, self._values())
            for vals in candidates:
                checks = self.check(vals, accept=accept)
                if all(c.passed for c in checks):
                    obj_val = float(evaluate(objective, vals)) if objective is not None else None
                    attempt.update(checks_passed=True, objective=obj_val)
                    record["attempts"].append(attempt)
                    for v in self._vars.values():
                        v.value = None if vals[v.name()] is None else vals[v.name()]
                    record.update(solver=solver, status=attempt["status"], objective=obj_val,
                                  checks=[asdict(c) for c in checks])
                    return LMISolution(vals, obj_val, solver, attempt["status"], checks, record)
                last_failed = checks
            attempt["checks_passed"] = False
            record["attempts"].append(attempt)
        # No verified point. Infeasibility is claimed only with a certificate checked here
        # (a dual point of the phase-1 problem, verified by eigenvalues), never from a status.
        if cert is None:
            cert = self.certify_infeasible(box=self.certificate_box)
        record["certificate"] = asdict(cert)
        if cert.proves_infeasible:
            raise LMIInfeasible(
                f"{self.title}: infeasible (certificate: every point with |entries| <= {cert.box:g} violates an LMI "
                f"with its margin by at least {cert.bound:.3g}; solvers: {', '.join(str(a['status']) for a in record['attempts'])}); "
                f"LMIs that cannot hold together: {', '.join(cert.binding) or 'undetermined'}", record)
        if last_failed is not None:
            bad = [c for c in last_failed if not c.passed]
            record["checks"] = [asdict(c) for c in last_failed]
            raise LMIUnverified(
                f"{self.title}: no verified solution: solver reported {record['attempts'][-1]['status']} but LMI "
                f"{bad[0].label} fails its check: {bad[0].problem}" + (f" (and {len(bad) - 1} more)" if len(bad) > 1 else "")
                + f"; infeasibility not certified either (phase-1 bound {cert.bound:.3g})", record)
        raise LMIUnverified(
            f"{self.title}: no solution found ({', '.join(str(a['status']) for a in record['attempts'])}) and "
            f"infeasibility not certified (phase-1 bound {cert.bound:.3g}); binding LMIs: "
            f"{', '.join(cert.binding) or 'undetermined'}", record)

    def _backoff_problem(self, objective, bound):
        """max s s.t. every LMI holds with margin m_k + s (s <= 100 max m_k), objective <= bound."""
        s = cp.Variable(name="__backoff_s")
        cap = 100.0 * max(x.margin for x in self.lmis)
        cons = []
        for x in self.lmis:
            n = x.expr.shape[0]
            M = (x.expr + x.expr.T) / 2
            if x.sense == "<0":
                cons.append(M << -(x.margin + s) * np.eye(n))
            else:
                cons.append(M >> (x.margin + s) * np.eye(n))
        return cp.Problem(cp.Maximize(s), cons + self.extra + [objective <= bound, s <= cap])

    def certify_infeasible(self, box: float = 1e6, solver: str = "CLARABEL") -> InfeasibilityCertificate:
        """Try to prove that no point satisfies every LMI, independently of any solver's exit status.

        Phase-1 problem: min t s.t. F_k(x) <= t I for every LMI k (F_k = M_k + m_k I for
        ``M_k < -m_k I``, -M_k + m_k I for ``M_k > m_k I``). Its dual gives matrices Z_k; any
        positive semidefinite Z_k (we project the solver's onto the PSD cone, checked by
        eigenvalues) certify, for every x with |x_e| <= ``box`` (every free entry),
            t >= (L(0) - box * ||grad L||_1) / sum_k tr Z_k,   L(x) = sum_k tr(Z_k F_k(x)),
        because L is affine and tr(Z_k F_k(x)) <= t tr Z_k. ``bound`` is that number with the
        margins: ``bound > 0`` proves that the LMIs as posed have no solution in the box, whatever
        the solver's path; ``bound_strict`` is the same with every margin set to 0 (``> 0``: not
        even the non-strict LMIs M_k <= 0, resp. >= 0, have one). The LMIs carrying the dual weight
        are the ones that conflict."""
        t = cp.Variable(name="__phase1_t")
        cons, duals = [], []
        for x in self.lmis:
            n = x.expr.shape[0]
            M = (x.expr + x.expr.T) / 2
            F = M + x.margin * np.eye(n) if x.sense == "<0" else -M + x.margin * np.eye(n)
            c = F << t * np.eye(n)
            cons.append(c)
            duals.append((x, F, c))
        variables = list(self._vars.values())
        prob = cp.Problem(cp.Minimize(t), cons + self.extra)
        status = "not solved"
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)
                prob.solve(solver=solver, **(CLARABEL_OPTS if solver == "CLARABEL" else {}))
            status = prob.status
        except cp.error.SolverError as exc:
            status = f"solver error: {exc}"
        saved = [v.value for v in variables]
        try:
            Zs = []
            for _lmi, _F, c in duals:
                Z = c.dual_value
                if Z is None:
                    return InfeasibilityCertificate(-math.inf, -math.inf, box, {}, [], str(status))
                Z = np.asarray(Z, float)
                w, V = np.linalg.eigh((Z + Z.T) / 2)
                Zs.append((V * np.maximum(w, 0.0)) @ V.T)  # PSD by construction
            total = sum(float(np.trace(Z)) for Z in Zs)
            if not total > 0:
                return InfeasibilityCertificate(-math.inf, -math.inf, box, {}, [], str(status))
            L = sum(cp.trace(Z @ F) for Z, (_, F, _) in zip(Zs, duals))
            for v in variables:
                v.value = np.zeros(v.shape)
            c0 = float(L.value)
            slope = _l1_gradient(L, variables)
            margin_part = sum(float(np.trace(Z)) * x.margin for Z, (x, _, _) in zip(Zs, duals))
        finally:
            for v, val in zip(variables, saved):
                v.value = val
        bound = (c0 - box * slope) / total
        bound_strict = (c0 - margin_part - box * slope) / total
        weights = {}
        for Z, (x, _, _) in zip(Zs, duals):
            weights[x.label] = weights.get(x.label, 0.0) + float(np.trace(Z)) / total
        binding = [k for k, w in sorted(weights.items(), key=lambda kv: -kv[1]) if w > 1e-3]
        return InfeasibilityCertificate(bound, bound_strict, box, weights, binding, str(status))


def feasibility(problem: LMIProblem, found: str = "solution found") -> dict:
    """Solve a feasibility problem; ``feasible`` only with a verified point, ``certified_infeasible``
    only with a verified dual certificate (neither: the numbers cannot decide; both are False)."""
    try:
        problem.solve()
        return {"feasible": True, "certified_infeasible": False, "message": found}
    except LMIError as exc:
        cert = exc.record.get("certificate", {})
        return {"feasible": False, "certified_infeasible": bool(cert.get("bound", -1.0) > 0),
                "bound": cert.get("bound"), "binding": cert.get("binding", []), "message": str(exc)}


def _l1_gradient(L, variables) -> float:
    """||grad L||_1 of the affine scalar L over the free parameters of ``variables`` (for a
    symmetric matrix variable the gradient is symmetrised: x_ij = x_ji is one parameter)."""
    grad = L.grad or {}
    total = 0.0
    for v in variables:
        g = grad.get(v)
        if g is None:
            continue
        g = np.asarray(g.todense() if hasattr(g, "todense") else g, float).reshape(v.shape, order="F") if v.shape \
            else np.asarray(g, float)
        if v.attributes.get("symmetric") or v.attributes.get("PSD") or v.attributes.get("NSD"):
            g = (g + g.T) / 2
        total += float(np.abs(g).sum())
    return total


@dataclass
class InfeasibilityCertificate:
    """A dual certificate of :meth:`LMIProblem.certify_infeasible` (see there)."""

    bound: float  # every x in the box violates some LMI (with its margin) by at least this
    bound_strict: float  # the same for the non-strict LMIs (margins 0)
    box: float
    weights: dict  # LMI label -> share of the dual weight
    binding: list  # labels with a share > 1e-3, largest first
    solver_status: str

    @property
    def proves_infeasible(self) -> bool:
        """The LMIs as posed (with their margins) have no solution in the box."""
        return self.bound > 0
