"""The fault catalog (plant/fault_catalog.py): each class against its formula at hand-computable
times, the Markov class against an independently generated path (plant.markov.sample_path), the
stuck class's latch, announced instants, rollback, and bad parameters named."""
import math

import numpy as np
import pytest

from plant.fault_catalog import (
    BIAS,
    INTERMITTENT,
    LOE_RAMP,
    LOE_STEP,
    LOST,
    MARKOV,
    NONE,
    STUCK,
    TIME_VARYING,
    FaultCatalog,
)
from plant.markov import ALPHA_COS2, T_NEVER, AlphaProfile, sample_path

U = np.array([0.3, -0.2, 0.5])


def _block(n=3, **params):
    b = FaultCatalog(n)
    b.set_parameters(params)
    b.initialize(0.0)
    return b


def _out(b, t, u=U):
    y = b.outputs_at(t, np.asarray(u, dtype=float))
    n = b.n
    return {"u_f": y[0:n], "fault": y[n:2 * n], "e": y[2 * n:3 * n], "b": y[3 * n:4 * n], "active": y[4 * n],
            "mode": y[4 * n + 1], "t_next": y[4 * n + 2]}


def test_no_fault_passes_the_command():
    o = _out(_block(fault_class=NONE), 50.0)
    np.testing.assert_array_equal(o["u_f"], U)
    assert not o["fault"].any() and o["active"] == 0.0 and o["mode"] == 1.0 and o["t_next"] == T_NEVER


def test_loss_of_effectiveness_step_on_one_channel():
    b = _block(fault_class=LOE_STEP, channel=2, onset=10.0, loss=0.4)
    before, after = _out(b, 9.999), _out(b, 10.0)
    np.testing.assert_array_equal(before["u_f"], U)
    assert before["t_next"] == 10.0 and after["t_next"] == T_NEVER
    np.testing.assert_allclose(after["u_f"], [0.3, -0.2 * 0.6, 0.5], rtol=0, atol=1e-16)
    np.testing.assert_allclose(after["fault"], [0.0, 0.2 * 0.4, 0.0], atol=1e-16)
    np.testing.assert_array_equal(after["e"], [1.0, 0.6, 1.0])
    assert after["active"] == 1.0


def test_loss_of_effectiveness_ramp_every_channel():
    b = _block(fault_class=LOE_RAMP, channel=0, onset=10.0, loss=0.5, ramp_time=4.0)
    np.testing.assert_allclose(_out(b, 12.0)["e"], [0.75] * 3, atol=1e-15)  # half-way: l / 2 lost
    np.testing.assert_allclose(_out(b, 20.0)["e"], [0.5] * 3, atol=1e-15)
    assert _out(b, 12.0)["t_next"] == 14.0 and _out(b, 14.0)["t_next"] == T_NEVER


def test_additive_bias_and_time_varying():
    o = _out(_block(fault_class=BIAS, channel=1, onset=0.0, magnitude=0.04), 1.0)
    np.testing.assert_allclose(o["u_f"], U + [0.04, 0, 0], atol=1e-16)
    np.testing.assert_allclose(o["b"], [0.04, 0, 0])
    b = _block(fault_class=TIME_VARYING, channel=3, onset=5.0, magnitude=0.2, period=8.0)
    for t in (5.0, 7.0, 9.0, 11.0):
        np.testing.assert_allclose(_out(b, t)["fault"], [0, 0, 0.2 * math.sin(2 * math.pi * (t - 5.0) / 8.0)], atol=1e-16)


def test_intermittent_windows():
    b = _block(fault_class=INTERMITTENT, channel=1, onset=10.0, loss=1.0, period=4.0, duty=0.25)
    on = {10.0: True, 10.5: True, 11.0: False, 13.9: False, 14.0: True, 14.99: True, 15.0: False}
    for t, active in on.items():
        o = _out(b, t)
        assert (o["e"][0] == 0.0) == active and (o["active"] == 1.0) == active, t
    assert _out(b, 10.5)["t_next"] == 11.0 and _out(b, 11.0)["t_next"] == 14.0 and _out(b, 9.0)["t_next"] == 10.0


def test_actuator_lost():
    o = _out(_block(n=4, fault_class=LOST, channel=4, onset=3.0), 3.0, [0.1, 0.2, 0.3, 0.4])
    np.testing.assert_array_equal(o["u_f"], [0.1, 0.2, 0.3, 0.0])
    np.testing.assert_array_equal(o["fault"], [0.0, 0.0, 0.0, -0.4])


def test_stuck_at_the_command_of_the_onset_point():
    b = _block(fault_class=STUCK, channel=2, onset=1.0)
    h = 0.5
    t, u = 0.0, np.array([0.0, 0.1, 0.0])
    seen = []
    for k in range(6):
        u = np.array([0.0, 0.1 * (k + 1), 0.0])  # a ramping command
        seen.append(_out(b, t, u)["u_f"][1])
        b.advance(t, h, u)
        t += h
    # points 0, 0.5: healthy; 1.0: stuck at the command there (0.3); later points keep 0.3
    np.testing.assert_allclose(seen, [0.1, 0.2, 0.3, 0.3, 0.3, 0.3], atol=1e-16)
    s = _block(fault_class=STUCK, channel=0, onset=0.0, stuck_mode=1, magnitude=-0.05)
    np.testing.assert_array_equal(_out(s, 0.0)["u_f"], [-0.05] * 3)


def test_markov_switching_follows_the_independent_path():
    from papers.p004_xu2024.parameters import FAULT_MODES, RATE_VERTICES

    params = {"fault_class": MARKOV, "alpha_profile": ALPHA_COS2, "seed": 7, "r0": 1}
    b = FaultCatalog(3)
    b.set_defaults({"F": FAULT_MODES["F"], "G": FAULT_MODES["G"], "v": FAULT_MODES["v"], "Pi": RATE_VERTICES})
    b.set_parameters(params)
    b.initialize(0.0)
    times, modes = sample_path(RATE_VERTICES, AlphaProfile(ALPHA_COS2, 2), 1, 7, 20.0)
    assert len(times) > 5  # the path switches
    h, t = 0.01, 0.0
    for _ in range(2000):
        o = _out(b, t)
        r = int(modes[np.searchsorted(times, t + 1e-9, side="right") - 1])
        assert o["mode"] == r, t
        F, G = FAULT_MODES["F"][r - 1], FAULT_MODES["G"][r - 1]
        np.testing.assert_allclose(o["u_f"], F * U + G * FAULT_MODES["v"], atol=1e-15)
        assert o["t_next"] > t
        b.advance(t, h, U)
        t = round(t + h, 10)


def test_markov_on_one_channel_leaves_the_others_healthy():
    from papers.p004_xu2024.parameters import FAULT_MODES

    b = FaultCatalog(3)
    b.set_defaults({"F": FAULT_MODES["F"], "G": FAULT_MODES["G"], "v": FAULT_MODES["v"]})
    b.set_parameters({"fault_class": MARKOV, "channel": 3, "r0": 2})  # no rates: mode 2 for ever
    b.initialize(0.0)
    np.testing.assert_allclose(_out(b, 5.0)["u_f"], [0.3, -0.2, 0.5 * 0.6], atol=1e-16)


def test_rollback_restores_markov_and_stuck_states_exactly():
    from papers.p004_xu2024.parameters import RATE_VERTICES

    for params in ({"fault_class": MARKOV, "alpha_profile": ALPHA_COS2, "seed": 3},
                   {"fault_class": STUCK, "onset": 0.05, "channel": 1}):
        b = FaultCatalog(3)
        b.set_defaults({"Pi": RATE_VERTICES, "F": np.array([[1.0] * 3, [0.5] * 3, [1.0] * 3])})
        b.set_parameters(params)
        b.initialize(0.0)
        t = 0.0
        for k in range(300):
            b.advance(t, 0.01, U * (1 + 0.01 * k))
            t += 0.01
        saved = b.get_state()
        run = []
        for _rep in range(2):
            b.set_state(saved)
            tt, ys = t, []
            for k in range(300):
                ys.append(b.outputs_at(tt, U * k).tolist())
                b.advance(tt, 0.01, U * k)
                tt += 0.01
            run.append(ys)
        assert run[0] == run[1]


@pytest.mark.parametrize("params,match", [
    ({"fault_class": 9}, "fault_class"),
    ({"fault_class": LOE_STEP, "loss": 1.5}, "loss"),
    ({"fault_class": LOE_STEP, "channel": 4}, "channel"),
    ({"fault_class": LOE_RAMP, "loss": 0.5, "ramp_time": 0.0}, "ramp_time"),
    ({"fault_class": INTERMITTENT, "loss": 0.5, "duty": 1.5}, "duty"),
    ({"fault_class": MARKOV, "Pi[1,1,2]": -1.0}, "negative"),
])
def test_bad_parameters_are_named(params, match):
    with pytest.raises(ValueError, match=match):
        _block(**params)


@pytest.mark.parametrize("cls", [NONE, LOE_STEP, BIAS, LOST, INTERMITTENT, MARKOV])
def test_outputs_kept_between_events_are_the_recomputed_ones(cls):
    """outputs_at keeps e and b between events for the piecewise-constant classes: on a 10 ms grid
    through the onset (and a few points off the grid), with changing commands, the outputs equal a
    recomputation from scratch bit for bit."""
    kw = dict(fault_class=cls, channel=2, onset=0.37, loss=0.4, magnitude=0.05, period=0.1, duty=0.5, seed=3)
    b, ref = _block(**kw), _block(**kw)
    rng = np.random.default_rng(1)
    times = sorted(set(np.round(np.arange(0.0, 1.0, 0.01), 12).tolist() + [0.369999999, 0.37, 0.3700001]))
    for k, t in enumerate(times):
        u = rng.normal(size=3)
        ref._segment = None  # recomputed from scratch
        assert np.array_equal(b.outputs_at(t, u), ref.outputs_at(t, u)), (cls, t)
        if k + 1 < len(times):
            h = times[k + 1] - t
            b.advance(t, h, u)
            ref.advance(t, h, u)
