"""Issue 24: FONTSM (controller/fontsm.py, fixed fractional-operator step fo_step) under hosts that
form time by ``t += h`` (OMSimulator, Ecos): rounding drift within the stated tolerance is the
step, a clipped (shorter) last step never raises, shorter steps that split a sample interval give
the GL operators the same samples as one full step, a longer step is refused with the parameter
named, and zhang2019_fontsm runs to 25 s on a clipped ``t += h`` grid (OMSimulator aborted there:
its last step was 7.6e-9 h short and the block refused it)."""
import numpy as np
import pytest
from host_time import run_accumulating

from papers.p001_zhang2019 import blocks
from papers.p001_zhang2019.parameters import OMEGA0, SIGMA0

H = 0.001


def _loop(b3, times, steps):
    """plant -> observer -> controller -> plant over the given (t, h) steps; the controller's
    outputs at the end."""
    p, o, c = b3
    uc = np.zeros(4)
    cin = None
    for t, h in steps:
        yp = p.outputs_at(t, uc)
        yo = o.outputs_at(t, np.concatenate([yp[3:6], uc]))
        cin = np.concatenate([yp[0:6], yo[3:11], np.zeros(3)])
        uc = c.outputs_at(t, cin)[0:4].copy()
        p.advance(t, h, uc)
        o.advance(t, h, np.concatenate([yp[3:6], uc]))
        c.advance(t, h, cin)
    return cin


def _fresh():
    b3 = [blocks.plant(), blocks.observer(), blocks.controller()]
    for x in b3:
        x.initialize(0.0)
    return b3


def _accumulated(t0, t1, h):
    """(t, h) of a ``t += h`` host with the last step clipped to t1."""
    out, t = [], t0
    while t < t1:
        step = min(h, t1 - t)
        out.append((t, step))
        t += step
    return out


def _input():
    return np.concatenate([SIGMA0, OMEGA0, np.ones(4), np.zeros(4), np.zeros(3)])


def test_clipped_last_step_off_the_grid_is_taken_and_keeps_the_operators_on_their_grid():
    """0.3005 s by t += h: 300 steps of 1 ms, then a last step of 0.5 ms. The state after the 300
    full steps equals the exact-grid run's; the last step moves Upsilon_hat by h_last rho J^-T s
    and adds no GL sample."""
    steps = _accumulated(0.0, 0.3005, H)
    assert len(steps) == 301 and abs(steps[-1][1] - 0.0005) < 1e-12
    exact = _fresh()
    _loop(exact, None, [(k * H, H) for k in range(300)])
    acc = _fresh()
    cin = _loop(acc, None, steps[:-1])
    c, ce = acc[2], exact[2]
    assert c.k == ce.k == 300
    np.testing.assert_allclose(c.get_state(), ce.get_state(), rtol=1e-12, atol=1e-15)
    before = c.upsilon.copy()
    s = c.outputs_at(steps[-1][0], cin)[4:7]
    acc[0].advance(*steps[-1], np.zeros(4))  # the plant and observer take it too
    c.advance(*steps[-1], cin)
    assert c.k == 300  # no GL sample for half an interval
    np.testing.assert_allclose(c.upsilon, before + steps[-1][1] * c.rho * (c.JiT @ s), rtol=1e-13)


def test_two_half_steps_give_the_gl_operators_one_full_sample():
    x = _input()
    full, halves = blocks.controller(), blocks.controller()
    for c in (full, halves):
        c.initialize(0.0)
        for k in range(20):
            c.advance(k * H, H, x)
    full.advance(20 * H, H, x)
    halves.advance(20 * H, H / 2, x)
    assert halves.k == 20 and halves._pending is not None
    mid = halves.get_state()
    halves.advance(20 * H + H / 2, H / 2, x)
    assert halves.k == full.k == 21
    np.testing.assert_allclose(halves.get_state(), full.get_state(), rtol=1e-14, atol=1e-18)
    # the state inside an interval restores exactly
    other = blocks.controller()
    other.initialize(0.0)
    other.set_state(mid)
    other.advance(20 * H + H / 2, H / 2, x)
    assert other.get_state() == halves.get_state()


def test_drift_of_a_long_t_plus_h_run_is_the_step_and_a_longer_step_is_refused():
    c = blocks.controller()
    c.initialize(0.0)
    c.k = 25_000  # where OMSimulator's last step was 7.6e-9 h off
    tol = c.step_tolerance(25.0, H)
    assert 7.6e-9 * H < tol < 1e-6 * H
    x = _input()
    k = c.k
    c.advance(24.999, H * (1 + 7.6e-9), x)  # a few ulps long: the step, one GL sample
    assert c.k == k + 1 and c._pending is None
    with pytest.raises(ValueError, match=r"fo_step = 0\.001 s but the communication step is 0\.002 s"):
        c.advance(25.0, 2 * H, x)
    c.advance(25.0, 0.4 * H, x)
    with pytest.raises(ValueError, match=r"after 0\.0004 s of the sample interval"):
        c.advance(25.0 + 0.4 * H, H, x)  # crosses the end of the sample interval


@pytest.mark.slow
def test_zhang2019_fontsm_runs_to_25_s_on_a_clipped_t_plus_h_grid():
    result, policy = run_accumulating("zhang2019_fontsm", 25.0)
    assert result.complete, result.error
    t_last, h_last = policy.steps[-1]
    assert t_last + h_last == 25.0 and len(policy.steps) == 25_000
    assert h_last != H and abs(h_last - H) < 1e-6 * H  # the clipped step really differs from h
    assert np.isfinite(result.data).all()
    sigma = result.data[-1, [result.columns.index(f"plant.sigma[{i}]") for i in (1, 2, 3)]]
    assert np.degrees(np.abs(sigma)).max() < 1.0  # and the loop is still controlled at 25 s
