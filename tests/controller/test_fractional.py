"""Grünwald-Letnikov operators (controller/fractional.py) against closed forms of the
Riemann-Liouville operators, the weight identity, memory truncation and exact state restore."""
import math

import numpy as np
import pytest

from controller.fractional import GLHistory, gl_weights


def _gl(f, alpha, h, memory=10**9):
    """D^alpha f at the last sample by the GLHistory (pushing the samples before it)."""
    g = GLHistory([alpha], memory)
    for x in f[:-1]:
        g.push([x])
    return float(g.value([f[-1]], h)[0])


@pytest.mark.parametrize(
    "alpha, f, exact",
    [
        (0.01, lambda t: np.ones_like(t), lambda t: t**-0.01 / math.gamma(0.99)),  # D^a 1
        (-0.01, lambda t: np.ones_like(t), lambda t: t**0.01 / math.gamma(1.01)),  # I^0.01 1
        (0.01, lambda t: t, lambda t: t**0.99 / math.gamma(1.99)),  # D^a t
        (0.99, lambda t: t, lambda t: t**0.01 / math.gamma(1.01)),
        (0.5, lambda t: t**2, lambda t: 2 * t**1.5 / math.gamma(2.5)),
        (-0.5, lambda t: t, lambda t: t**1.5 / math.gamma(2.5)),
    ],
)
def test_gl_converges_to_riemann_liouville(alpha, f, exact):
    """First-order convergence: the error at t = 1 s halves (within 25 %) when h halves."""
    errs = []
    for h in (1e-2, 5e-3, 2.5e-3):
        t = np.arange(0, 1 + h / 2, h)
        errs.append(abs(_gl(f(t), alpha, h) - exact(1.0)))
    assert errs[-1] < 2e-2 * max(1.0, abs(exact(1.0)))
    for a, b in zip(errs, errs[1:]):
        assert 1.5 < a / b < 2.5, errs


def test_weights_and_the_order_plus_one_identity():
    w = gl_weights(0.01, 5)
    assert np.allclose(w[:4], [1.0, -0.01, -0.00495, -0.0032835], atol=1e-7)
    assert np.allclose(gl_weights(-0.01, 3)[:3], [1.0, 0.01, 0.00505], atol=1e-12)
    # w^(alpha+1) = w^(alpha) * [1, -1]: the GL derivative of order alpha+1 is the backward
    # difference of the GL values of order alpha (how controller/fontsm.py forms 1 + alpha_1)
    for a in (0.01, -0.01, 0.4):
        w0, w1 = gl_weights(a, 50), gl_weights(a + 1, 50)
        assert np.allclose(w1, w0 - np.concatenate(([0.0], w0[:-1])), atol=1e-15)
    rng = np.random.default_rng(3)
    f = rng.normal(size=200)
    h = 1e-3
    direct = h ** -1.01 * np.dot(gl_weights(1.01, 199)[::-1], f)
    diff = (_gl(f, 0.01, h) - _gl(f[:-1], 0.01, h)) / h
    assert math.isclose(direct, diff, rel_tol=1e-9)


def test_bounded_memory_is_the_truncated_sum_and_growth_does_not_change_it():
    """Against a naive sum over the last L samples, across buffer growth and compaction."""
    rng = np.random.default_rng(5)
    L = 300
    g = GLHistory([0.3, -0.2, 0.01], L, initial_capacity=16)
    w = np.array([gl_weights(a, L) for a in (0.3, -0.2, 0.01)])
    f = rng.normal(size=(2000, 3))
    for k in range(2000):
        if k % 97 == 0:
            n = min(k, L)
            past = f[k - n : k][::-1]  # f_{k-1}, ..., f_{k-n}
            naive = np.einsum("ij,ji->i", w[:, 1 : n + 1], past) if n else np.zeros(3)
            assert np.allclose(g.past_sum(), naive, rtol=1e-12, atol=1e-12), k
        g.push(f[k])
    assert g.n == L and g.buf.shape[1] <= 2 * L


def test_state_restore_is_bit_exact():
    rng = np.random.default_rng(8)
    g = GLHistory([0.01, 0.01, -0.01], 500, initial_capacity=8)
    for x in rng.normal(size=(777, 3)):
        g.push(x)
    saved = g.samples()
    before = [g.past_sum().tolist()]
    tail = rng.normal(size=(600, 3))
    for x in tail:
        g.push(x)
        before.append(g.past_sum().tolist())
    h = GLHistory([0.01, 0.01, -0.01], 500, initial_capacity=8)
    h.set_samples(saved)
    after = [h.past_sum().tolist()]
    for x in tail:
        h.push(x)
        after.append(h.past_sum().tolist())
    assert before == after  # bit for bit, although the buffers lie elsewhere and grew differently


def test_memory_must_be_positive():
    with pytest.raises(ValueError, match="memory"):
        GLHistory([0.5], 0)


def test_sums_longer_than_a_chunk_match_the_naive_sum():
    """Beyond CHUNK samples the dot is split into chunks (OpenBLAS threads a long ddot, see the
    module docstring): same value as one naive sum to rounding."""
    from controller.fractional import CHUNK

    rng = np.random.default_rng(9)
    n = 2 * CHUNK + 123
    g = GLHistory([0.01, -0.01, 0.5], n + 10)
    f = rng.normal(size=(n, 3))
    for x in f:
        g.push(x)
    w = np.array([gl_weights(a, n) for a in (0.01, -0.01, 0.5)])
    naive = np.array([np.sum(w[i, 1:] * f[::-1, i]) for i in range(3)])
    assert np.allclose(g.past_sum(), naive, rtol=1e-12, atol=1e-13)
