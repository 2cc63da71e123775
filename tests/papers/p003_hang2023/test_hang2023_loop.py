"""003 section 4 in process (shipped scenarios, shortened; fault moved to 2 s so that both phases fit).

* Figs. 5-6: after the observer transient (window [1, 2] s, before the fault) max |d0 - d0_hat| is
  below 1 % of the peak |d0| of the window (the 60 s run: 1.65e-4 N.m against 0.246 N.m, 0.07 %);
* the fault is absorbed by the observer (why Figs. 9-10's ordering does not appear with the published
  L1): after the fault d0_hat tracks the lumped torque d0 + T_d - (1 - rho) u of 003 (3.3) to 1 % of
  the d0 peak while d0 - d0_hat jumps to (1 - rho) |u|;
* Figs. 7-8: (3.21) reduces the torque chattering of (3.10): RMS(du/dt) over [1, 3] s lower by > 100x
  (the 60 s runs: see papers/p003_hang2023/README.md);
* Figs. 11-12: without the observer the attitude is worse than with it (same law, same window).
"""
from pathlib import Path

import numpy as np
import pytest
from scenario_text import write

from orchestrator.cosim.runner import run_scenario
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.toml import load
from papers.p003_hang2023.metrics import chattering, metrics

SCEN = Path(__file__).resolve().parents[3] / "papers" / "p003_hang2023" / "scenarios"


def _short(tmp, name, stop, onset=2.0, extra=""):
    base = (SCEN / "hang2023_asmftc_f04.toml").read_text()
    write(tmp, base, "hang2023_asmftc_f04.toml")
    text = (SCEN / f"{name}.toml").read_text()
    if "extends" not in text:
        text = text.replace("stop = 60.0", f"stop = {stop}")
    text += f"\n[timing]\nstart = 0.0\nstop = {stop}\nstep = 0.0005\nexchange = \"ordered\"\n" if "extends" in text else ""
    path = write(tmp, text + extra, f"short_{name}.toml")
    sc = load(path, in_process=True)
    sc = with_overrides(sc, parameters={"plant.effectiveness_onset": onset})
    sc.metrics.update({"onset": onset, "settle": 0.5 if onset < 5 else 1.0, "chatter_window": [1.0, min(3.0, stop)]})
    res = run_scenario(sc)
    assert res.complete, res.error
    return res, sc.metrics, metrics(res, sc.metrics)


@pytest.fixture(scope="module")
def f04(tmp_path_factory):
    return _short(tmp_path_factory.mktemp("h3"), "hang2023_asmftc_f04", 4.0)


@pytest.mark.slow
def test_disturbance_estimate_after_the_transient(f04):
    res, cfg, m = f04
    t = res.time
    w = (t >= 1.0) & (t <= 2.0)
    d0, dh = res.column("plant.d_vib"), res.column("est.d0_hat")
    err, peak = np.abs(d0 - dh)[w].max(), np.abs(d0[w]).max()
    assert err < 0.01 * peak, (err, peak)
    assert peak > 0.1  # the vibration torque is not small


@pytest.mark.slow
def test_fault_is_absorbed_by_the_observer(f04):
    res, cfg, m = f04
    t = res.time
    w = t >= 2.5
    u, tau = res.column("ctrl.u"), res.column("plant.tau_applied")
    d0, td, dh = res.column("plant.d_vib"), res.column("plant.u_d"), res.column("est.d0_hat")
    lumped = d0 + td + (tau - u)  # d0 + d1 - (1 - rho) u
    assert np.abs(lumped - dh)[w].max() < 0.01 * np.abs(d0[w]).max()
    assert np.abs(d0 - dh)[w].max() > 0.5 * np.abs(0.6 * u[w]).max()
    assert m["estimation_error_lumped_max_post_fault"] < 0.01 * m["d0_peak_post_fault"]


@pytest.mark.slow
def test_smoothed_law_reduces_chattering(f04, tmp_path):
    res, cfg, m = f04
    sign, _, ms = _short(tmp_path, "hang2023_asmftc_sign_f04", 3.0)
    rms_smooth, _ = chattering(res.time, res.column("ctrl.u"), (1.0, 3.0))
    rms_sign, _ = chattering(sign.time, sign.column("ctrl.u"), (1.0, 3.0))
    assert rms_sign > 100 * rms_smooth, (rms_sign, rms_smooth)
    assert ms["max_abs_u"] > 3 * m["max_abs_u"]


@pytest.mark.slow
def test_without_observer_is_worse(f04, tmp_path):
    res, cfg, m = f04
    no, _, mn = _short(tmp_path, "hang2023_asmftc_noobs_f04", 4.0)
    t = res.time
    w = t >= 3.0
    # same law and initial state: the attitude error without d0_hat is larger
    assert np.abs(no.column("plant.theta")[w]).max() > np.abs(res.column("plant.theta")[w]).max()
