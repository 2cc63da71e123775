"""Compiled kernels (plant/kernels) against the numpy reference code of every block that has one:
outputs, feedthrough outputs and the state after a step, on random states and inputs (including
steps across fault onsets and switches, and projections that bind), to 1e-12 relative."""
import numpy as np
import pytest

from plant import kernels

pytestmark = pytest.mark.skipif(not kernels.enabled(), reason=f"kernels off: {kernels.REASON}")

RTOL = 1e-12


def close(k, r, what):
    k, r = np.asarray(k, float), np.asarray(r, float)
    assert k.shape == r.shape, what
    scale = max(1.0, float(np.abs(r).max(initial=0.0)))
    err = float(np.abs(k - r).max(initial=0.0))
    assert err <= RTOL * scale, f"{what}: kernel - reference = {err:.3g} (scale {scale:.3g})"


def pair(factory, params=None):
    """The same block twice, initialised with kernels on and off."""
    out = []
    for on in (True, False):
        previous = kernels.set_enabled(on)
        try:
            b = factory()
            b.set_parameters(params or {})
            b.initialize(0.0)
        finally:
            kernels.set_enabled(previous)
        assert b._kernels is on
        out.append(b)
    return out


def compare(factory, params, state, inputs, times, h, rng, cases=40):
    """For random (state, input, time): outputs, feedthrough outputs and the state after one step."""
    k, r = pair(factory, params)
    for _ in range(cases):
        x = state(rng)
        u = inputs(rng)
        t = float(rng.choice(times))
        k.set_state(list(x))
        r.set_state(list(x))
        yk, yr = k.outputs_at(t, u), r.outputs_at(t, u)
        close(yk, yr, f"outputs at t = {t}")
        if hasattr(r, "feedthrough_outputs"):
            u2 = inputs(rng)
            close(k.feedthrough_outputs(t, u2, yk.copy()), r.feedthrough_outputs(t, u2, yr.copy()), "feedthrough outputs")
        k.advance(t, h, u)
        r.advance(t, h, u)
        close(k.get_state(), r.get_state(), f"state after [{t}, {t + h}]")


def unit_quaternion(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def test_flexible_spacecraft():
    from papers.p000_li2023.blocks import flexible_spacecraft

    rng = np.random.default_rng(0)
    times = [0.0, 12.3, 39.995, 40.0, 40.004, 69.995, 70.0, 99.999, 100.0, 131.7]
    for params in ({}, {"fault_scale": 1.0, "disturbance_scale": 1.0},
                   {"fault_scale": 0.2, "effectiveness[1]": 0.4, "effectiveness[3]": 0.7, "effectiveness_onset": 40.0,
                    "bias[2]": 0.3, "bias_onset": 70.003, "saturation_mode": 1, "misalign_a[1]": 0.2, "h_max": 0.004}):
        compare(flexible_spacecraft, params,
                lambda g: np.concatenate([unit_quaternion(g), g.normal(size=3) * 0.3, g.normal(size=8) * 0.01]),
                lambda g: g.normal(size=3) * 4.0, times, 0.01, rng)
    # with the wheel momenta as states (wheel_momentum = 1): y = [q, omega, eta, eta_dot, h_w]
    for params in ({"wheel_momentum": 1.0}, {"wheel_momentum": 1.0, "fault_scale": 1.0, "disturbance_scale": 1.0,
                                              "effectiveness[2]": 0.5, "effectiveness_onset": 40.0, "misalign_b[3]": 0.3}):
        compare(flexible_spacecraft, params,
                lambda g: np.concatenate([unit_quaternion(g), g.normal(size=3) * 0.3, g.normal(size=8) * 0.01,
                                          g.normal(size=3) * 20.0]),
                lambda g: g.normal(size=3) * 4.0, times, 0.01, rng)


def test_fafeo():
    from papers.p000_li2023.blocks import fafeo

    rng = np.random.default_rng(1)
    for params in ({}, {"sampling_mode": 0, "h_max": 0.0025}, {"f_min": -0.05, "f_max": 0.05, "d_max": 0.001}):
        compare(fafeo, params,
                lambda g: np.concatenate([g.normal(size=3) * 0.3, g.normal(size=3), g.normal(size=8) * 0.01, [1.0]]),
                lambda g: np.concatenate([g.normal(size=3) * 0.5, g.normal(size=3) * 3]), [0.0, 5.0], 0.01, rng)


def controller_inputs(rng, n=4):
    return np.concatenate([unit_quaternion(rng), rng.normal(size=3) * 0.5, unit_quaternion(rng), rng.normal(size=3) * 0.05,
                           rng.normal(size=3) * 0.01, rng.normal(size=3), rng.normal(size=2 * n) * 0.01])


@pytest.mark.parametrize("name", ["fasmc", "aismc", "pd_controller"])
def test_attitude_controllers(name):
    from papers.p000_li2023 import blocks

    rng = np.random.default_rng(2)
    factory = getattr(blocks, name)
    for params in ({}, {"saturation_mode": 1}):
        n_state = len(factory().get_state())
        compare(factory, params, lambda g, n=n_state: g.normal(size=n) * 0.1, controller_inputs, [0.0, 3.0], 0.01, rng)
    # omega_d = 0 and d2_hat = 0: the branches the reference skips
    k, r = pair(factory)
    u = controller_inputs(rng)
    u[11:17] = 0.0
    u[20:] = 0.0
    close(k.outputs_at(0.0, u), r.outputs_at(0.0, u), "outputs with omega_d = 0, d2_hat = 0")


def test_tsfdo():
    from papers.p003_hang2023.blocks import observer

    rng = np.random.default_rng(3)
    for params in ({}, {"sampling_mode": 0, "h_max": 2.5e-4}):
        n_state = len(observer().get_state())
        compare(observer, {**params, "step_check": 0},
                lambda g, n=n_state: np.concatenate([g.normal(size=n - 2) * 0.1, [float(g.integers(2)), 0.0]]),
                lambda g: g.normal(size=3) * [0.05, 0.01, 0.5], [0.0, 1.0], 0.001, rng)


@pytest.mark.parametrize("paper", ["p002_zhang2014", "p003_hang2023"])
def test_pitch_axis_feedthrough_outputs(paper):
    """The pitch-axis plant's feedthrough_outputs (tau_applied only) equals a full evaluation."""
    import importlib

    b = importlib.import_module(f"papers.{paper}.blocks").plant()
    b.initialize(0.0)
    rng = np.random.default_rng(4)
    for t in (0.0, 19.9995, 20.0, 35.0):
        b.set_state(list(rng.normal(size=len(b.get_state())) * 0.01))
        y = b.outputs_at(t, np.array([0.1]))
        u2 = rng.normal(size=1)
        assert np.array_equal(b.feedthrough_outputs(t, u2, y.copy()), b.outputs_at(t, u2))


def test_rigid_wheels_plant():
    """001's plant: RK4 steps of 4 ms (4 internal steps) before, across and after the fault onsets
    (20 s), with and without saturation; the validity guard gives the reference's message."""
    from papers.p001_zhang2019.blocks import plant

    rng = np.random.default_rng(7)
    for params in ({}, {"u_max": 0.05}):
        compare(plant, params, lambda g: np.concatenate([g.normal(size=3) * 0.5, g.normal(size=3) * 0.5]),
                lambda g: g.normal(size=4) * 0.1, [0.0, 19.998, 20.0, 35.0], 0.004, rng)
    for params in ({"wheel_momentum": 1.0}, {"wheel_momentum": 1.0, "u_max": 0.05}):  # state [sigma, omega, h_w]
        compare(plant, params, lambda g: np.concatenate([g.normal(size=3) * 0.5, g.normal(size=3) * 0.5,
                                                         g.normal(size=4) * 10.0]),
                lambda g: g.normal(size=4) * 0.1, [0.0, 19.998, 20.0, 35.0], 0.004, rng)
    messages = []
    for b in pair(plant):
        b.set_state([1.553, 0.0, 0.0, 1.0, 0.0, 0.5])  # nu crosses nu_max within the step
        with pytest.raises(FloatingPointError) as info:
            b.advance(0.0, 0.01, np.zeros(4))
        messages.append(str(info.value))
    assert messages[0] == messages[1] and "singularity" in messages[0]


def test_asmfeo():
    """001's ASMFEO, held innovation (sampling_mode 1): K on both branches of 001 (15) (above and
    below mu, ||omega~|| above and below epsilon), zero innovation components, 4 internal steps."""
    from papers.p001_zhang2019.blocks import observer

    rng = np.random.default_rng(8)

    def state(g):
        n = 4
        K = float(g.choice([1e-5, 1e-4, 0.01]))  # mu = 1e-4 (below, at, above)
        return np.concatenate([g.normal(size=3) * 0.5, g.uniform(0.5, 1.0, n), g.normal(size=n) * 0.02, [K]])

    def inputs(g):
        u = np.concatenate([g.normal(size=3) * 0.5, g.normal(size=4) * 0.1])
        if g.random() < 0.3:
            u[0:3] *= 1e-6  # the innovation omega - omega_hat is then around omega_hat
        return u

    compare(observer, {"h_max": 2.5e-4}, state, inputs, [0.0, 20.0], 0.001, rng)

    def state_paired(g):  # with the previous command (command_pairing = 1), present or not yet
        return np.concatenate([state(g), g.normal(size=4) * 0.1, [float(g.random() < 0.8)]])

    compare(observer, {"h_max": 2.5e-4, "command_pairing": 1}, state_paired, inputs, [0.0, 20.0], 0.001, rng)
    k, r = pair(observer)
    x = state(rng)
    for b in (k, r):
        b.set_state(list(x))
        b.advance(0.0, 0.001, np.concatenate([x[0:3], np.zeros(4)]))  # omega~ = 0 exactly
    close(k.get_state(), r.get_state(), "zero innovation")


def test_fontsm():
    """001's FONTSM law (c = 0): random GL memories (at and after the first sample), sign and
    boundary-layer switching, both pairings, e_hat clipped by the allocation."""
    from papers.p001_zhang2019.blocks import controller

    rng = np.random.default_rng(9)
    m = 60  # retained past samples

    def state(g):
        k = float(g.choice([0, m]))
        hist = g.normal(size=2 * 3 * int(k)) * 0.3
        return np.concatenate([g.normal(size=9) * 0.1, [k, k], hist])

    def inputs(g):
        return np.concatenate([g.normal(size=3) * 0.5, g.normal(size=3) * 0.3, g.uniform(0.3, 1.2, 4),
                               g.normal(size=4) * 0.05, g.normal(size=3) * 0.1])

    for params in ({"fo_step": 0.001}, {"fo_step": 0.001, "boundary_layer": 0.05, "pairing": 0, "fo_start": 0}):
        compare(controller, params, state, inputs, [0.0], 0.001, rng, cases=30)
    u = inputs(rng)
    u[6:8] = -0.1  # two failed wheels (clipped to e_hat_min = 0): the allocation is singular
    messages = []
    for b in pair(controller, {"fo_step": 0.001}):
        with pytest.raises(FloatingPointError) as info:
            b.outputs_at(0.0, u)
        messages.append(str(info.value))
    # lambda_min is 0 up to rounding (the last bits differ): the rest of the message is the same
    assert messages[0].split("(e_hat")[1] == messages[1].split("(e_hat")[1] and "singular" in messages[0]


@pytest.mark.parametrize("factory", ["plant", "observer"])
def test_zhang2019_feedthrough_outputs(factory):
    """001's plant and ASMFEO: feedthrough_outputs (the outputs that depend on u_c) equals a full
    evaluation bit for bit, before and after the fault onsets (20 s) and with saturation."""
    from papers.p001_zhang2019 import blocks

    b = getattr(blocks, factory)()
    if factory == "plant":
        b.set_parameters({"u_max": 0.05})
    b.initialize(0.0)
    rng = np.random.default_rng(6)
    n_in = len(b.inputs)
    for t in (0.0, 19.9995, 20.0, 35.0):
        x = np.array(b.get_state()) + rng.normal(size=len(b.get_state())) * 0.01
        b.set_state(list(x))
        y = b.outputs_at(t, rng.normal(size=n_in) * 0.1)
        u2 = rng.normal(size=n_in) * 0.1
        assert np.array_equal(b.feedthrough_outputs(t, u2, y.copy()), b.outputs_at(t, u2))


def test_ts_attitude_plant():
    """004's T-S plant (triangular product memberships at every RK4 stage), including states on
    the degenerate set (the mean fallback) and outside the premise domain."""
    from papers.p004_xu2024.blocks import ts_plant

    rng = np.random.default_rng(5)
    b = ts_plant()
    b.initialize(0.0)
    half = b.memb.b

    def state(g):
        x = g.uniform(-1.5, 1.5, size=6) * half
        if g.random() < 0.3:  # on a domain edge with components of both signs
            x[0], x[1] = half[0], -half[1]
        return x

    compare(ts_plant, {}, state, lambda g: g.normal(size=3) * 0.5, [0.0], 0.01, rng)
    from plant.kernels.ts_attitude import triangular_weights

    for _ in range(200):
        z = state(rng)
        out = np.empty(b.memb.n_rules)
        triangular_weights(z, b.memb.b, b.memb.s, np.ascontiguousarray(b.memb._row, dtype=np.int64), b.memb.tol, out)
        close(out, b.memb.weights(z), "triangular weights")
