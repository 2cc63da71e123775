"""Actuator path, faults and disturbance, each against its formula."""
import math

import numpy as np
import pytest

from papers.p000_li2023 import blocks as li2023
from plant.actuator import (
    SATURATE_ONE_NORM,
    SATURATE_PER_AXIS,
    effectiveness_and_bias,
    li2023_disturbance,
    li2023_fault,
    misalignment,
    saturate,
)


def test_per_axis_saturation():
    u = np.array([7.0, -9.0, 2.0])
    assert np.array_equal(saturate(u, 5.0, SATURATE_PER_AXIS), [5.0, -5.0, 2.0])


def test_one_norm_saturation_keeps_direction():
    u = np.array([3.0, -4.0, 3.0])  # ||u||_1 = 10
    s = saturate(u, 5.0, SATURATE_ONE_NORM)
    assert math.isclose(np.abs(s).sum(), 5.0)
    assert np.allclose(s / np.linalg.norm(s), u / np.linalg.norm(u))
    small = np.array([1.0, -1.0, 1.0])
    assert np.array_equal(saturate(small, 5.0, SATURATE_ONE_NORM), small)


def test_li2023_fault_profile_000_66():
    """000 (66), switches by plant/timing.py: at a point the new value holds from the switch on,
    whatever rounding the time carries; inside a step by the one-sided rule."""
    from plant.timing import StepWindow

    assert li2023_fault(39.99) == (0.0, 0.0, 0.0)
    for t40 in (40.0, np.nextafter(40.0, 0.0), np.nextafter(40.0, 50.0), 40.0 + 3e-14):
        assert li2023_fault(t40)[1] == 1.0  # 1 N.m from 40 s on
    t = 57.3
    f1, f2, f3 = li2023_fault(t)
    assert math.isclose(f1, 0.5 * (t - 40) ** 0.2 * math.sin(0.2 * (t - 40)))
    assert (f2, f3) == (1.0, 0.0)
    assert li2023_fault(69.99)[1] == 1.0 and li2023_fault(70.0)[1] == 0.0 and li2023_fault(70.01)[1] == 0.0
    assert li2023_fault(99.99)[1] == 0.0 and li2023_fault(100.0)[1] == 1.5
    # inside the step [39.99, 40]: the fault is off at every stage, the end point included
    w = StepWindow(39.99, 0.01)
    assert li2023_fault(40.0, window=w) == li2023_fault(np.nextafter(40.0, 50.0), window=w) == (0.0, 0.0, 0.0)
    # inside [40, 40.01] (start formed with an ulp below 40): on at every stage
    w = StepWindow(np.nextafter(40.0, 0.0), 0.01)
    assert all(li2023_fault(40.0 + c * 0.01, window=w)[1] == 1.0 for c in (0.0, 0.5, 1.0))
    # a switch strictly inside a step acts at the stage times after it
    w = StepWindow(40.0, 0.02)
    assert li2023_fault(40.0, onset=40.01, window=w)[1] == 0.0 and li2023_fault(40.015, onset=40.01, window=w)[1] == 1.0
    weak = li2023_fault(t, scale=0.2)
    assert np.allclose(weak, 0.2 * np.array(li2023_fault(t)))
    assert li2023_fault(t + 10, onset=50.0) == li2023_fault(t)


def test_li2023_disturbance_formula():
    t = 3.7
    d = li2023_disturbance(t)
    a, b = 0.2 * math.pi * t, 0.4 * math.pi * t
    ref = 1e-4 * np.array(
        [-3 + 4 * math.cos(a) - math.cos(b), 4 + 3 * math.sin(a) - 2 * math.cos(b), -3 + 4 * math.sin(a) - 3 * math.sin(b)]
    )
    assert np.allclose(d, ref, rtol=0, atol=1e-18)


def test_misalignment_000_section5():
    dg = misalignment([0.2, 0.1, 0.1], [0.15, 0.1, 0.1])
    assert np.all(np.diag(dg) == 0)
    col1 = math.radians(0.2) * math.cos(math.radians(0.15))
    assert math.isclose(dg[1, 0], col1) and math.isclose(dg[2, 0], col1)
    assert math.isclose(dg[0, 1], math.radians(0.1) * math.cos(math.radians(0.1)))


def test_effectiveness_and_bias_onsets_001_5():
    e = np.array([1.0, 0.6, 1.0])
    b = np.array([0.04, 0.0, 0.0])
    e0, b0 = effectiveness_and_bias(19.99, e, 20.0, b, 20.0)
    assert np.array_equal(e0, [1, 1, 1]) and np.array_equal(b0, [0, 0, 0])
    e1, b1 = effectiveness_and_bias(20.0, e, 20.0, b, 20.0)
    assert np.array_equal(e1, e) and np.array_equal(b1, b)


@pytest.mark.parametrize("t", [10.0, 45.0, 130.0])
def test_plant_actuator_path_composes_the_formulas(t):
    """tau = (Gamma + Delta Gamma)(E sat(u) + u_f + f(t)); f_eq = tau-equivalent fault."""
    p = li2023.flexible_spacecraft()
    p.set_parameters(
        {
            "fault_scale": 1.0, "u_max": 5.0,
            "misalign_a[1]": 0.2, "misalign_a[2]": 0.1, "misalign_a[3]": 0.1,
            "misalign_b[1]": 0.15, "misalign_b[2]": 0.1, "misalign_b[3]": 0.1,
            "effectiveness[2]": 0.6, "effectiveness_onset": 20.0,
            "bias[1]": 0.04, "bias_onset": 20.0,
        }
    )
    p.initialize(0.0)
    u = np.array([7.0, -2.0, 1.0])
    out = p.outputs_at(t, u)
    tau, f = out[p.output_index["tau_applied[1]"] : p.output_index["tau_applied[1]"] + 3], out[p.output_index["f[1]"] : p.output_index["f[1]"] + 3]
    us = np.array([5.0, -2.0, 1.0])
    e = np.array([1.0, 0.6, 1.0]) if t >= 20 else np.ones(3)
    uf = np.array([0.04, 0, 0]) if t >= 20 else np.zeros(3)
    f000 = np.array(li2023_fault(t))
    G = np.eye(3) + misalignment([0.2, 0.1, 0.1], [0.15, 0.1, 0.1])
    assert np.allclose(tau, G @ (e * us + uf + f000), rtol=1e-14, atol=1e-14)
    assert np.allclose(f, (e - 1) * us + uf + f000, rtol=1e-14, atol=1e-14)


def test_disturbance_enters_the_dynamics():
    """With u = 0 and only u_d, the initial angular acceleration is (J - d^T d)^-1 u_d."""
    p = li2023.flexible_spacecraft()
    p.set_parameters({"disturbance_scale": 1.0})
    p.initialize(0.0)
    ud = np.array(li2023_disturbance(0.0))
    acc = p._deriv(p.y, ud)[4:7]
    Jm = p.J - p.delta.T @ p.delta
    assert np.allclose(acc, np.linalg.solve(Jm, ud), rtol=1e-12, atol=0)
    k = p.output_index["u_d[1]"]
    assert np.allclose(p.outputs_at(0.0, np.zeros(3))[k:k + 3], ud)
