"""The LMI layer: margins are matrices, symmetry is enforced, infeasible/unverified designs fail."""

import cvxpy as cp
import numpy as np
import pytest

import lmi
from lmi.verify import disk_excess, hinf_norm, spectral_abscissa

pytestmark = pytest.mark.design


def test_scalar_margin_pitfall_is_real_in_raw_cvxpy():
    # what the layer protects against: X >> 1.0 means X - ones >> 0, X may be singular
    X = cp.Variable((2, 2), symmetric=True)
    cp.Problem(cp.Minimize(cp.trace(X)), [X >> 1.0]).solve(solver="CLARABEL")
    assert np.linalg.eigvalsh(X.value)[0] < 1e-6


def test_layer_margin_is_identity_times_float():
    p = lmi.LMIProblem("margin")
    X = p.symmetric("X", 2)
    p.positive_definite("X > 0", X, 1.0)
    sol = p.solve(cp.trace(X))
    assert np.linalg.eigvalsh(sol["X"])[0] >= 1.0 - 1e-6  # X >= 1*I, not X >= ones
    assert sol.solver == "CLARABEL" and all(c.passed for c in sol.checks)


@pytest.mark.parametrize("bad", [np.eye(2) * 1e-3, np.array(1e-3), "1e-3", True, -1e-3, 0.0, float("nan")])
def test_margin_must_be_positive_float(bad):
    p = lmi.LMIProblem("m")
    X = p.symmetric("X", 2)
    with pytest.raises((TypeError, ValueError)):
        p.negative_definite("(x)", X, bad)


def test_margin_cannot_be_an_expression():
    p = lmi.LMIProblem("m")
    X = p.symmetric("X", 2)
    t = p.scalar("t")
    with pytest.raises(TypeError):
        p.positive_definite("(x)", X, t)


def test_non_square_and_non_symmetric_rejected():
    p = lmi.LMIProblem("s")
    Y = p.matrix("Y", 2, 2)
    with pytest.raises(ValueError, match="not symmetric"):
        p.negative_definite("(y)", Y, 1e-3)
    with pytest.raises(ValueError, match="square"):
        p.negative_definite("(z)", p.matrix("Z", 2, 3), 1e-3)
    # a wrong '*' block typed by hand is caught; sym_blocks builds the right one
    A = np.array([[0.0, 1.0], [-2.0, -3.0]])
    P = p.symmetric("P", 2)
    wrong = cp.bmat([[A.T @ P + P @ A, P], [P @ A, -np.eye(2)]])
    with pytest.raises(ValueError, match="not symmetric"):
        p.negative_definite("(wrong)", wrong, 1e-3)
    right = lmi.sym_blocks([[A.T @ P + P @ A, P], [None, -np.eye(2)]])
    p.negative_definite("(right)", right, 1e-3)


def test_plain_psd_constraint_refused():
    p = lmi.LMIProblem("c")
    X = p.symmetric("X", 2)
    with pytest.raises(TypeError):
        p.constrain(X >> 0)


def test_known_infeasible_reported_and_named():
    # A = I is unstable: no P > 0 with A^T P + P A < 0
    p = lmi.LMIProblem("unstable Lyapunov")
    P = p.symmetric("P", 2)
    p.positive_definite("P > 0", P, 1e-3)
    for r, A in enumerate((np.eye(2), -np.eye(2)), start=1):
        p.negative_definite("(lyap)", A.T @ P + P @ A, 1e-3, rule=r)
    with pytest.raises(lmi.LMIInfeasible) as ei:
        p.solve()
    assert "infeasible" in str(ei.value) and "(lyap) rule 1" in str(ei.value)
    assert ei.value.record["attempts"][0]["solver"] == "CLARABEL"
    # the same problem without rule 1 is feasible: the failure is really rule 1's
    q = lmi.LMIProblem("stable Lyapunov")
    Q = q.symmetric("P", 2)
    q.positive_definite("P > 0", Q, 1e-3)
    q.negative_definite("(lyap)", -2 * Q, 1e-3, rule=2)
    assert all(c.passed for c in q.solve().checks)


def test_checker_rejects_a_violating_solution():
    A = np.array([[0.0, 1.0], [-2.0, -3.0]])
    p = lmi.LMIProblem("Lyapunov")
    P = p.symmetric("P", 2)
    p.positive_definite("P > 0", P, 1e-3)
    p.negative_definite("(lyap)", A.T @ P + P @ A, 1e-3, rule=1)
    good = p.solve()
    assert all(c.passed for c in good.checks)
    # a hand-made point that violates (lyap) although "the solver said optimal"
    bad = {"P": np.array([[1.0, 0.0], [0.0, -0.5]])}
    res = {c.label: c for c in p.check(bad)}
    assert not res["(lyap) rule 1"].passed and not res["P > 0"].passed
    # a point that satisfies the inequality but not with half its margin is rejected too
    Pm = good["P"] * 1e-9
    res = {c.label: c for c in p.check({"P": Pm})}
    assert res["(lyap) rule 1"].extreme_eigenvalue < 0 and not res["(lyap) rule 1"].passed


def test_solve_rejects_optimal_status_with_violated_lmi(monkeypatch):
    A = np.array([[0.0, 1.0], [-2.0, -3.0]])
    p = lmi.LMIProblem("fake solver")
    P = p.symmetric("P", 2)
    p.negative_definite("(lyap)", A.T @ P + P @ A, 1e-3, rule=3)
    p.positive_definite("P > 0", P, 1e-3)

    def fake_solve(self, *a, **k):  # claims optimal, returns a bad point
        P.value = np.array([[1.0, 0.0], [0.0, -1.0]])
        self._status = "optimal"
        self._value = 0.0
        return 0.0

    monkeypatch.setattr(cp.Problem, "solve", fake_solve)
    monkeypatch.setattr(cp.Problem, "status", property(lambda self: "optimal"))
    monkeypatch.setattr(cp.Problem, "value", property(lambda self: 0.0))
    with pytest.raises(lmi.LMIUnverified, match=r"\(lyap\) rule 3"):
        p.solve()


def test_verify_helpers():
    A = np.array([[0.0, 1.0], [-1.0, -0.02]])
    h = hinf_norm(A, np.array([[0.0], [1.0]]), np.array([[1.0, 0.0]]))
    assert h["norm"] == pytest.approx(1 / (0.02 * np.sqrt(1 - 1e-4)), rel=1e-5)
    assert spectral_abscissa(A) == pytest.approx(-0.01)
    assert disk_excess(np.diag([-1.0, -3.0]), -2.0, 1.5) == pytest.approx(-0.5)
    assert hinf_norm(np.eye(1), np.eye(1), np.eye(1))["norm"] == float("inf")
