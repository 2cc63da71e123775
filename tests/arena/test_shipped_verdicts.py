"""The shipped arena's verdicts of issue 33 on slices of it, through the command line as a user runs it:
FONTSM with realistic wheels is ``stopped`` (with its reason and time), counted as not flying and not
keeping its accuracy; 002's H-infinity law and 004's law under a bias read "outside the method's
claims" beside their measured result. (FASMC flying 000's craft over 000's mission with ideal hardware
and no fault: tests/arena/test_missions.py.)"""
import pytest

from orchestrator.api import read_table
from orchestrator.cli.main import main
from tests.arena.reduced import ROOT

SHIPPED = ROOT / "arena" / "ftc_arena.toml"


def _arena(tmp_path, *argv):
    out = tmp_path / "out"
    assert main(["arena", str(SHIPPED), "--out", str(out), "--workers", "0", "--quiet", "--draws", "1", *argv]) == 0
    return out, {n: read_table(out / "tables" / f"{n}.parquet") for n in ("runs", "outcomes", "summary", "accuracy")}


def test_fontsm_with_realistic_wheels_is_stopped_and_counted(tmp_path):
    out, t = _arena(tmp_path, "--only", "fontsm_on_zhang2019", "--faults", "none", "bias", "--stop", "4")
    runs = t["runs"]
    real = runs[runs["hardware"] == "realistic"]
    assert (real["outcome"] == "stopped").all() and len(real) == 2
    assert (real["stop_time"] < 1.0).all() and real["stop_reason"].str.contains("singular").all()
    assert (runs.loc[runs["hardware"] == "ideal", "outcome"] == "flies").all()
    row = t["summary"].set_index("hardware").loc["realistic", "zhang2019"]
    assert row.startswith("✘ 0/2") and "■2" in row
    acc = t["accuracy"].iloc[0]
    assert not bool(acc["keeps_accuracy"]) and acc["verdict"] == "does not (stopped in 2 of 2 runs)"
    page = (out / "leaderboard.html").read_text(encoding="utf-8")
    assert "do not: fontsm (stopped in 2/2)" in page


@pytest.mark.parametrize("cell", ["hinf_on_zhang2014", "sftc_on_xu2024"])
def test_a_bias_outside_the_papers_fault_model_reads_so(tmp_path, cell):
    out, t = _arena(tmp_path, "--only", cell, "--faults", "bias", "--hardware", "ideal", "--stop", "2")
    oc = t["outcomes"]
    assert len(oc) == 1 and oc.iloc[0]["claims"] == "outside the method's claims"
    assert oc.iloc[0]["runs"] == 1 and oc.iloc[0]["failed"] == 0  # measured all the same
    assert "(†" in t["summary"].iloc[0, 2] and t["summary"].iloc[0, 2].startswith("— 0/0")
    page = (out / "leaderboard.html").read_text(encoding="utf-8")
    assert "outside the method&#x27;s claims" in page
