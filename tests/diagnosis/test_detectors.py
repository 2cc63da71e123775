"""The change detectors (diagnosis/detectors.py) against plain numpy recurrences written here from
Basseville & Nikiforov's formulas, on given and random sequences; kernel == reference; the decision
rule (persistence, latch, restart, reset, t_enable); the block's timing and rollback; bad parameters."""
import numpy as np
import pytest
from scipy import stats

from diagnosis.detectors import Chi2Detector, CusumDetector, GlrDetector
from plant import kernels

RNG = np.random.default_rng(34)
T = 0.01


def _block(cls, n=3, **params):
    b = cls(n)
    b.set_parameters(params)
    b.initialize(0.0)
    return b


def _feed(b, r, reset=None):
    r = np.atleast_2d(np.asarray(r, dtype=float))
    if r.shape[0] == 1 and b.n != 1:
        r = r.T
    K = len(r)
    return b.process(r.reshape(K, b.n), np.arange(K) * T, np.zeros(K) if reset is None else np.asarray(reset, float))


@pytest.fixture(params=[True, False], ids=["kernel", "reference"])
def path(request):
    previous = kernels.set_enabled(request.param)
    yield request.param
    kernels.set_enabled(previous)


# -- the statistics against plain recurrences ---------------------------------------------------------
def test_cusum_on_a_given_sequence(path):
    """drift 0.5, z = 1, 2, -1, 3, -4, -4: g+ = 0.5, 2, 0.5, 3, 0, 0 and g- = 0, 0, 0.5, 0, 3.5, 7."""
    b = _block(CusumDetector, 1, drift=0.5, h=1e9)
    gp, gm = [], []
    for z in (1, 2, -1, 3, -4, -4):
        _feed(b, [[z]])
        gp.append(b.st[6])
        gm.append(b.st[7])
    assert gp == [0.5, 2.0, 0.5, 3.0, 0.0, 0.0]
    assert gm == [0.0, 0.0, 0.5, 0.0, 3.5, 7.0]


def test_cusum_against_a_numpy_recurrence(path):
    r = RNG.normal(0.1, 0.02, size=(400, 3))
    r[200:, 1] += 0.05
    mu0, sigma, drift = np.array([0.1, 0.09, 0.11]), np.array([0.02, 0.03, 0.025]), 0.7
    b = CusumDetector(3)
    b.set_defaults({"mu0": mu0, "sigma": sigma})
    b.set_parameters({"drift": drift, "h": 1e9})
    b.initialize(0.0)
    stat, _ = _feed(b, r)
    gp, gm, ref = np.zeros(3), np.zeros(3), []
    for x in r:  # B&N 2.2, two-sided, in sigma units
        z = (x - mu0) / sigma
        gp = np.maximum(0.0, gp + z - drift)
        gm = np.maximum(0.0, gm - z - drift)
        ref.append(np.maximum(gp, gm).max())
    np.testing.assert_allclose(stat, ref, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(b.st[6:9], gp, rtol=1e-12)
    np.testing.assert_allclose(b.st[9:12], gm, rtol=1e-12)


@pytest.mark.parametrize("W", [1000, 25])
def test_glr_against_the_direct_maximum(path, W):
    """g_k = max over the last min(k, W) change times j of (sum_{i=j..k} z_i)^2 / (2 (k - j + 1)), B&N 2.4.3."""
    z = RNG.normal(size=(300, 2))
    z[150:, 0] += 0.8
    b = _block(GlrDetector, 2, window=W * T, h=1e9)
    stat, _ = _feed(b, z)
    ref = []
    for k in range(len(z)):
        g = np.zeros(2)
        for j in range(max(0, k - W + 1), k + 1):
            S = z[j:k + 1].sum(axis=0)
            g = np.maximum(g, S * S / (2.0 * (k - j + 1)))
        ref.append(g.max())
    np.testing.assert_allclose(stat, ref, rtol=1e-11, atol=1e-12)


def test_glr_on_a_given_sequence(path):
    """z = 1, 1, 4: g = 1/2, max(1/2, 4/4) = 1, max(16/2, 25/4, 36/6) = 8."""
    b = _block(GlrDetector, 1, window=1.0, h=1e9)
    stat, _ = _feed(b, [[1.0], [1.0], [4.0]])
    assert stat.tolist() == [0.5, 1.0, 8.0]


@pytest.mark.parametrize("form", [0, 1])
def test_chi2_against_window_sums(path, form):
    W = 20
    z = RNG.normal(size=(200, 3))
    b = _block(Chi2Detector, window=W * T, form=form, h=1e9)
    stat, _ = _feed(b, z)
    for k in range(len(z)):
        if k < W - 1:
            assert stat[k] == 0.0
            continue
        w = z[k - W + 1:k + 1]
        ref = (w.sum(axis=0) ** 2).sum() / W if form else (w * w).sum()
        assert stat[k] == pytest.approx(ref, rel=1e-12)


def test_chi2_statistic_has_its_distribution_under_white_noise():
    """Non-overlapping full windows of white N(0, I): the mean form is chi2(n), the energy form chi2(nW)."""
    W, n, m = 10, 3, 400
    z = np.random.default_rng(7).normal(size=(W * m, n))
    for form, dof in ((1, n), (0, n * W)):
        b = _block(Chi2Detector, window=W * T, form=form, h=1e9)
        stat, _ = _feed(b, z)
        x = stat[W - 1::W]
        assert stats.kstest(x, stats.chi2(dof).cdf).pvalue > 1e-3, (form, x.mean())
        assert b.degrees_of_freedom() == dof


@pytest.mark.parametrize("cls,extra", [(CusumDetector, {"drift": 0.3}), (GlrDetector, {"window": 0.3}),
                                       (Chi2Detector, {"window": 0.2, "form": 1}), (Chi2Detector, {"window": 0.2})])
def test_kernel_equals_reference(cls, extra):
    """Same state on both paths through resets, t_enable, persistence, restart, after every sample."""
    if not kernels.numba:
        pytest.skip("no numba")
    r = RNG.normal(size=(500, 3))
    r[250:, 2] += 1.5
    reset = np.zeros(500)
    reset[[100, 101, 320]] = 1.0
    params = dict(extra, h=6.0, persistence=0.02, restart=1, latch=1, t_enable=0.3)
    blocks = []
    for on in (True, False):
        previous = kernels.set_enabled(on)
        try:
            blocks.append(_block(cls, **params))
        finally:
            kernels.set_enabled(previous)
    for k in range(500):
        out = [b.process(r[k:k + 1], np.array([k * T]), reset[k:k + 1]) for b in blocks]
        np.testing.assert_allclose(out[0][0], out[1][0], rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(out[0][1], out[1][1])
        np.testing.assert_allclose(blocks[0].st, blocks[1].st, rtol=1e-12, atol=1e-12)
    assert blocks[0].st[3] > 0  # alarms happened


# -- the decision rule --------------------------------------------------------------------------------
def test_persistence_latch_reset_and_alarm_time(path):
    """h = 1 on a one-channel CUSUM with drift 0: the statistic is the sum of z. Persistence 0.02 s =
    3 consecutive exceeding samples."""
    b = _block(CusumDetector, 1, drift=0.0, h=1.0, persistence=0.02)
    z = [0.5, 0.6, 0.0, 0.0, -0.5, 2.0, 0.0, 0.0, 0.0]
    stat, ev = _feed(b, np.array(z)[:, None])
    # g+: .5, 1.1, 1.1, 1.1, .6, 2.6, 2.6, 2.6, 2.6 (g- at most .5); exceeding from sample 1; 3 in a row at 3
    np.testing.assert_allclose(stat, [0.5, 1.1, 1.1, 1.1, 0.6, 2.6, 2.6, 2.6, 2.6], rtol=1e-15)
    assert ev.tolist() == [0, 0, 0, 1, 0, 0, 0, 1, 0]  # a second exceedance run decides again (counted)
    assert b.st[2] == pytest.approx(0.03) and b.st[3] == 2.0  # alarm time: the first decision's instant
    assert b.st[5] == 1.0 and b.st[1] == 1.0  # latched although the statistic dropped at sample 4
    assert b.st[4] == 1.0  # channel
    _feed(b, [[0.0]], reset=[1.0])
    assert b.st[5] == 0.0 and b.st[2] == -1.0 and b.st[3] == 2.0  # cleared, the count kept
    b = _block(CusumDetector, 1, drift=0.0, h=1.0, persistence=0.02, latch=0)
    _, ev = _feed(b, np.array(z)[:, None])
    assert ev.tolist() == [0, 0, 0, 1, 0, 0, 0, 1, 0]
    alarm = []
    b = _block(CusumDetector, 1, drift=0.0, h=1.0, persistence=0.02, latch=0)
    for x in z:
        _feed(b, [[x]])
        alarm.append(b.st[5])
    assert alarm == [0, 0, 0, 1, 0, 0, 0, 1, 1]  # unlatched: the alarm follows the (persistent) exceedance


def test_restart_counts_repeated_alarms_and_t_enable_ignores_early_samples(path):
    b = _block(CusumDetector, 1, drift=0.0, h=1.0, restart=1, latch=0, t_enable=0.025)
    _, ev = _feed(b, np.full((12, 1), 0.6))
    # samples 0..2 ignored; then g = .6, 1.2 (alarm, restart), .6, 1.2 (alarm) ...
    assert np.flatnonzero(ev).tolist() == [4, 6, 8, 10]
    assert b.st[3] == 4.0


def test_block_timing_no_feedthrough_and_rollback(path):
    """Outputs at t show the samples before t; with a 10 ms sample period and a 5 ms step only every
    other step samples; get_state / set_state restore the block bit for bit."""
    b = _block(CusumDetector, 1, drift=0.0, h=1.0, sample_period=0.01)
    assert b.feedthrough == {}
    u = np.array([2.0, 0.0])  # r, reset
    assert b.outputs_at(0.0, u)[-1] == pytest.approx(0.01)  # announced: the sample at 0 is taken in this step
    b.advance(0.0, 0.005, u)
    y = b.outputs_at(0.005, u)
    names = [v.name for v in b.outputs]
    assert y[names.index("alarm")] == 1.0 and y[names.index("alarm_time")] == 0.0
    assert y[names.index("statistic")] == 2.0
    s = b.get_state()
    b.advance(0.005, 0.005, u)
    assert b.get_state() == s  # no sample inside (0.005, 0.01)
    b.advance(0.01, 0.005, u)
    assert b.outputs_at(0.015, u)[names.index("g_pos")] == 4.0
    b.set_state(s)
    assert b.get_state() == s and b.outputs_at(0.005, u)[names.index("statistic")] == 2.0


@pytest.mark.parametrize("cls,params,match", [
    (CusumDetector, {"sigma[2]": 0.0}, "sigma"), (CusumDetector, {"drift": -1.0}, "drift"),
    (CusumDetector, {"h": 0.0}, "h = 0"), (CusumDetector, {"latch": 2.0}, "latch"),
    (GlrDetector, {"window": 0.015}, "whole multiple"), (Chi2Detector, {"form": 0.5}, "form"),
    (CusumDetector, {"persistence": -0.1}, "persistence"), (CusumDetector, {"sample_period": 0.0}, "sample_period")])
def test_bad_parameters_are_named(cls, params, match):
    b = cls(3)
    b.set_parameters(params)
    with pytest.raises(ValueError, match=match):
        b.initialize(0.0)
