"""004 (7)-(8), (14): the sensor network (printed values give no feedback), the aperiodic
sample schedule driven at its announced instants, zero-order hold, mode handling, bad input."""
import json

import numpy as np
import pytest

from controller.sampled_fuzzy import SampledFuzzyFTC, SampleSchedule, network_gain, network_matrix
from papers.p004_xu2024 import parameters as P
from papers.p004_xu2024.blocks import controller

TAU_MIN, TAU_MAX = P.SAMPLING["tau_min"], P.SAMPLING["tau_max"]


def _inputs(y, mode=1.0):
    q = np.asarray(y[3:6], float)
    return np.concatenate([y[:3], [np.sqrt(max(0.0, 1 - q @ q))], q, [mode]])


def _names(b):
    return [v.name for v in b.outputs]


def test_printed_network_gives_zero_feedback():
    """N1: with the printed Theta (rows sum to 0) and L = 0.8, 0.5, 0.9 I, the column sums
    (0.4, -0.1, -0.3) weighted by (0.8, 0.5, 0.9) vanish: I_qm^T (Theta (x) I) L = 0, built
    literally with Kronecker products."""
    Th, L = P.NETWORK["Theta"], P.NETWORK["L_gain"]
    assert np.allclose(Th.sum(axis=1), 0.0, atol=1e-15)
    assert np.allclose(Th.sum(axis=0), [0.4, -0.1, -0.3], atol=1e-15)
    Ms = network_matrix(Th, L)
    assert Ms.shape == (6, 6) and np.abs(Ms).max() < 1e-15
    assert abs(network_gain(Th, L)) < 1e-15
    # a generic network is not degenerate: the same routine gives a nonzero m_s I
    L2 = np.array([1.0, 0.5, 0.9])
    assert np.allclose(network_matrix(Th, L2), network_gain(Th, L2) * np.eye(6))
    assert abs(network_gain(Th, L2)) > 0.05


def test_printed_network_mode_commands_nothing_bypass_does():
    y = np.array([0.3, -0.2, 0.1, 0.05, -0.1, 0.2])
    out = {}
    for mode in (0, 1):
        b = controller()
        b.set_parameter("network_mode", mode)
        b.initialize(0.0)
        out[mode] = b.outputs_at(0.0, _inputs(y))
    n = _names(b)
    assert np.abs(out[0][:3]).max() < 1e-12 and abs(out[0][n.index("network_gain")]) < 1e-15
    assert np.abs(out[1][:3]).max() > 10.0


def _drive_at_announced_instants(b, t_end, y_of_t):
    """A small master: step exactly to each announced instant t_next_sample (variable steps)."""
    n = _names(b)
    t, instants, lengths = 0.0, [], []
    while t < t_end:
        u = _inputs(y_of_t(t))
        out = b.outputs_at(t, u)
        if out[n.index("t_k")] == t:
            instants.append(t)
        t_next = out[n.index("t_next_sample")]
        b.advance(t, t_next - t, u)
        lengths.append(t_next - t)
        t = t_next
    return np.array(instants), np.array(lengths)


def test_controller_is_stepped_exactly_at_its_announced_instants():
    """Every step of the driver ends on an announced instant; the controller latches there
    (t_k = t), the intervals lie in [tau_min, tau_max] and on the 1 ms grid, and the
    instants equal the schedule's pure function of (seed, k)."""
    b = controller()
    b.set_parameter("sample_seed", 5)
    b.initialize(0.0)
    inst, lengths = _drive_at_announced_instants(b, 20.0, lambda t: np.full(6, 0.1 * np.cos(t)))
    d = np.diff(inst)
    assert len(inst) > 150
    assert d.min() >= TAU_MIN - 1e-12 and d.max() <= TAU_MAX + 1e-12
    assert np.array_equal(lengths[: len(d)], d)  # every step went from one instant to the next
    assert np.allclose(np.round(d / 1e-3), d / 1e-3, atol=1e-9)  # on the quantum grid
    assert len(np.unique(np.round(d, 9))) > 20  # really aperiodic (51 possible lengths)
    sched = SampleSchedule(0.0, 1e-3, TAU_MIN, TAU_MAX, 5, 1)
    assert np.array_equal(inst, sched.instants(inst[-1]))


def test_fixed_grid_and_announced_instants_give_the_same_commands():
    """A 1 ms fixed-step driver and the announced-instant driver: same instants, and the
    command at every instant is the same (the hold does not depend on the host's steps)."""
    y_of_t = lambda t: np.array([0.2 * np.sin(t), 0.1, -0.1 * t, 0.05, 0.0, -0.02])  # noqa: E731
    a = controller()
    a.initialize(0.0)
    inst, _ = _drive_at_announced_instants(a, 2.0, y_of_t)
    b = controller()
    b.initialize(0.0)
    n = _names(b)
    seen, cmds = [], {}
    for k in range(2000):
        t = k * 1e-3  # t += h arithmetic, not the schedule's integer nanoseconds
        out = b.outputs_at(t, _inputs(y_of_t(t)))
        if abs(out[n.index("t_k")] - t) < 1e-12:
            seen.append(t)
            cmds[round(t, 9)] = out[:3]
            assert out[n.index("sample_count")] == len(seen)
        b.advance(t, 1e-3, _inputs(y_of_t(t)))
    assert np.allclose(seen, inst[inst < 2.0], atol=1e-12)
    c = controller()
    c.initialize(0.0)
    for t in inst[inst < 2.0]:
        out = c.outputs_at(t, _inputs(y_of_t(t)))
        assert np.allclose(out[:3], cmds[round(t, 9)], rtol=1e-12, atol=1e-9)
        c.advance(t, c.outputs_at(t, _inputs(y_of_t(t)))[n.index("t_next_sample")] - t, _inputs(y_of_t(t)))


def test_zero_order_hold_between_instants_and_mode_switch():
    """Between instants u ignores new measurements (ZOH of y(t_k), h(t_k)); with
    mode_sampling = 0 (004 (16)) a mode change acts at once, with 1 it waits for t_{k+1}."""
    y0 = np.array([0.3, -0.2, 0.1, 0.05, -0.1, 0.2])
    y1 = -2 * y0
    res = {}
    for ms in (0, 1):
        b = controller()
        b.set_parameter("mode_sampling", ms)
        b.initialize(0.0)
        u0 = b.outputs_at(0.0, _inputs(y0))
        b.advance(0.0, 0.001, _inputs(y0))
        held = b.outputs_at(0.001, _inputs(y1, 1.0))
        switched = b.outputs_at(0.001, _inputs(y1, 2.0))
        res[ms] = (u0[:3], held[:3], switched[:3])
    for ms in (0, 1):
        assert np.array_equal(res[ms][0], res[ms][1])  # held
    assert not np.allclose(res[0][2], res[0][0])  # mode 2 gains at once
    assert np.array_equal(res[1][2], res[1][0])  # r(t_k) held


def test_instant_inside_a_step_is_an_error():
    b = controller()
    b.set_parameter("sample_mode", 0)  # periodic 0.1 s
    b.initialize(0.0)
    b.advance(0.0, 0.06, _inputs(np.zeros(6)))
    with pytest.raises(ValueError, match=r"sample instant t = 0.1 s lies inside the communication step"):
        b.advance(0.06, 0.06, _inputs(np.zeros(6)))


def test_state_round_trip_is_exact():
    b = controller()
    b.initialize(0.0)
    y = lambda t: np.full(6, 0.2 * np.cos(3 * t))  # noqa: E731
    for k in range(137):
        b.advance(k * 1e-3, 1e-3, _inputs(y(k * 1e-3)))
    s = json.loads(json.dumps(b.get_state()))

    def run():
        out = []
        for k in range(137, 400):
            out.append(b.outputs_at(k * 1e-3, _inputs(y(k * 1e-3))).tobytes())
            b.advance(k * 1e-3, 1e-3, _inputs(y(k * 1e-3)))
        return out

    first = run()
    b.set_state(s)
    assert run() == first


@pytest.mark.parametrize("params, words", [
    ({"tau_min": 0.2, "tau_max": 0.1}, "tau_min = 0.2 s > tau_max = 0.1 s"),
    ({"tau_min": 0.0}, "tau_min = 0 s must be > 0"),
    ({"tau_min": 0.0612, "tau_max": 0.0618}, "no multiple of sample_quantum"),
    ({"Theta[1,2]": -0.3, "Theta[1,1]": -0.2}, "Theta[1,2] = -0.3 < 0"),
    ({"Theta[2,2]": -0.9}, "row 2 sums to 0.1"),
    ({"network_mode": 2}, "network_mode = 2 unknown"),
])
def test_bad_input_gives_one_clear_message(params, words):
    b = controller()
    b.set_parameters(params)
    with pytest.raises(ValueError) as e:
        b.initialize(0.0)
    assert words in str(e.value) and str(e.value).startswith("Xu2024SampledFTC:"), str(e.value)


def test_mode_input_out_of_range_is_named():
    b = SampledFuzzyFTC()
    b.initialize(0.0)
    with pytest.raises(ValueError, match="input mode = 4 is not one of the modes 1..3"):
        b.outputs_at(0.0, _inputs(np.zeros(6), 4.0))
