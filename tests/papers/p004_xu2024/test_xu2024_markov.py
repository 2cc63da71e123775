"""004 (9)-(13), (52)-(53): the Markov fault-mode sampler against the Kolmogorov forward
equation of the same rates, determinism, exact rollback, bad rate matrices."""
import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from papers.p004_xu2024 import parameters as P
from papers.p004_xu2024.blocks import mode_source
from plant.markov import ALPHA_COS2, ALPHA_RANDOM, AlphaProfile, MarkovChain, MarkovModeSource, check_generator, sample_path

N_PATHS = 10_000
HORIZON = math.pi  # one period of (52)
SIGMAS = 4.0


def _forward(profile, V, r0, T):
    """Kolmogorov forward equation p' = p Pi(t), with the expected occupation times
    E int 1{r=i} = int p_i and the expected jump counts E N_ij = int p_i pi_ij (scipy)."""
    N = V.shape[1]

    def f(t, y):
        p = y[:N]
        G = np.tensordot(profile(t), V, axes=1)
        return np.concatenate([p @ G, p, (p[:, None] * G).ravel()])

    y0 = np.zeros(N + N + N * N)
    y0[r0 - 1] = 1.0
    y = solve_ivp(f, (0.0, T), y0, rtol=1e-11, atol=1e-13).y[:, -1]
    return y[:N], y[N:2 * N], y[2 * N:].reshape(N, N)


def _simulate(profile, V, r0, T, n):
    N = V.shape[1]
    final = np.zeros(n, dtype=int)
    occ = np.zeros((n, N))
    cnt = np.zeros((n, N, N))
    ch = MarkovChain(V, profile, r0, 0)
    for k in range(n):
        if k:
            ch.restart(k, r0)
        t = 0.0
        while ch.t_next <= T:
            occ[k, ch.r] += ch.t_next - t
            i, t = ch.r, ch.t_next
            ch.advance_to(t)
            cnt[k, i, ch.r] += 1
        occ[k, ch.r] += T - t
        final[k] = ch.r
    return final, occ, cnt


@pytest.fixture(scope="module")
def nonhomogeneous():
    prof = AlphaProfile(ALPHA_COS2, 2)
    exact = _forward(prof, P.RATE_VERTICES, 1, HORIZON)
    sim = _simulate(prof, P.RATE_VERTICES, 1, HORIZON, N_PATHS)
    return exact, sim


@pytest.mark.slow
def test_final_distribution_matches_kolmogorov(nonhomogeneous):
    """P(r(pi) = j | r(0) = 1): 10,000 paths against p(pi) of the forward equation, each
    within 4 sigma of the binomial, and Pearson's chi-square (2 dof) below 18.4 (p = 1e-4)."""
    (p, _, _), (final, _, _) = nonhomogeneous
    counts = np.bincount(final, minlength=3)
    sigma = np.sqrt(p * (1 - p) / N_PATHS)
    assert np.all(np.abs(counts / N_PATHS - p) <= SIGMAS * sigma), (counts / N_PATHS, p)
    chi2 = float(np.sum((counts - N_PATHS * p) ** 2 / (N_PATHS * p)))
    assert chi2 < 18.42, chi2


@pytest.mark.slow
def test_occupation_times_match_kolmogorov(nonhomogeneous):
    """E int_0^pi 1{r = i} dt: sample means within 4 standard errors of int p_i."""
    (_, occ_exact, _), (_, occ, _) = nonhomogeneous
    se = occ.std(axis=0, ddof=1) / math.sqrt(N_PATHS)
    assert np.all(np.abs(occ.mean(axis=0) - occ_exact) <= SIGMAS * se), (occ.mean(axis=0), occ_exact, se)
    assert math.isclose(float(occ_exact.sum()), HORIZON, rel_tol=1e-9)


@pytest.mark.slow
def test_transition_counts_match_kolmogorov(nonhomogeneous):
    """E N_ij(pi) (number of i -> j jumps) within 4 standard errors of int p_i pi_ij."""
    (_, _, c_exact), (_, _, cnt) = nonhomogeneous
    mean, se = cnt.mean(axis=0), cnt.std(axis=0, ddof=1) / math.sqrt(N_PATHS)
    off = ~np.eye(3, dtype=bool)
    assert np.all(np.abs(mean - c_exact)[off] <= SIGMAS * se[off]), (mean, c_exact, se)
    assert np.all(np.diag(mean) == 0)


def test_homogeneous_chain_tends_to_its_stationary_law():
    """Pi_1 alone: the occupation fractions of one long path (2000 s, ~7000 jumps) against the
    stationary distribution (0.45477, 0.16542, 0.37981) of Pi_1 (left null vector, scipy-free)."""
    w, v = np.linalg.eig(P.PI_1.T)
    pi = np.real(v[:, np.argmin(np.abs(w))])
    pi /= pi.sum()
    times, modes = sample_path(P.PI_1[None], AlphaProfile(0, 1), 1, 3, 2000.0)
    dur = np.diff(np.append(times, 2000.0))
    frac = np.bincount(modes - 1, weights=dur, minlength=3) / 2000.0
    assert np.allclose(pi, [0.45477, 0.16542, 0.37981], atol=1e-5)
    assert np.abs(frac - pi).max() < 0.03, (frac, pi)


def test_same_seed_same_path_bit_for_bit():
    prof = AlphaProfile(ALPHA_COS2, 2)
    a = sample_path(P.RATE_VERTICES, prof, 1, 42, 50.0)
    b = sample_path(P.RATE_VERTICES, prof, 1, 42, 50.0)
    c = sample_path(P.RATE_VERTICES, prof, 1, 43, 50.0)
    assert a[0].tobytes() == b[0].tobytes() and a[1].tobytes() == b[1].tobytes()
    assert len(a[0]) > 50 and a[0].tobytes() != c[0].tobytes()


def test_block_follows_the_path_and_announces_each_jump():
    """The block on a 1 ms grid: its mode equals the path's, t_next_jump is the path's next
    jump time exactly, and a jump is seen at the first grid point at or after it."""
    b = mode_source()
    b.set_parameter("seed", 7)
    b.initialize(0.0)
    times, modes = sample_path(P.RATE_VERTICES, AlphaProfile(ALPHA_COS2, 2), 1, 7, 5.0)
    names = [v.name for v in b.outputs]
    h = 0.001
    for n in range(5000):
        t = n * h
        y = b.outputs_at(t, np.zeros(0))
        k = np.searchsorted(times, t, side="right") - 1
        assert y[names.index("mode")] == modes[k]
        nxt = times[k + 1] if k + 1 < len(times) else None
        if nxt is not None:
            assert y[names.index("t_next_jump")] == nxt
        b.advance(t, h, np.zeros(0))


def test_rollback_across_a_jump_is_exact():
    """get_state before a jump, advance across it, set_state, advance again: the same
    outputs bit for bit, also after a JSON round trip of the state (the FMU's serialisation)."""
    b = mode_source()
    b.set_parameter("seed", 11)
    b.initialize(0.0)
    t, h = 0.0, 0.001
    while b.outputs_at(t, np.zeros(0))[1] > t + 0.02:  # until a jump is less than 20 ms ahead
        b.advance(t, h, np.zeros(0))
        t += h
    saved = json.loads(json.dumps(b.get_state()))
    n_before = b.outputs_at(t, np.zeros(0))[3]

    def run(t0):
        out, tt = [], t0
        for _ in range(60):
            b.advance(tt, h, np.zeros(0))
            tt += h
            out.append(b.outputs_at(tt, np.zeros(0)).tobytes())
        return out

    first = run(t)
    assert np.frombuffer(first[-1])[3] > n_before  # a jump happened inside the window
    b.set_state(saved)
    assert run(t) == first


def test_random_alpha_profile_is_a_pure_function_of_time():
    prof = AlphaProfile(ALPHA_RANDOM, 2, grid=0.1, seed=3)
    a = [prof(t).tolist() for t in np.arange(0, 2, 0.05)]
    assert a == [prof(t).tolist() for t in np.arange(0, 2, 0.05)]
    assert all(abs(sum(x) - 1) < 1e-12 and min(x) >= 0 for x in a)
    assert len({round(x[0], 12) for x in a}) == 20  # one value per 0.1 s cell


@pytest.mark.parametrize("bad, words", [
    (np.array([[-1.0, 0.9, 0.8], [1, -5, 4], [1.6, 1.1, -2.7]]), ["Pi vertex 1", "row 1 sums to 0.7"]),
    (np.array([[-1.7, 0.9, 0.8], [1, -5, 4], [1.6, -1.1, -0.5]]), ["Pi vertex 1", "[3,2] = -1.1", "negative"]),
])
def test_bad_rate_matrix_gives_one_clear_message(bad, words):
    b = MarkovModeSource(3, 2)
    b.set_defaults({"Pi": np.stack([bad, P.PI_2])})
    with pytest.raises(ValueError) as e:
        b.initialize(0.0)
    msg = str(e.value)
    assert "MarkovModeSource" in msg and all(w in msg for w in words), msg
    assert msg.count("\n") == 0


def test_rate_bound_below_the_exit_rates_is_refused():
    with pytest.raises(ValueError, match="rate_bound = 3 1/s is below the largest exit rate 5"):
        MarkovChain(P.RATE_VERTICES, AlphaProfile(ALPHA_COS2, 2), 1, 0, rate_bound=3.0)
    with pytest.raises(ValueError, match="row 2 sums to"):
        check_generator([[0.0, 0.0], [1.0, 0.0]])
