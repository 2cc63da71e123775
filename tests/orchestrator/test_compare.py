"""`ftcsim compare`: a user's controller FMU (here the C FMU of tests/fmus/third_party, a PD law
with the fault estimate fed forward) against PD, AISMC and FASMC on the same draws of the shipped
campaign li2023_methods, as one more campaign variant, with the campaign report. Short: 2 draws
of 1 s, in this process (--workers 0)."""
from pathlib import Path

import pandas as pd
import pytest

import ftcsim
from orchestrator.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
pytestmark = [pytest.mark.fmu, pytest.mark.slow]
DISPERSED = ["plant.fault_scale", "plant.fault_onset", "plant.effectiveness_onset", "plant.J[1,1]", "plant.J[2,2]",
             "plant.J[3,3]", "plant.effectiveness[1]"]


def own_scenario(folder: Path, fmu: Path) -> Path:
    """docs/examples/own_controller.toml with the controller FMU given by its path."""
    text = (ROOT / "docs" / "examples" / "own_controller.toml").read_text()
    path = folder / "c_controller.toml"
    path.write_text(text.replace('fmu = "MinimalPD.fmu"', f'fmu = "{fmu.as_posix()}"'))
    return path


def test_compare_runs_the_controller_on_the_same_draws_as_the_shipped_methods(c_fmu, fmu_dir, tmp_path):
    """One comparison (its report costs most of the time), checked four ways."""
    scenario = own_scenario(tmp_path, c_fmu)
    out = tmp_path / "out"
    rc = main(["compare", str(c_fmu), "--scenario", str(scenario), "--out", str(out), "--runs", "2", "--stop", "1",
               "--workers", "0", "--quiet"])
    assert rc == 0
    df = pd.read_parquet(out / "summary.parquet")
    assert list(dict.fromkeys(df["variant"])) == ["pd", "aismc", "fasmc", "cattitudepd"]
    assert len(df) == 8 and (df["status"] == "ok").all(), df[["variant", "status", "error"]]

    # 1. the same draws: the dispersed values, read back from each variant's plant FMU after set-up
    for draw, rows in df.groupby("draw"):
        for col in DISPERSED:
            assert rows[col].nunique() == 1, (draw, col, rows[col].tolist())
    # ... and they are li2023_methods' own first two draws (draw k does not depend on the number of runs)
    from orchestrator.campaign.expand import draws
    from orchestrator.campaign.spec import load

    c = load(ROOT / "campaigns" / "li2023_methods.toml")
    for k in (0, 1):
        expected = draws(c, k, c.bases[0])
        got = df[(df["draw"] == k) & (df["variant"] == "cattitudepd")].iloc[0]
        for ref in ("plant.fault_scale", "plant.fault_onset", "plant.J[1,1]"):
            assert got[f"requested:{ref}"] == expected[ref], (k, ref)

    # 2. independent path: ftcsim.run of the user's scenario with the draw's values gives the metrics
    # that the campaign stored for the user's variant
    row = df[df["variant"] == "cattitudepd"].iloc[1]
    params = {col.removeprefix("requested:"): float(row[col]) for col in df.columns if col.startswith("requested:")}
    result = ftcsim.run(str(scenario), stop=1.0, parameters=params)
    for metric in ("final_attitude_error", "final_rate_error", "control_energy", "max_abs_u"):
        assert row[metric] == pytest.approx(result.metrics[metric], rel=1e-12, abs=1e-15), metric
    # the methods differ on the same draw: the comparison has something to show
    pd_row = df[(df["variant"] == "pd") & (df["draw"] == row["draw"])].iloc[0]
    assert abs(pd_row["control_energy"] - row["control_energy"]) > 1e-3 * row["control_energy"]

    # 3. the campaign report: the user's variant in the table, paired with the first variant, and the plots
    report = (out / "report" / "report.md").read_text()
    assert "| final_attitude_error | cattitudepd | 2/2 |" in report
    assert "| final_attitude_error | cattitudepd - pd | 2 |" in report
    assert (out / "report" / "metrics.png").stat().st_size > 10_000
    assert (out / "report" / "envelopes.png").stat().st_size > 10_000

    # 4. the folder keeps the derived campaign, with absolute paths: it replays a run by itself
    text = (out / "campaign.toml").read_text()
    assert 'name = "cattitudepd"' in text and f'"{scenario}"' in text


def test_a_controller_that_does_not_fit_the_scenario_is_one_clear_message(c_fmu, fmu_dir, tmp_path, capsys):
    """The default scenario is FASMC's, whose d2_hat input the PD law does not have."""
    rc = main(["compare", str(c_fmu), "--out", str(tmp_path / "out"), "--runs", "1", "--stop", "1", "--workers", "0"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    assert err[0] == ("ftcsim: error: command line: CONTROLLER: CAttitudePD.fmu in place of ctrl of li2023_fasmc: "
                      "CAttitudePD has no input 'd2_hat[1]', which scenario li2023_fasmc connects (give a scenario "
                      "that wires this controller with --scenario)"), err
    assert not (tmp_path / "out").exists()


def test_a_too_deeply_nested_base_campaign_is_one_error_naming_the_file(tmp_path):
    from orchestrator.campaign.compare import derive
    from orchestrator.common.errors import InputError

    base = tmp_path / "deep.toml"
    base.write_text("x = " + "[" * 5000 + "]" * 5000 + "\n", encoding="utf-8")
    with pytest.raises(InputError) as e:
        derive(base, tmp_path / "ctrl.fmu")
    assert str(base) in str(e.value) and "nested too deeply" in str(e.value)
