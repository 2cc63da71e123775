"""Sampled-data fuzzy output feedback over a sensor network, with mode-dependent gains.

The law (004 (14), with (7)-(8)): for t in [t_k, t_{k+1}),

    u(t) = sum_j h_j(lambda(t_k)) K_{r j} M_s y(t_k),      M_s = I_qm^T (Theta (x) I_q) L,

y = x = [omega; q_v] (C_i = I), the premise lambda = x, r the fault mode (a Markov mode input).
The actuator then applies F_r u + G_r v (004 (9); ``plant/mode_faults.py``).

Sensor network (004 (7)-(8), before (16)): m nodes on a directed graph with weights Theta
(off-diagonal >= 0, rows summing to 0 by (7)) and output matrices L_l = l_l I_q (004 prints
L_l as scalars times I). Then M_s = sum_{l1,l2} theta_{l1 l2} L_{l2} = m_s I with the scalar

    m_s = sum_{l2} (sum_{l1} theta_{l1 l2}) l_{l2}     (column sums of Theta weighted by l).

With 004's printed Theta and L this is exactly 0 (0.4*0.8 - 0.1*0.5 - 0.3*0.9): the printed
law applies no feedback at all. ``network_mode`` = 0 uses the network as printed (m_s from
Theta and L; the output ``network_gain`` shows it), 1 bypasses it (M_s = I, the "one aggregated
sensor" reading under which the published gains have their size). The design refuses m_s = 0.

Sampling: aperiodic instants with bounded intervals tau_min <= t_{k+1} - t_k <= tau_max, on
a grid of ``sample_quantum`` seconds: tau_k = quantum * n_k with n_k uniform on the integers
of [tau_min, tau_max] / quantum (``sample_mode`` = 1) or n_k = floor(tau_max / quantum)
(``sample_mode`` = 0, periodic). n_k is drawn from ``numpy.random.default_rng([sample_seed, k])``:
the schedule is a pure function of (seed, k), and the state holds k and the instants as integer
multiples of the quantum (exact, no drift). t_0 = the start time.

Timing contract (announced instants): the output ``t_next_sample`` is the next sample instant,
always > t. At a communication point t that is a sample instant (``happened_at(t_next, t)``),
``outputs_at`` computes u from the inputs at t (direct feedthrough: y(t_k)); ``advance(t, h)``
then latches y(t_k) and h(lambda(t_k)) and moves to the next instant. Between instants u uses the
held values (zero-order hold). An instant strictly inside a communication step cannot be sampled
(the block sees its inputs only at communication points): ``advance`` raises ValueError naming
it. So the master must land on every instant: with the fixed-step master, a step dividing
``sample_quantum`` (and a start time on the quantum grid) does; a master that lands on announced
instants does for any step (``announced_instants``).

Mode: ``mode_sampling`` = 0 uses r(t) at every communication point (004 (14)/(16): K_{r(t) j},
so u changes inside a sampling interval when the mode jumps); 1 holds r(t_k).

Inputs:  omega[1..3] (rad/s), q[0..3] (1, q[1..3] used), mode (1)
Outputs: u[1..3] (N·m); t_k (s, instant of the sample in use); t_next_sample (s, announced
         instant); tau_k (s, current interval t_next - t_k); sample_count (1, samples taken);
         h[1..p] (held memberships); z[1..6] (held network output M_s y(t_k)); network_gain (1)
Parameters: K[r,j,a,b] (N·m per unit of y_b), Theta[l1,l2], L_gain[l], network_mode,
         sample_mode, tau_min, tau_max, sample_quantum (s), sample_seed, mode_sampling,
         memberships (``plant.fuzzy.triangular_parameters``)
"""
from __future__ import annotations

import math

import numpy as np

from plant.block import Block, Variable, matrix, scalar, vector
from plant.fuzzy import triangular_from_parameters, triangular_parameters
from plant.timing import POINT_TOL, StepWindow, happened_at

NY, NU = 6, 3
NETWORK_AS_PRINTED, NETWORK_BYPASS = 0, 1
SAMPLE_PERIODIC, SAMPLE_UNIFORM = 0, 1


def check_network(Theta, name: str = "Theta") -> np.ndarray:
    """004 (7): off-diagonal theta >= 0 and theta_ii = -sum_{j != i} theta_ij (rows sum to 0)."""
    T = np.asarray(Theta, dtype=float)
    if T.ndim != 2 or T.shape[0] != T.shape[1]:
        raise ValueError(f"{name}: must be square, got shape {T.shape}")
    m = T.shape[0]
    for i in range(m):
        for j in range(m):
            if i != j and T[i, j] < 0:
                raise ValueError(f"{name}[{i + 1},{j + 1}] = {T[i, j]:g} < 0: edge weights must be >= 0 (004 (7))")
    tol = 1e-9 * (1.0 + float(np.abs(T).max()))
    for i in range(m):
        if abs(float(T[i].sum())) > tol:
            raise ValueError(f"{name}: row {i + 1} sums to {float(T[i].sum()):.6g}, but 004 (7) sets "
                             f"theta_ii = -sum_(j != i) theta_ij (rows sum to 0)")
    return T


def network_gain(Theta, L_gain) -> float:
    """m_s with I_qm^T (Theta (x) I_q) L = m_s I_q for L_l = l_l I_q (module docstring)."""
    T = np.asarray(Theta, dtype=float)
    ell = np.asarray(L_gain, dtype=float).ravel()
    if ell.size != T.shape[0]:
        raise ValueError(f"L_gain has {ell.size} entries for {T.shape[0]} sensor nodes")
    return float(T.sum(axis=0) @ ell)


def network_matrix(Theta, L_gain, q: int = NY) -> np.ndarray:
    """I_qm^T (Theta (x) I_q) L, built literally with Kronecker products (check of
    :func:`network_gain`)."""
    T = np.asarray(Theta, dtype=float)
    m = T.shape[0]
    Iqm = np.tile(np.eye(q), (m, 1))  # (qm, q): I_qm = [I_q; ...; I_q]
    L = np.vstack([l * np.eye(q) for l in np.ravel(L_gain)])  # (qm, q)
    return Iqm.T @ np.kron(T, np.eye(q)) @ L


class SampleSchedule:
    """Instants t_k = t0 + quantum * N_k, N_{k+1} = N_k + n_k (module docstring). Stateless:
    :meth:`ticks` of interval k is a pure function of (seed, k)."""

    def __init__(self, t0: float, quantum: float, tau_min: float, tau_max: float, seed: int, mode: int):
        if not quantum > 0:
            raise ValueError(f"sample_quantum = {quantum:g} s must be > 0")
        if not tau_max > 0:
            raise ValueError(f"tau_max = {tau_max:g} s must be > 0 (004: 0 < t_(k+1) - t_k <= tau_M)")
        if not tau_min > 0:
            raise ValueError(f"tau_min = {tau_min:g} s must be > 0 (004: 0 < t_(k+1) - t_k)")
        if tau_min > tau_max:
            raise ValueError(f"tau_min = {tau_min:g} s > tau_max = {tau_max:g} s: the sampling bounds are inverted")
        if mode not in (SAMPLE_PERIODIC, SAMPLE_UNIFORM):
            raise ValueError(f"sample_mode = {mode} unknown (0 periodic tau_max, 1 uniform on [tau_min, tau_max])")
        if seed < 0 or seed != int(seed):
            raise ValueError(f"sample_seed = {seed:g} must be a non-negative integer")
        self.n_min = math.ceil(tau_min / quantum - 1e-9)
        self.n_max = math.floor(tau_max / quantum + 1e-9)
        if self.n_min > self.n_max:
            raise ValueError(f"no multiple of sample_quantum = {quantum:g} s lies in [tau_min, tau_max] = "
                             f"[{tau_min:g}, {tau_max:g}] s")
        self.t0, self.q, self.seed, self.mode = float(t0), float(quantum), int(seed), int(mode)
        t0_ns, q_ns = round(t0 * 1e9), round(quantum * 1e9)
        self._ns = (q_ns > 0 and abs(quantum * 1e9 - q_ns) < 1e-6 and abs(t0 * 1e9 - t0_ns) < 1e-6)
        self._t0_ns, self._q_ns = t0_ns, q_ns

    def ticks(self, k: int) -> int:
        """n_k: length of interval k (from t_k to t_{k+1}) in quanta."""
        if self.mode == SAMPLE_PERIODIC or self.n_min == self.n_max:
            return self.n_max
        return int(np.random.default_rng([self.seed, int(k)]).integers(self.n_min, self.n_max, endpoint=True))

    def time(self, N: int) -> float:
        """t0 + N quanta; from integer nanoseconds when t0 and the quantum are whole ns (the
        same doubles as the master's grid, ``orchestrator.cosim.master.time_grid``)."""
        if self._ns and abs(self._t0_ns) + N * self._q_ns < 2**53:
            return (self._t0_ns + N * self._q_ns) / 1e9
        return self.t0 + N * self.q

    def instants(self, t_end: float) -> np.ndarray:
        """All instants t_0 .. <= t_end (for reports and tests)."""
        out, N, k = [], 0, 0
        while self.time(N) <= t_end + POINT_TOL * max(1.0, abs(t_end)):
            out.append(self.time(N))
            N += self.ticks(k)
            k += 1
        return np.array(out)


class SampledFuzzyFTC(Block):
    model_name = "SampledFuzzyFTC"
    description = "Sampled-data fuzzy output feedback over a sensor network, mode-dependent gains (004 (14))"
    announced_instants = ("t_next_sample",)

    def __init__(self, n_modes: int = 3, n_rules: int = 3, n_nodes: int = 3):
        N, p, m = self.N, self.p_rules, self.m_nodes = int(n_modes), int(n_rules), int(n_nodes)
        inputs = (vector("omega", 3, "rad/s", "measured body rate")
                  + vector("q", 4, "1", "measured attitude quaternion (q[1..3] used)", [1, 0, 0, 0], first=0)
                  + [Variable("mode", "1", "fault mode r(t), 1..N", 1.0)])
        outputs = (vector("u", NU, "N.m", "commanded torque")
                   + scalar("t_k", 0.0, "s", "instant of the sample in use")
                   + scalar("t_next_sample", 0.0, "s", "announced instant: the next sample instant")
                   + scalar("tau_k", 0.0, "s", "current sampling interval t_next - t_k")
                   + scalar("sample_count", 0, "1", "samples taken")
                   + vector("h", p, "1", "held memberships h_j(lambda(t_k))")
                   + vector("z", NY, "1", "held network output M_s y(t_k)")
                   + scalar("network_gain", 0.0, "1", "m_s in M_s = m_s I (0 with 004's printed network)"))
        params = (
            [Variable(f"K[{r + 1},{j + 1},{a + 1},{b + 1}]", "1", "gain K_rj (mode r, rule j), N.m per unit of y_b")
             for r in range(N) for j in range(p) for a in range(NU) for b in range(NY)]
            + matrix("Theta", np.zeros((m, m)), "1", "sensor-network weights, 004 (7)")
            + vector("L_gain", m, "1", "sensor output matrices L_l = L_gain[l] I", [1.0] * m)
            + scalar("network_mode", NETWORK_BYPASS, "1", "0: M_s from Theta and L (004 (14)); 1: bypass M_s = I")
            + scalar("sample_mode", SAMPLE_UNIFORM, "1", "0: periodic tau_max; 1: uniform on [tau_min, tau_max]")
            + scalar("tau_min", 0.05, "s", "smallest sampling interval (> 0)")
            + scalar("tau_max", 0.1, "s", "largest sampling interval tau_M")
            + scalar("sample_quantum", 0.001, "s", "sampling instants lie on this grid")
            + scalar("sample_seed", 0, "1", "seed of the sampling sequence")
            + scalar("mode_sampling", 0, "1", "0: gains follow r(t) (004 (16)); 1: r(t_k)")
            + triangular_parameters(p, NY)
        )
        u_feed = [v.name for v in inputs if v.name != "q[0]"]
        feed = {f"u[{a + 1}]": u_feed for a in range(NU)}
        for name in ("t_k", "t_next_sample", "tau_k", "sample_count"):
            feed[name] = []
        feed.update({f"h[{j + 1}]": [n for n in u_feed if n != "mode"] for j in range(p)})
        feed.update({f"z[{b + 1}]": [n for n in u_feed if n != "mode"] for b in range(NY)})
        feed = {k: v for k, v in feed.items() if v}
        super().__init__(inputs, outputs, params, feed)
        self._state_init()

    def _state_init(self):
        self.k, self.N_k, self.N_next = 0, 0, 0
        self.z = np.zeros(NY)
        self.h = np.zeros(self.p_rules)
        self.r_held = 0

    # -- set-up ---------------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        name = self.model_name
        try:
            Theta = check_network(self.p_matrix("Theta"))
            self.m_s = network_gain(Theta, self.p_vector("L_gain"))
            mode = int(round(self.p("network_mode")))
            if mode not in (NETWORK_AS_PRINTED, NETWORK_BYPASS):
                raise ValueError(f"network_mode = {mode} unknown (0 as printed, 1 bypass)")
            self.M = self.m_s if mode == NETWORK_AS_PRINTED else 1.0
            self.schedule = SampleSchedule(t0, self.p("sample_quantum"), self.p("tau_min"), self.p("tau_max"),
                                           self.p("sample_seed"), int(round(self.p("sample_mode"))))
            ms = self.p("mode_sampling")
            if ms not in (0.0, 1.0):
                raise ValueError(f"mode_sampling = {ms:g} unknown (0 r(t), 1 r(t_k))")
            self.hold_mode = ms == 1.0
        except ValueError as e:
            raise ValueError(f"{name}: {e}") from None
        self.K = self.p_array("K").reshape(self.N, self.p_rules, NU, NY)
        self._Kflat = self.K.reshape(self.N, self.p_rules, NU * NY)
        self.memb = triangular_from_parameters(self)
        self._state_init()

    # -- pieces -------------------------------------------------------------------------
    def _y(self, u):
        return np.concatenate((u[0:3], u[4:7]))

    def _mode(self, x: float) -> int:
        r = int(round(x))
        if not 1 <= r <= self.N or abs(x - r) > 1e-9:
            raise ValueError(f"{self.model_name}: input mode = {x:g} is not one of the modes 1..{self.N}")
        return r - 1

    def _command(self, r: int, h: np.ndarray, z: np.ndarray) -> np.ndarray:
        return (h @ self._Kflat[r]).reshape(NU, NY) @ z  # sum_j h_j K_rj z

    def _sample_now(self, t: float) -> bool:
        return happened_at(self.schedule.time(self.N_next), t)

    # -- the contract -------------------------------------------------------------------------
    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        sch = self.schedule
        if self._sample_now(t):  # a sample instant not yet latched: y(t_k) is the input now
            y = self._y(u)
            z, h = self.M * y, self.memb.weights(y)
            r = self._mode(u[7])
            N_k, N_next, count = self.N_next, self.N_next + sch.ticks(self.k), self.k + 1
        else:
            z, h = self.z, self.h
            r = self.r_held if self.hold_mode else self._mode(u[7])
            N_k, N_next, count = self.N_k, self.N_next, self.k
        t_k, t_next = sch.time(N_k), sch.time(N_next)
        cmd = self._command(r, h, z)
        return np.concatenate((cmd, [t_k, t_next, t_next - t_k, float(count)], h, z, [self.m_s]))

    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        sch = self.schedule
        t_next = sch.time(self.N_next)
        if t_next < t - POINT_TOL * max(1.0, abs(t)):
            raise ValueError(f"{self.model_name}: sample instant t = {t_next:.9g} s was skipped (the step "
                             f"starts at {t:.9g} s)")
        if self._sample_now(t):
            y = self._y(u)
            self.z, self.h = self.M * y, self.memb.weights(y)
            self.r_held = self._mode(u[7])
            self.N_k = self.N_next
            self.N_next += sch.ticks(self.k)
            self.k += 1
        t_next = sch.time(self.N_next)
        if StepWindow(t, h).contains(t_next):
            raise ValueError(f"{self.model_name}: sample instant t = {t_next:.9g} s lies inside the communication "
                             f"step ({t:.9g}, {t + h:.9g}) s: use a step that divides sample_quantum = "
                             f"{sch.q:g} s, or a master that lands on t_next_sample")

    def get_state(self) -> list:
        return [float(self.k), float(self.N_k), float(self.N_next), float(self.r_held)] + self.z.tolist() + self.h.tolist()

    def set_state(self, state) -> None:
        s = list(state)
        self.k, self.N_k, self.N_next, self.r_held = int(s[0]), int(s[1]), int(s[2]), int(s[3])
        self.z = np.array(s[4 : 4 + NY], dtype=float)
        self.h = np.array(s[4 + NY : 4 + NY + self.p_rules], dtype=float)
