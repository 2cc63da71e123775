"""``ftcsim report``: figures and the table from result folders."""
import json

import numpy as np
import pytest
from scenario_text import write

from orchestrator.cli.main import main
from orchestrator.results.files import metrics_and_info, read_results


@pytest.fixture(scope="module")
def runs(tmp_path_factory, scenarios):
    tmp = tmp_path_factory.mktemp("report")
    folders = []
    for name in ("li2023_fasmc", "li2023_aismc"):
        text = (scenarios / f"{name}.toml").read_text().replace("stop = 200.0", "stop = 60.0")
        text = text.replace("fault_window = [50.0, 200.0]", "fault_window = [50.0, 60.0]")
        path = write(tmp, text, f"{name}.toml")
        out = tmp / name
        assert main(["run", str(path), "--out", str(out), "--mode", "inprocess", "--quiet", "--no-plots"]) == 0
        folders.append(out)
    return tmp, folders


def test_report_figures_and_table(runs, capsys):
    tmp, folders = runs
    out = tmp / "report"
    assert main(["report", *map(str, folders), "--out", str(out)]) == 0
    rep = json.loads((out / "report.json").read_text())
    for name in ("fig4_modes.png", "fig5_vibration_torque.png", "fig6_omega_estimate.png",
                 "fig7_8_faults_li2023_fasmc.png", "fig10_rate_errors.png", "fig11_attitude_errors.png",
                 "fig12d_energy.png", "fig9_control.png", "fig12abc_control.png"):
        assert name in rep["figures"] and (out / name).stat().st_size > 20000
    # the table repeats each run's metrics, and E agrees with the recorded torque
    for folder in folders:
        m = metrics_and_info(folder)
        row = rep["runs"][m["scenario"]]
        assert row["control_energy"] == m["control_energy"]
        header, data = read_results(folder)
        u = data[:, [header.index(f"ctrl.u[{i}]") for i in (1, 2, 3)]]
        assert np.isclose(m["control_energy"], (u[:-1] ** 2).sum() * 0.01)
    assert "| li2023_fasmc |" in (out / "report.md").read_text()


def test_report_rejects_a_folder_that_is_not_a_run(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    rc = main(["report", str(tmp_path / "empty"), "--out", str(tmp_path / "rep")])
    err = capsys.readouterr().err
    assert rc == 2 and "results.parquet: missing" in err
    assert not (tmp_path / "rep").exists()
