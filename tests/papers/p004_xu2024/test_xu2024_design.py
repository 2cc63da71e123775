"""004 Theorem 2 (45)-(50): a reduced design (every LMI checked by its eigenvalues), the
stored full designs checked independently, the printed values that make the method vacuous."""
import math

import numpy as np
import pytest

from papers.p004_xu2024 import design as D
from papers.p004_xu2024 import parameters as P
from papers.p004_xu2024.gains import designed, published_tensor
from tests.schema_check import check_design_file


@pytest.fixture(scope="module")
def reduced():
    """Case I (one mode), operating points P1 and P2 only: 6 LMIs (45) of 42 x 42 instead of
    216 of 45 x 45 for the full nonhomogeneous case (benchmarks/bench_xu2024.py runs those).
    No back-off solve (the benchmark's designs have one): the optimum itself must pass the
    eigenvalue checks, which demand half the 1e-6 margin (solver tolerances are 1e-8)."""
    return D.design_case("one_mode", rules=(0, 1), backoff=0.0)


@pytest.mark.design
@pytest.mark.slow
def test_reduced_design_every_lmi_verified(reduced):
    r = reduced
    check_design_file(r)  # as `ftcsim design` writes it: the shipped design schema
    assert r["lmi_checks_passed"] and r["n_lmi"] == 6 + 5 + 3  # (45) x 6, (46)-(47) + P > 0, (48)-(49), Q, R, W > 0
    assert r["worst_lmi_margin"] <= -0.5 * r["settings"]["margin"]
    s = D.case_setup("one_mode", (0, 1))
    psi1, psi2 = D.psi_terms(s.alpha, s.tau_M)
    mu1, mu2, mu3 = r["mu"]
    rhs = math.exp(s.alpha * s.T) * (s.c1 * (mu1 + mu2 * psi1 + 2 * mu3 * psi2) + s.gamma**2 * s.w_bar)
    assert r["c2"] >= rhs * (1 - 1e-9)  # (50) at the returned point
    assert mu1 > 1.0 and r["c2"] > D.c2_lower_bound(s)
    assert 5.0 < r["c2"] < 60.0  # 15.2 here; far from the feasibility boundary


@pytest.mark.design
@pytest.mark.slow
def test_reduced_design_gains_pass_the_independent_checks(reduced):
    """Not the LMIs: every local rule loop A_j + B F_r K_rj is Hurwitz and every frozen sampled
    loop contracts for tau in [0.05, 0.1] s."""
    v = reduced["verify"]
    assert v["all_hold"], v["failed"]
    assert np.max(v["local_abscissa"]) < -0.01 and np.max(v["sampled_radius_max"]) < 1.0


@pytest.mark.parametrize("case", D.CASES)
def test_stored_designs_pass_the_independent_checks(case):
    """The gains the FMU and scenarios use (designed_gains.py, from the full designs of the
    benchmark): their provenance records every LMI verified, (50) holds at the recorded mu, and
    the independent checks hold now."""
    d = designed(case)
    s = D.case_setup(case)
    assert d["provenance"]["lmi_checks_passed"] and d["provenance"]["verify_all_hold"]
    assert d["settings"]["eps2"] > 0 and d["settings"]["rho_mm"] == s.rho_mm
    psi1, psi2 = D.psi_terms(s.alpha, s.tau_M)
    mu1, mu2, mu3 = d["mu"]
    assert d["c2"] >= math.exp(s.alpha * s.T) * (mu1 + mu2 * psi1 + 2 * mu3 * psi2 + s.gamma**2 * s.w_bar) * (1 - 1e-9)
    v = D.verify(d["K"], s)
    assert v["all_hold"], v["failed"]


def test_printed_network_is_refused_by_the_design():
    with pytest.raises(ValueError) as e:
        D.case_setup("one_mode", m_s=0.0).check()
    assert "m_s = I_qm^T (Theta (x) I) L = 0" in str(e.value) and "network_mode = 1" in str(e.value)


def test_printed_eps2_is_refused_with_its_proof():
    """004 prints eps2 = -0.1; (45) block (2,2) and (47) are then contradictory (a proof, no solver)."""
    with pytest.raises(ValueError) as e:
        D.theorem2(D.case_setup("one_mode", eps2=P.PRINTED_SCALARS["eps2"]))
    msg = str(e.value)
    assert msg.startswith("eps2 = -0.1 <= 0") and "(47)" in msg and "positive definite" in msg


@pytest.mark.parametrize("field, value, words", [
    ("rho_mm", 1.5, "rho_mm = 1.5 must lie in (0, 1]"),
    ("alpha", 0.0, "alpha = 0.0 must be > 0"),
    ("eta", (1.0, -1.0, 1.0), "eta_1..3 must be > 0"),
])
def test_bad_design_scalars(field, value, words):
    with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(")", r"\)").replace(".", r"\.")):
        D.case_setup("one_mode", **{field: value}).check()


def test_bad_rates_in_a_design():
    bad = P.RATE_VERTICES.copy()
    bad[1, 0, 1] = -2.0
    s = D.case_setup("nonhomogeneous")
    s.vertices = bad
    with pytest.raises(ValueError, match=r"vertex 2: off-diagonal rate \[1,2\] = -2 1/s is negative"):
        s.check()


def test_published_gains_as_printed_are_unstable_and_the_sign_fix_repairs_them():
    """R8b: as printed, K21 and K31 destabilise A_1 and every rule-2 gain (K12, K22, K32) is
    unstable at its own point P2; with the documented sign fix every local loop is Hurwitz."""
    s = D.case_setup("three_homogeneous")
    ab = D.local_abscissae(published_tensor(), s)
    assert ab[1, 0] > 0.1 and ab[2, 0] > 0.1 and np.all(ab[:, 1] > 0.1)
    fixed = D.local_abscissae(published_tensor(sign_fix=True), s)
    assert np.all(fixed < 0)


def test_lower_bound_on_c2():
    """Every feasible point has c2 > e^{alpha T}(c1 + gamma^2 w_bar) (mu1 > 1 from (46)-(47)):
    with our alpha T = 1 that is 2.76, so the bound alone does not exclude 004's 5.4-6.0; it
    excludes them for alpha T >= ln(6.0114) = 1.79."""
    s = D.case_setup("one_mode")
    assert math.isclose(D.c2_lower_bound(s), math.e * (1 + 0.01 * s.w_bar), rel_tol=1e-12)
    assert D.c2_lower_bound(D.case_setup("one_mode", alpha=0.18)) > P.PUBLISHED_C2["one_mode"]
