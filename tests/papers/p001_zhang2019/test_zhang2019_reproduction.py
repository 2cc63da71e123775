"""001's acceptance of issue 21 on the shipped variants, and the mechanism of the effectiveness drift.

* ``command_pairing``: with a command that alternates sign every step (what sign(s) does at a fixed
  step) the literal sampled law (14) moves e_hat_2 away from e_2 = 0.6, the paired law towards it;
  with a constant command both are the same law (bit for bit).
* ``zhang2019_fontsm_accurate`` (40 s instead of 60 s; Table 1's window [30, 60] s cut to [30, 40] s):
  the three attitude accuracies within a factor 3 of Table 1, the torque-level fault estimate within
  10 % RMS.
* ``zhang2019_fontsm_paired`` (30 s, 2 s fractional memory instead of the full memory, to keep the
  test short; the observer does not see the memory): e_hat_2 ends between 0.6 and 1 and closer to 0.6.
"""
import numpy as np
import pytest

from orchestrator.cosim.runner import run_scenario
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.toml import load, read_document
from papers.p001_zhang2019 import blocks
from papers.p001_zhang2019.metrics import metrics
from papers.p001_zhang2019.reproduction import READINGS, TABLE1, rows
from papers.reproduction import NOT, PARTLY, REPRODUCED, VARIANT, VERDICTS, close
from tests.papers.flip import assert_every_check_can_fail


def _observer_on_alternating_command(pairing, steps, amplitude=40.0, lambda_1=50.0, alternate=True, h=1e-3):
    """Plant without disturbance, Delta J or bias, e_2 = 0.6 from t = 0, driven by u_c = +-amplitude on
    wheel 2; the observer sees the true omega and the command. Returns e_hat_2."""
    p, o = blocks.plant(), blocks.observer()
    zero = {f"{k}[{i}]": 0.0 for k in ("dJ_amp", "Td_amp", "omega_init", "sigma_init") for i in (1, 2, 3)}
    p.set_parameters(zero | {f"effectiveness_onset[{j}]": 0.0 for j in range(1, 5)} | {f"bias[{j}]": 0.0 for j in range(1, 5)})
    o.set_parameters({"lambda_1": lambda_1, "command_pairing": pairing} | {f"omega_hat_init[{i}]": 0.0 for i in (1, 2, 3)})
    p.initialize(0.0)
    o.initialize(0.0)
    for k in range(steps):
        uc = np.array([0.0, amplitude * ((-1) ** k if alternate else 1.0), 0.0, 0.0])
        oin = np.concatenate([p.x[3:6], uc])
        p.advance(k * h, h, uc)
        o.advance(k * h, h, oin)
    return float(o.x[4])


def test_literal_pairing_drifts_away_paired_moves_towards_e2():
    literal = _observer_on_alternating_command(0, 3000)
    paired = _observer_on_alternating_command(1, 3000)
    assert literal > 1.05  # away from e_2 = 0.6 (measured 1.2 after 3 s)
    assert 0.6 < paired < 0.95  # towards it (measured 0.87)
    # a constant command: the innovation and the command that produced it carry the same U
    assert _observer_on_alternating_command(0, 500, alternate=False) == _observer_on_alternating_command(1, 500, alternate=False)


def _run(scenarios, name, stop, ctrl=None):
    s = load(scenarios / f"{name}.toml", in_process=True)
    s = with_overrides(s, stop=stop, parameters={"ctrl": dict(ctrl or {})})
    r = run_scenario(s)
    assert r.complete, r.error
    cfg = dict(read_document(scenarios / f"{name}.toml").get("metrics", {}))
    return r, cfg


@pytest.mark.slow
def test_accurate_variant_reaches_table1_attitude_and_estimates_the_fault_torque(scenarios):
    r, cfg = _run(scenarios, "zhang2019_fontsm_accurate", 40.0)
    cfg["accuracy_window"] = cfg["estimate_window"] = [30.0, 40.0]
    m = metrics(r, cfg)
    for ours, paper in zip(m["attitude_accuracy_deg"], TABLE1["attitude"]):
        assert paper / 3 <= ours <= 3 * paper, (ours, paper)
    assert m["fault_torque_estimate_rms_error_ratio"] <= 0.10
    table = rows({"zhang2019_fontsm_accurate": (r, cfg, m)})
    assert_every_check_can_fail(table)
    col = [row for row in table if row.item.startswith("Table 1 (FTC in this paper): attitude accuracy")]
    assert len(col) == 4 and sum(row.ours is not None for row in col) == 1  # one reading per column: one run, six entries
    (ours,) = [row for row in col if row.ours is not None]
    assert ours.reading == READINGS["zhang2019_fontsm_accurate"][0] and ours.kind == VARIANT and len(ours.ours) == 6
    # the six entries of one run: its verdict is the worst entry's (no per-axis best-of), a variant's success partly
    worst = max((close().verdict(p, o) for p, o in zip(ours.paper, ours.ours)), key=VERDICTS.index)
    assert ours.rule_verdict == worst and ours.verdict in (PARTLY, NOT)
    fe = next(row for row in table if row.item == "Fig. 5: fault estimate, torque level" and row.ours is not None)
    assert fe.rule_verdict == REPRODUCED and fe.verdict == PARTLY  # reproduced only under chosen gains: partly


@pytest.mark.slow
def test_paired_observer_moves_e_hat_2_towards_e_2_in_the_printed_loop(scenarios):
    r, _ = _run(scenarios, "zhang2019_fontsm_paired", 30.0, {"fo_memory": 2.0})
    e2 = r.vector("est.e_hat")[:, 1]
    assert 0.6 < e2[-1] < 1.0
    assert abs(e2[-1] - 0.6) < abs(e2[0] - 0.6)
