"""Grünwald-Letnikov (GL) fractional operators on a uniform sampling grid, with memory.

For samples f_k = f(t0 + k h), the GL approximation of the Riemann-Liouville operator of order
alpha (a derivative for alpha > 0, an integral I^-alpha for alpha < 0), t0 the start:

    D^alpha f(t_k) ~ h^-alpha sum_{j=0}^{n} w_j f_{k-j},   w_0 = 1,  w_j = w_{j-1} (1 - (alpha + 1) / j)

which converges to the RL operator (001 (21)) as h -> 0 (first order). The weights are those of
(1 - z)^alpha, so w^(alpha+1) = w^(alpha) * [1, -1]: the GL derivative of order alpha + 1 is exactly
the backward difference of the GL values of order alpha, (D^alpha f(t_k) - D^alpha f(t_{k-1})) / h
(what 001's Property 4.1 (22) says of the RL operators). That is how controller/fontsm.py forms its
orders 1 + alpha_1 and alpha_2 from two GL sums.

Memory: n = min(k, L) past samples, L = ``memory`` (samples). L >= k gives the full GL sum from
t0 (faithful to (21)); a smaller L is the "short-memory principle" (Podlubny): the sum is
truncated to the last L h seconds. Samples live in a chronological buffer that grows by doubling
up to 2 L and is compacted when full, so a step costs one dot product of length n per channel
(in chunks of ``CHUNK``). The result depends only on the values and n, not on where the buffer
lies in memory, so restoring a state (``get_state``/``set_state``) reproduces a run bit for bit.
"""
from __future__ import annotations

import numpy as np

# Dot products are taken over chunks of at most CHUNK samples: OpenBLAS multithreads a ddot above
# ~10^4 elements, and on a loaded machine its threads cost ~100x the arithmetic (measured: 8.6 ms
# instead of 0.15 ms for n = 60000 with the two cores busy). Chunks also keep the summation order
# a function of n alone.
CHUNK = 4096


def gl_weights(alpha: float, n: int) -> np.ndarray:
    """w_0..w_n of order alpha: w_0 = 1, w_j = w_{j-1} (1 - (alpha + 1)/j)."""
    j = np.arange(1, n + 1, dtype=float)
    return np.concatenate(([1.0], np.cumprod(1.0 - (alpha + 1.0) / j)))


class GLHistory:
    """Past samples of a ``width``-channel signal and their GL sums, channel i of order alpha[i].

    ``past_sum()`` = sum_{j=1}^{n} w_j f_{k-j} per channel (n = retained past samples);
    ``value(f_k, h)`` = h^-alpha (f_k + past_sum()); ``push(f_k)`` commits f_k.
    """

    def __init__(self, alpha, memory: int, initial_capacity: int = 1024):
        self.alpha = np.atleast_1d(np.asarray(alpha, dtype=float)).copy()
        self.width = self.alpha.size
        if int(memory) != memory or memory < 1:
            raise ValueError(f"memory must be a whole number of samples >= 1, got {memory}")
        self.memory = int(memory)
        self._cap0 = max(2, min(int(initial_capacity), 2 * self.memory))
        self._rev = [None] * self.width  # reversed weights [w_m, ..., w_1] per channel (a cache)
        self._m = 0
        self.reset()

    def reset(self) -> None:
        self.buf = np.zeros((self.width, self._cap0))
        self.end = 0  # samples occupy buf[:, end - n : end]
        self.n = 0

    # -- weights (derived data, not state) ---------------------------------------------------------
    def _ensure_weights(self, n: int) -> None:
        if n <= self._m:
            return
        m = min(self.memory, max(n, 2 * self._m, 1024))
        self._rev = [np.ascontiguousarray(gl_weights(a, m)[:0:-1]) for a in self.alpha]
        self._m = m

    # -- sums --------------------------------------------------------------------------------------
    def past_sum(self) -> np.ndarray:
        n = self.n
        if n == 0:
            return np.zeros(self.width)
        self._ensure_weights(n)
        a, m = self.end - n, self._m
        out = []
        for i in range(self.width):
            x, w = self.buf[i], self._rev[i]
            acc = 0.0
            for c in range(0, n, CHUNK):  # fixed chunks from the oldest retained sample
                k = min(CHUNK, n - c)
                acc += float(np.dot(x[a + c : a + c + k], w[m - n + c : m - n + c + k]))
            out.append(acc)
        return np.array(out)

    def value(self, f_k, h: float, past=None) -> np.ndarray:
        past = self.past_sum() if past is None else past
        return h ** (-self.alpha) * (np.asarray(f_k, dtype=float) + past)

    def push(self, f_k) -> None:
        if self.end == self.buf.shape[1]:
            keep = min(self.n, self.memory - 1)  # after this push n is at most memory
            cap = self.buf.shape[1]
            new_cap = min(2 * cap, 2 * self.memory) if cap < 2 * self.memory else cap
            new = np.zeros((self.width, new_cap))
            if keep:
                new[:, :keep] = self.buf[:, self.end - keep : self.end]
            self.buf, self.end, self.n = new, keep, keep
        self.buf[:, self.end] = f_k
        self.end += 1
        self.n = min(self.n + 1, self.memory)

    # -- state -------------------------------------------------------------------------------------
    def samples(self) -> np.ndarray:
        """Retained past samples, oldest first, shape (n, width)."""
        return self.buf[:, self.end - self.n : self.end].T.copy()

    def set_samples(self, samples) -> None:
        s = np.asarray(samples, dtype=float).reshape(-1, self.width)
        if s.shape[0] > self.memory:
            raise ValueError(f"{s.shape[0]} samples exceed the memory of {self.memory}")
        self.reset()
        cap = self._cap0
        while cap < s.shape[0] + 1 and cap < 2 * self.memory:
            cap *= 2
        self.buf = np.zeros((self.width, max(cap, s.shape[0])))
        self.buf[:, : s.shape[0]] = s.T
        self.end = self.n = s.shape[0]
