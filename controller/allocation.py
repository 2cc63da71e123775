"""Torque allocation between a 3-axis command and N wheels, and back (issue 26 item 1).

A 3-axis method (000's FASMC/AISMC/PD, 004's sampled fuzzy FTC) commands a body torque u; 001's
plant takes N wheel torques u_c with body torque M u_c (001 (3), M the 3 x N distribution
matrix). The other way round, 001's FONTSM commands wheel torques, and the 000/004 plants take a
body torque.

:func:`allocation_matrix` is the weighted pseudo-inverse with dropped wheels,

    u_c = W^-1/2 (M_a W^-1/2)^+ u,      W = diag(w_j),  M_a = M with the dropped wheels' columns zeroed,

the minimum of sum_j w_j u_c,j^2 over the commands that give M_a u_c = u (rank M_a = 3), and the
least-squares best effort min ||M_a u_c - u|| otherwise (fewer than three independent wheels
left). With w = 1 and no wheel dropped it is the Moore-Penrose inverse M^+ = M^T (M M^T)^-1. It
is tested against ``numpy.linalg.lstsq`` (tests/controller/test_allocation.py).

:class:`TorqueAllocation` drops wheel j (column j of M zeroed, u_c,j = 0)

* from ``failed_onset`` on if ``failed_wheel`` = j (a reconfiguration that knows the failed
  wheel: ideal fault isolation, selectable per scenario/draw), and/or
* while the estimate e_hat_j (input, e.g. ASMFEO's) is below ``e_drop`` (0: never), and/or
* while the input ``isolated`` names it (issue 34: the wheel a fault isolation names,
  ``diagnosis/isolation.py``, at the communication point it names it; 0 names none). The input is
  read as a wheel number: rounded to the nearest integer; a value outside 0..N (or not finite) is
  an error naming it (an FMI error status), never a silent guess.

Allocation matrices are computed once per set of dropped wheels (an SVD when the set changes),
so a step costs one 3 x N product.

:class:`WheelsToBody` maps wheel torques to the body: tau = M u_wheel, and per-wheel faults
(the fault catalog's additive equivalent u_f - u_c, ``plant/fault_catalog.py``) to the body fault
torque M (u_f - u_c), the ground truth a body-level fault estimator is compared with.

Timing: the failed wheel is dropped at a communication point t once ``happened_at(failed_onset,
t)`` (plant/timing.py); both blocks are static.
"""
from __future__ import annotations

import math

import numpy as np

from plant.block import StatelessBlock, matrix, scalar, vector
from plant.rigid_wheels import check_distribution, default_distribution, wheel_count
from plant.timing import happened_at

__all__ = ["allocation_matrix", "TorqueAllocation", "WheelsToBody"]


def allocation_matrix(M, weights=None, dropped=()) -> np.ndarray:
    """The N x 3 matrix A with u_c = A u: the weighted pseudo-inverse of M without the wheels in
    ``dropped`` (0-based), module docstring. ``weights`` (N,) > 0, default 1."""
    M = np.asarray(M, dtype=float)
    n = M.shape[1]
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
    if w.shape != (n,) or not np.all(w > 0):
        raise ValueError(f"weights: {n} values > 0 expected, got {np.ravel(w).tolist()}")
    s = 1.0 / np.sqrt(w)  # W^-1/2
    keep = [j for j in range(n) if j not in set(dropped)]
    A = np.zeros((n, 3))
    if keep:  # the pseudo-inverse of M_a W^-1/2 has zero rows for the zero columns: formed on the others
        A[keep] = s[keep, None] * np.linalg.pinv(M[:, keep] * s[keep])
    return A


class TorqueAllocation(StatelessBlock):
    """Body torque command u (3) -> wheel commands u_c (N): weighted pseudo-inverse, dropping a
    failed wheel (module docstring).

    Inputs:  u[1..3] N.m (body torque command); e_hat[1..N] 1 (wheel effectiveness estimate, start 1);
             isolated 1 (wheel named by a fault isolation, 0 none)
    Outputs: u_c[1..N] N.m (wheel torque commands); tau_alloc[1..3] N.m (M u_c: the body torque
             the wheels give if healthy; equals u while three independent wheels remain);
             n_active (1, wheels in the allocation)
    Parameters: M[3,N] (1), w[1..N] (1, weights of sum w_j u_c,j^2), failed_wheel (1, 0 none),
             failed_onset (s), e_drop (1, drop wheel j while e_hat_j < e_drop; 0 never)
    """

    model_name = "TorqueAllocation"
    description = "Torque allocation 3 axes -> N wheels: weighted pseudo-inverse, a failed wheel dropped"

    def __init__(self, n_wheels: int = 4):
        n = self.n = wheel_count(n_wheels)
        inputs = (vector("u", 3, "N.m", "body torque command")
                  + vector("e_hat", n, "1", "wheel effectiveness estimate (1: healthy)", [1.0] * n)
                  + scalar("isolated", 0.0, "1", f"wheel named by a fault isolation, dropped while named (1..{n}; 0 none)"))
        outputs = (vector("u_c", n, "N.m", "wheel torque commands")
                   + vector("tau_alloc", 3, "N.m", "body torque M u_c of healthy wheels")
                   + scalar("n_active", n, "1", "wheels used by the allocation"))
        params = (matrix("M", default_distribution(n), "1", "wheel distribution matrix (column j: spin axis of wheel j)")
                  + vector("w", n, "1", "allocation weights w_j > 0 (minimise sum w_j u_c,j^2)", [1.0] * n)
                  + scalar("failed_wheel", 0, "1", "wheel dropped from failed_onset on (1..N; 0 none)")
                  + scalar("failed_onset", 0.0, "s", "time from which failed_wheel is dropped")
                  + scalar("e_drop", 0.0, "1", "drop wheel j while e_hat_j < e_drop (0: never)"))
        every = [v.name for v in inputs]
        feed = {v.name: every for v in outputs if v.name != "n_active"}
        feed["n_active"] = [f"e_hat[{j + 1}]" for j in range(n)] + ["isolated"]
        super().__init__(inputs, outputs, params, feed)
        self._cache: dict = {}

    def initialize(self, t0: float) -> None:
        n = self.n
        M = self.p_matrix("M")
        check_distribution(M, "M")
        w = self.p_vector("w")
        if not np.all(w > 0):
            raise ValueError(f"{self.model_name}: weights w must be > 0, got {w.tolist()}")
        fw = self.p("failed_wheel")
        if fw != round(fw) or not 0 <= fw <= n:
            raise ValueError(f"{self.model_name}: failed_wheel = {fw:g} must be 0 (none) or a wheel 1..{n}")
        self.M, self.w = M, w
        self.failed = int(round(fw)) - 1  # -1: none
        self.onset = self.p("failed_onset")
        self.e_drop = self.p("e_drop")
        self._cache = {}

    def dropped(self, t: float, e_hat, isolated: float = 0.0) -> tuple:
        """0-based wheels left out at time t for the estimates e_hat and the isolated wheel."""
        out = [j for j in range(self.n) if e_hat[j] < self.e_drop] if self.e_drop > 0 else []
        if self.failed >= 0 and self.failed not in out and happened_at(self.onset, t):
            out.append(self.failed)
        j = self.isolated_wheel(isolated)
        if j >= 0 and j not in out:
            out.append(j)
        return tuple(sorted(out))

    def isolated_wheel(self, x: float) -> int:
        """The 0-based wheel the input ``isolated`` names (-1: none); a value outside 0..N is an error."""
        if not (math.isfinite(x) and -0.5 < x < self.n + 0.5):
            raise ValueError(f"{self.model_name}: input isolated = {x:g} names no wheel (0 none, 1..{self.n})")
        return int(round(x)) - 1

    def matrix_for(self, dropped: tuple) -> np.ndarray:
        A = self._cache.get(dropped)
        if A is None:
            A = self._cache[dropped] = allocation_matrix(self.M, self.w, dropped)
        return A

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        n = self.n
        drop = self.dropped(t, u[3:3 + n], float(u[3 + n]))
        uc = self.matrix_for(drop) @ u[0:3]
        return np.concatenate((uc, self.M @ uc, (float(n - len(drop)),)))


class WheelsToBody(StatelessBlock):
    """Wheel torques (N) -> body torque tau = M u_wheel and body fault torque M fault.

    Inputs:  u_wheel[1..N] N.m (torques the wheels deliver); fault[1..N] N.m (their additive fault
             equivalent u_f - u_c, e.g. the fault catalog's ``fault``; 0 if unconnected)
    Outputs: tau[1..3] N.m (to a body-torque plant); fault_torque[1..3] N.m (ground truth of a
             body-level fault estimate)
    Parameters: M[3,N] (1)
    """

    model_name = "WheelsToBody"
    description = "Wheel torques -> body torque M u and per-wheel faults -> body fault torque M f"

    def __init__(self, n_wheels: int = 4):
        n = self.n = wheel_count(n_wheels)
        inputs = (vector("u_wheel", n, "N.m", "wheel torques delivered")
                  + vector("fault", n, "N.m", "per-wheel additive fault equivalent"))
        outputs = (vector("tau", 3, "N.m", "body torque M u_wheel")
                   + vector("fault_torque", 3, "N.m", "body fault torque M fault"))
        params = matrix("M", default_distribution(n), "1", "wheel distribution matrix (column j: spin axis of wheel j)")
        feed = {f"tau[{i}]": [f"u_wheel[{j + 1}]" for j in range(n)] for i in (1, 2, 3)}
        feed.update({f"fault_torque[{i}]": [f"fault[{j + 1}]" for j in range(n)] for i in (1, 2, 3)})
        super().__init__(inputs, outputs, params, feed)

    def initialize(self, t0: float) -> None:
        M = self.p_matrix("M")
        check_distribution(M, "M")
        self.M = M

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        n = self.n
        return np.concatenate((self.M @ u[0:n], self.M @ u[n:2 * n]))
