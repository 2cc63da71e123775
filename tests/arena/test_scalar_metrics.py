"""``[metrics]`` naming scalar outputs (the pitch-axis plants' ``ctrl.u``, ``plant.theta``): the run's
control metrics are those of the recorded column (issue 26: compute_metrics used to read no column)."""
import numpy as np
import pytest

import ftcsim
from tests.arena.test_scenarios import FOLDER


def test_pitch_axis_control_metrics_of_a_scalar_command(tmp_path):
    text = (FOLDER / "arena_hinf_on_hang2023.toml").read_text().replace("stop = 60.0", "stop = 2.0", 1)
    text += '\n[metrics]\ncontrol = "ctrl.u"\nattitude_error = "plant.theta"\nrate_error = "plant.theta_dot"\n'
    f = tmp_path / "pitch_metrics.toml"
    f.write_text(text)
    r = ftcsim.run(str(f), mode="inprocess")
    assert r.info["complete"], r.info.get("error")
    u = r.df["ctrl.u"].to_numpy()
    t = r.df.index.to_numpy()
    assert r.metrics["max_abs_u"] == pytest.approx(np.abs(u).max(), rel=1e-12) and r.metrics["max_abs_u"] > 0
    assert r.metrics["control_energy"] == pytest.approx(float(np.sum(u[:-1] ** 2 * np.diff(t))), rel=1e-12)
    assert r.metrics["final_attitude_error"] == pytest.approx(abs(r.df["plant.theta"].iloc[-1]), rel=1e-12)
    assert r.metrics["final_rate_error"] == pytest.approx(abs(r.df["plant.theta_dot"].iloc[-1]), rel=1e-12)
