"""Continuous-time Markov chains with time-varying (polytopic) rates, sampled exactly.

The mode r(t) in {1..N} jumps with rates 004 (9)-(11): Pr{r(t+D) = j | r(t) = i} = pi_ij(t) D + o(D)
for j != i, with the generator confined to a polytope (004 (10))

    Pi(t) = sum_l alpha_l(t) Pi^(l),   alpha_l >= 0,  sum_l alpha_l = 1,

each vertex Pi^(l) a generator (off-diagonal entries >= 0, rows summing to 0). Profiles of
alpha(t) (``ALPHA_*``):

* ``ALPHA_CONSTANT``: alpha fixed (a homogeneous chain; alpha = e_1 gives Pi^(1));
* ``ALPHA_COS2``: alpha = (cos^2 t, sin^2 t), 004 (52) (Z = 2; |alpha_1'| = |sin 2t| <= 1, so
  the rate bound of 004 (11) is v_1 = 1);
* ``ALPHA_RANDOM``: alpha piecewise constant on a grid of ``alpha_grid`` seconds, Dirichlet(1)
  on each cell (for Z = 2: alpha_1 uniform on [0, 1]) drawn from ``numpy.random.default_rng(
  [alpha_seed, k])`` for cell k, i.e. a pure function of time (004 Remark 3 / Fig. 1 "random
  functions generated using MATLAB": our choice of such a function). alpha' is unbounded there,
  so this profile has no rate bound v for a design.

Exact sampling by thinning (uniformisation with a state-dependent bound): in mode i the exit
rate q_i(t) = -pi_ii(t) never exceeds lam_i = max_l(-pi_ii^(l)) (a convex combination of the
vertices). Candidate times follow a Poisson process of rate lam_i; a candidate at s jumps to
j != i with probability pi_ij(s) / lam_i and is otherwise fictitious. Each candidate draws
exactly two uniforms from one PCG64 stream (the waiting time -log(1 - u1) / lam_i, then u2
for the choice), so the path is a pure function of (seed, r0, vertices, profile, t0) and the
generator is consumed in a fixed order; ``get_state`` carries the PCG64 state exactly (the
128-bit words as 32-bit pieces, each exact in a float), so rollback and reruns are bit for bit.

The chain always knows its next jump (time and target): :meth:`MarkovChain.advance_to` takes
every jump that has happened at a time point, :attr:`t_next` is the next one. Jumps are
right-continuous: the new mode holds from the jump time on, and a jump at T counts as happened at
time t when ``plant.timing.happened_at(T, t)``.
"""
from __future__ import annotations

import math

import numpy as np

from .block import Block, Variable, scalar, vector
from .timing import happened_at

ALPHA_CONSTANT, ALPHA_COS2, ALPHA_RANDOM = 0, 1, 2
ALPHA_PROFILES = {ALPHA_CONSTANT: "constant alpha", ALPHA_COS2: "004 (52): cos^2 t, sin^2 t",
                  ALPHA_RANDOM: "random piecewise constant (Dirichlet(1) per cell)"}
T_NEVER = 1e300  # "no further jump" (absorbing mode); finite so that states stay JSON-safe
ROW_SUM_TOL = 1e-9  # relative to 1 + max |pi|


# ---------------------------------------------------------------------------------------
# rate matrices and profiles


def check_generator(Pi, name: str = "Pi") -> np.ndarray:
    """Check one transition-rate matrix (004 (9)): square, finite, off-diagonal >= 0, rows
    summing to 0. Returns it as a float array; ``ValueError`` names the entry otherwise."""
    P = np.asarray(Pi, dtype=float)
    if P.ndim != 2 or P.shape[0] != P.shape[1] or P.shape[0] == 0:
        raise ValueError(f"{name}: a transition-rate matrix must be square, got shape {P.shape}")
    if not np.all(np.isfinite(P)):
        raise ValueError(f"{name}: entries must be finite")
    n = P.shape[0]
    for i in range(n):
        for j in range(n):
            if i != j and P[i, j] < 0.0:
                raise ValueError(f"{name}: off-diagonal rate [{i + 1},{j + 1}] = {P[i, j]:g} 1/s is negative "
                                 "(004 (9): pi_ij >= 0 for i != j)")
    tol = ROW_SUM_TOL * (1.0 + float(np.abs(P).max()))
    for i in range(n):
        s = float(P[i].sum())
        if abs(s) > tol:
            raise ValueError(f"{name}: row {i + 1} sums to {s:.6g} 1/s, not 0 "
                             f"(004 (9): pi_ii = -sum_(j != i) pi_ij)")
    return P


def check_vertices(vertices, name: str = "Pi") -> np.ndarray:
    """(Z, N, N) stack of generators, each checked with :func:`check_generator`."""
    V = np.asarray(vertices, dtype=float)
    if V.ndim == 2:
        V = V[None]
    if V.ndim != 3:
        raise ValueError(f"{name}: expected a (Z, N, N) stack of rate matrices, got shape {V.shape}")
    return np.stack([check_generator(V[l], f"{name} vertex {l + 1}") for l in range(V.shape[0])])


class AlphaProfile:
    """alpha(t) of 004 (10) for one of the ``ALPHA_*`` profiles (a pure function of t)."""

    def __init__(self, kind: int, n_vertices: int, alpha=None, grid: float = 0.1, seed: int = 0):
        if kind not in ALPHA_PROFILES:
            raise ValueError(f"alpha_profile = {kind} unknown (known: "
                             + ", ".join(f"{k} {v}" for k, v in ALPHA_PROFILES.items()) + ")")
        self.kind, self.Z = int(kind), int(n_vertices)
        if self.kind == ALPHA_COS2 and self.Z != 2:
            raise ValueError(f"alpha_profile = 1 (004 (52)) needs 2 vertices, got {self.Z}")
        if self.kind == ALPHA_CONSTANT:
            a = np.ones(self.Z) / self.Z if alpha is None else np.asarray(alpha, dtype=float).ravel()
            if a.size != self.Z or np.any(a < 0) or not math.isclose(float(a.sum()), 1.0, rel_tol=0, abs_tol=1e-9):
                raise ValueError(f"alpha_const = {a.tolist()}: needs {self.Z} entries >= 0 summing to 1 (004 (10))")
            self.alpha = a
            self._alpha_list = a.tolist()
        if self.kind == ALPHA_RANDOM and not grid > 0:
            raise ValueError(f"alpha_grid = {grid:g} s must be > 0")
        self.grid, self.seed = float(grid), int(seed)

    def __call__(self, t: float) -> np.ndarray:
        return np.array(self.values(t))

    def values(self, t: float) -> list:
        """alpha(t) as a list of Python floats (the sampler's hot path)."""
        if self.kind == ALPHA_CONSTANT:
            return self._alpha_list
        if self.kind == ALPHA_COS2:
            c = math.cos(t)
            return [c * c, 1.0 - c * c]
        k = math.floor(t / self.grid + 1e-9)
        e = -np.log1p(-np.random.default_rng([self.seed, k & 0xFFFFFFFF, (k >> 32) & 0xFFFFFFFF]).random(self.Z))
        return (e / e.sum()).tolist()

    def rate_bound(self) -> np.ndarray | None:
        """v of 004 (11) (bounds on |alpha_l'|, l < Z), or None if alpha' is unbounded."""
        if self.kind == ALPHA_CONSTANT:
            return np.zeros(self.Z - 1)
        if self.kind == ALPHA_COS2:
            return np.ones(1)  # alpha_1' = -sin 2t
        return None


def exit_rate_bounds(vertices) -> np.ndarray:
    """lam_i = max_l(-pi_ii^(l)): bounds the exit rate of mode i for every alpha."""
    V = np.asarray(vertices, dtype=float)
    return np.max(-np.diagonal(V, axis1=1, axis2=2), axis=0)


# ---------------------------------------------------------------------------------------
# the exact PCG64 state as floats


def _words(x: int, n: int = 4) -> list:
    return [float((x >> (32 * k)) & 0xFFFFFFFF) for k in range(n)]


def _unwords(ws) -> int:
    return sum(int(w) << (32 * k) for k, w in enumerate(ws))


def pcg64_state_to_floats(bit_generator) -> list:
    """PCG64 state -> 10 floats (state and increment as 4 x 32 bits each, the cached 32-bit
    half): every float is an integer < 2^32, so the encoding is exact."""
    s = bit_generator.state
    return _words(s["state"]["state"]) + _words(s["state"]["inc"]) + [float(s["has_uint32"]), float(s["uinteger"])]


def pcg64_state_from_floats(bit_generator, values) -> None:
    v = list(values)
    bit_generator.state = {"bit_generator": "PCG64",
                           "state": {"state": _unwords(v[0:4]), "inc": _unwords(v[4:8])},
                           "has_uint32": int(v[8]), "uinteger": int(v[9])}


PCG64_FLOATS = 10


# ---------------------------------------------------------------------------------------
# the sampler


class MarkovChain:
    """One path of the chain, generated forward exactly by thinning (module docstring).

    Modes are 1-based in the interface (``mode``), 0-based inside. ``rate_bound`` > 0 replaces
    the per-mode bounds lam_i by one global bound (it must not be below any of them)."""

    def __init__(self, vertices, profile: AlphaProfile, r0: int, seed: int, t0: float = 0.0,
                 rate_bound: float = 0.0):
        self.V = check_vertices(vertices)
        self.Z, self.N = self.V.shape[0], self.V.shape[1]
        if profile.Z != self.Z:
            raise ValueError(f"alpha profile has {profile.Z} vertices, the rates {self.Z}")
        self.profile = profile
        lam = exit_rate_bounds(self.V)
        if rate_bound:
            if rate_bound < float(lam.max()) * (1.0 - 1e-12):
                raise ValueError(f"rate_bound = {rate_bound:g} 1/s is below the largest exit rate "
                                 f"{float(lam.max()):g} 1/s of the vertices: thinning would be inexact")
            lam = np.full(self.N, float(rate_bound))
        self.lam = lam
        # per mode r: [(j, [pi_rj^(l) / lam_r for l])] for j != r, Python floats for the hot loop
        self._rows = [[(j, [float(self.V[l, r, j]) / float(lam[r]) if lam[r] > 0 else 0.0 for l in range(self.Z)])
                       for j in range(self.N) if j != r] for r in range(self.N)]
        self.restart(seed, r0, t0)

    def restart(self, seed: int, r0: int, t0: float = 0.0) -> None:
        """A new path (same rates and profile) from mode r0 at t0 with a new seed: the same as
        constructing a new chain, without checking the rates again (Monte Carlo loops)."""
        if int(seed) != seed or seed < 0:
            raise ValueError(f"seed = {seed}: must be a non-negative integer")
        if not 1 <= int(r0) <= self.N or int(r0) != r0:
            raise ValueError(f"r0 = {r0}: the initial mode must be an integer in 1..{self.N}")
        self._bg = np.random.PCG64(int(seed))
        self._rng = np.random.Generator(self._bg)
        self.r = int(r0) - 1
        self.n_jumps = 0
        self.t_last = float(t0)
        self.t_next, self.r_next = T_NEVER, self.r
        self._draw_next(float(t0))

    def generator(self, t: float) -> np.ndarray:
        """Pi(t) = sum_l alpha_l(t) Pi^(l)."""
        return np.tensordot(self.profile(t), self.V, axes=1)

    def _draw_next(self, t: float) -> None:
        """From time t in mode r: the next real jump (time and target), by thinning."""
        r, lam = self.r, float(self.lam[self.r])
        if lam <= 0.0:  # absorbing in every vertex
            self.t_next, self.r_next = T_NEVER, r
            return
        rnd = self._rng.random
        alpha, row = self.profile.values, self._rows[r]
        log1p = math.log1p
        while True:
            t += -log1p(-rnd()) / lam
            u = rnd()
            if t >= T_NEVER:
                self.t_next, self.r_next = T_NEVER, r
                return
            a = alpha(t)
            c = 0.0
            for j, w in row:  # j ascending; c accumulates pi_rj(t) / lam_r
                for al, wl in zip(a, w):
                    c += al * wl
                if u < c:
                    self.t_next, self.r_next = t, j
                    return

    def advance_to(self, t: float) -> None:
        """Take every jump that has happened at time t (``happened_at``)."""
        while self.t_next < T_NEVER and happened_at(self.t_next, t):
            self.t_last = self.t_next
            self.r = self.r_next
            self.n_jumps += 1
            self._draw_next(self.t_last)

    @property
    def mode(self) -> int:
        return self.r + 1

    # state ----------------------------------------------------------------------------
    def get_state(self) -> list:
        return [float(self.r), self.t_next, float(self.r_next), float(self.n_jumps), self.t_last] + \
            pcg64_state_to_floats(self._bg)

    def set_state(self, state) -> None:
        s = list(state)
        self.r, self.t_next, self.r_next = int(s[0]), float(s[1]), int(s[2])
        self.n_jumps, self.t_last = int(s[3]), float(s[4])
        pcg64_state_from_floats(self._bg, s[5 : 5 + PCG64_FLOATS])


def sample_path(vertices, profile: AlphaProfile, r0: int, seed: int, t_end: float, t0: float = 0.0):
    """Jump times and modes of one path on [t0, t_end]: (times, modes) with times[0] = t0,
    modes[k] holding on [times[k], times[k+1]) (1-based modes)."""
    ch = MarkovChain(vertices, profile, r0, seed, t0)
    times, modes = [float(t0)], [ch.mode]
    while ch.t_next <= t_end:
        ch.advance_to(ch.t_next)
        times.append(ch.t_last)
        modes.append(ch.mode)
    return np.array(times), np.array(modes)


# ---------------------------------------------------------------------------------------
# the block


class MarkovModeSource(Block):
    """Mode source: a Markov chain with polytopic time-varying rates, 004 (9)-(13), (52)-(53).

    Inputs:  none
    Outputs: mode (1, 1..N as a Real: consumers use round()), t_next_jump (s, announced instant:
             the time of the next jump, ``T_NEVER`` = 1e300 if none), t_last_jump (s),
             n_jumps (1), alpha[1..Z] (1), exit_rate (1/s, -pi_rr(t) of the current mode)
    Parameters: Pi[l,i,j] (1/s, vertex l of the rates; default 0: no jumps), alpha_profile
             (0 constant, 1 004 (52), 2 random piecewise constant), alpha_const[l], alpha_grid (s),
             alpha_seed, r0 (initial mode), seed (PCG64 seed of the path), rate_bound (1/s; 0:
             per-mode bounds from the vertices)
    State:   the chain (current and next mode, next jump time, jump count, PCG64 state).

    Timing: ``advance(t, h)`` takes every jump with ``happened_at(T, t + h)``, so at a
    communication point the output is the mode right after it. A jump strictly inside a step
    reaches consumers at the end of that step (at most one step late); a master that lands its
    steps on ``t_next_jump`` makes it exact (the block declares it in ``announced_instants``).
    """

    model_name = "MarkovModeSource"
    description = "Markov mode source with polytopic time-varying rates (exact thinning, seeded)"
    announced_instants = ("t_next_jump",)

    def __init__(self, n_modes: int = 3, n_vertices: int = 2):
        N, Z = self.N, self.Z = int(n_modes), int(n_vertices)
        outputs = (
            scalar("mode", 1, "1", "current mode r(t), 1..N")
            + scalar("t_next_jump", T_NEVER, "s", "announced instant: time of the next jump")
            + scalar("t_last_jump", 0.0, "s", "time of the last jump (start time before the first)")
            + scalar("n_jumps", 0, "1", "number of jumps so far")
            + vector("alpha", Z, "1", "polytope coordinates alpha_l(t), 004 (10)")
            + scalar("exit_rate", 0.0, "1/s", "-pi_rr(t) of the current mode")
        )
        params = (
            [Variable(f"Pi[{l + 1},{i + 1},{j + 1}]", "1/s", "transition rate, vertex l, from i to j")
             for l in range(Z) for i in range(N) for j in range(N)]
            + scalar("alpha_profile", ALPHA_CONSTANT, "1", "0 constant alpha, 1 004 (52) cos^2/sin^2, 2 random")
            + vector("alpha_const", Z, "1", "alpha for alpha_profile = 0", [1.0] + [0.0] * (Z - 1))
            + scalar("alpha_grid", 0.1, "s", "cell length of alpha_profile = 2")
            + scalar("alpha_seed", 0, "1", "seed of alpha_profile = 2")
            + scalar("r0", 1, "1", "initial mode r(t0)")
            + scalar("seed", 0, "1", "seed of the path (PCG64)")
            + scalar("rate_bound", 0.0, "1/s", "thinning bound (0: per-mode bounds from the vertices)")
        )
        super().__init__([], outputs, params, {})
        self.chain = None

    def _int(self, name, lo=None):
        x = self.p(name)
        if x != round(x) or (lo is not None and x < lo):
            raise ValueError(f"{self.model_name}: parameter '{name}' = {x:g} must be an integer"
                             + (f" >= {lo}" if lo is not None else ""))
        return int(round(x))

    def initialize(self, t0: float) -> None:
        try:
            V = check_vertices(self.p_array("Pi"), "Pi")
            prof = AlphaProfile(self._int("alpha_profile"), self.Z, self.p_vector("alpha_const"),
                                self.p("alpha_grid"), self._int("alpha_seed", 0))
            rb = self.p("rate_bound")
            if rb < 0:
                raise ValueError(f"rate_bound = {rb:g} 1/s must be >= 0")
            self.chain = MarkovChain(V, prof, self._int("r0", 1), self._int("seed", 0), t0, rb)
        except ValueError as e:
            raise ValueError(f"{self.model_name}: {e}") from None
        self.chain.advance_to(t0)

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        ch = self.chain
        a = ch.profile(t)
        rate = -float(a @ ch.V[:, ch.r, ch.r])
        return np.concatenate(([float(ch.mode), ch.t_next, ch.t_last, float(ch.n_jumps)], a, [rate]))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        self.chain.advance_to(t + h)

    def get_state(self) -> list:
        return self.chain.get_state()

    def set_state(self, state) -> None:
        self.chain.set_state(state)
