"""Paper 001's metrics (definitions checked on synthetic data and against an independent
computation on a run), report (figures and Table 1 from result folders) and descriptor."""
import json

import numpy as np
import pytest
from zhang2019_runs import run

from orchestrator.common.outputs import OutputFolder
from orchestrator.cosim.master import RunResult
from orchestrator.results.files import write_results
from papers.p001_zhang2019.metrics import metrics, stabilization_time


def test_stabilization_time_definition():
    t = np.arange(0, 10.0001, 0.5)
    err = np.where(t < 3.0, 1.0, 1e-3)
    err[12] = 0.5  # a late excursion at 6 s
    assert stabilization_time(t, err, 0.01) == 6.5
    assert stabilization_time(t, err, 0.01, t_from=7.0) == 7.0
    assert stabilization_time(t, err, 1e-4) is None
    assert stabilization_time(t, np.zeros_like(t), 1e-4) == 0.0


def test_metrics_on_a_run_are_json_safe_and_match_an_independent_computation():
    s, r = run("zhang2019_fontsm", stop=3.0)
    cfg = dict(s.metrics, accuracy_window=[2.5, 3.0], estimate_window=[10.0, 20.0])  # empty estimate window
    m = metrics(r, cfg)
    json.dumps(m, allow_nan=False)
    w = (r.time >= 2.5) & (r.time <= 3.0)
    sig = np.degrees(np.abs(r.vector("plant.sigma")[w]))
    assert m["attitude_accuracy_deg"] == sig.max(axis=0).tolist()
    assert m["rate_accuracy_deg_s"] == np.degrees(np.abs(r.vector("plant.omega")[w])).max(axis=0).tolist()
    assert m["fault_torque_rms"] is None and m["fault_torque_estimate_rms_error_ratio"] is None
    assert 2.0 < m["stabilization_time_s"]["0.01"] < 3.0
    assert m["stabilization_time_s"]["3e-06"] is None


def test_metrics_of_an_incomplete_run():
    r = RunResult(["plant.sigma[1]", "plant.sigma[2]", "plant.sigma[3]"], np.zeros(0), np.zeros((0, 3)), False, "x")
    assert metrics(r, {"euler": "plant.sigma"}) == {"complete": False, "t_end": None}


@pytest.mark.slow
def test_report_draws_figures_and_table_1_from_result_folders(tmp_path):
    folders = []
    for name in ("zhang2019_fontsm", "zhang2019_passive"):
        s, r = run(name, stop=3.0)
        write_results(OutputFolder(tmp_path / name, "run").check(), r, s, plots=False)
        folders.append(tmp_path / name)
    from papers.p001_zhang2019.report import make_report

    rep = make_report(folders, tmp_path / "report")
    md = (tmp_path / "report" / "report.md").read_text()
    assert "| attitude accuracy nu [deg] | 0.412 | 2.6e-06 |" in md  # 001's Table 1 verbatim
    assert "NOT 001's ref. [21]" in md
    for f in rep["figures"]:
        assert (tmp_path / "report" / f).stat().st_size > 10_000
    assert {"fig5_zhang2019_fontsm.png", "fig6_8_zhang2019_fontsm.png", "fig2_4_zhang2019_passive.png"} <= set(rep["figures"])
    assert rep["ours"]["zhang2019_fontsm"]["attitude"] is None  # window [30, 60] s is past a 3 s run
    json.loads((tmp_path / "report" / "report.json").read_text())


def test_paper_descriptor_is_consistent_with_the_catalog_and_scenarios():
    from papers.paper import resolve
    from papers.registry import PAPER_MODULES, folder
    from papers.registry import fmu_specs as catalog

    assert "papers.p001_zhang2019.paper" in PAPER_MODULES
    p = resolve("papers.p001_zhang2019.paper:PAPER")
    for spec in p.fmus:
        assert catalog()[spec.model].factory == spec.factory
        assert resolve(spec.factory)().model_name == spec.model
    names = [f.stem for f in (folder(p) / "scenarios").glob("*.toml")]
    assert set(p.demo) <= set(names) and all(n.startswith(p.key) for n in names)
