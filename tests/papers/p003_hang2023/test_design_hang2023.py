"""003 Theorem 1 (3.4) observer gain, and the `design` / `verify` CLI wiring for all designs.

Published L1 (signs as read, see papers/p003_hang2023/design.py): both error matrices
W_j + L1 B0 V_j are Hurwitz, every frozen blend is Hurwitz and (3.4) is feasible (a common
P1 exists): all checks hold. Its ultimate-bound figure alpha*beta is ~1000x worse than ours.
The recorded designed gain L1_DESIGNED (gains.py, used by scenario variants) passes the same checks.
"""
import argparse
import json

import numpy as np
import pytest

import lmi
from orchestrator.cli import design as design_commands
from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import write_json_atomic
from papers.p003_hang2023 import design as dh
from papers.p003_hang2023.gains import L1_DESIGNED
from tests.schema_check import check_design_file


@pytest.mark.design
@pytest.mark.slow
def test_design_and_verify(tmp_path):
    out = tmp_path / "h.json"
    r = dh.design()
    write_json_atomic(out, r)  # what `ftcsim design` writes
    L1 = r["gains"]["L1"]
    assert np.all(L1[:, 0] == 0.0)  # published structure [[0, *], [0, *]]
    assert r["verify"]["all_hold"]
    assert max(r["verify"]["abscissa"]) < -r["performance"]["alpha"] + 1e-6  # decay rate achieved
    assert r["performance"]["beta"] > 0
    data = json.loads(out.read_text())
    assert data["fmu_parameters"][dh.FMU_MODEL]["L1[2,2]"] == pytest.approx(L1[1, 1])
    pub = dh.verify(dh.L1_PUBLISHED)
    assert pub["all_hold"]
    assert r["performance"]["alpha"] * r["performance"]["beta"] > 100 * pub["best_alpha_beta_on_grid"]
    # the recorded gain is a gain of this design (same decay rate to 1 %), and it passes the checks
    rec = dh.verify(L1_DESIGNED, alphas=(1.0,))
    assert rec["all_hold"]
    np.testing.assert_allclose(rec["abscissa"], r["verify"]["abscissa"], rtol=1e-2)


def test_sign_reading_matters():
    # the opposite sign of the published gain makes the error system unstable
    assert not dh.verify(-dh.L1_PUBLISHED)["all_hold"]


@pytest.fixture
def cli():
    ap = argparse.ArgumentParser(prog="ftcsim")
    design_commands.register(ap.add_subparsers(dest="cmd"))

    def run(*argv):
        a = ap.parse_args(list(argv))
        return a.func(a)

    return run


@pytest.mark.design
@pytest.mark.slow
def test_cli_design_verify_roundtrip(cli, tmp_path, capsys):
    out = tmp_path / "h.json"
    assert cli("design", "hang2023-tsfdo", "--alpha", "0.8", "--out", str(out)) == 0
    check_design_file(out)  # the shipped design schema (orchestrator/schemas/design.schema.json)
    assert cli("verify", "hang2023-tsfdo", "--gains", str(out)) == 0
    assert cli("verify", "hang2023-tsfdo") == 0
    assert "all checks hold" in capsys.readouterr().out


def test_cli_failed_design_writes_nothing(cli, tmp_path, monkeypatch, capsys):
    # the CLI's failure path, without asserting that some LMI is infeasible
    def failing(**kw):
        raise lmi.LMIInfeasible("003 (3.4): infeasible for every decay rate tried", {})

    monkeypatch.setattr("papers.p003_hang2023.design.design", failing)
    out = tmp_path / "bad.json"
    assert cli("design", "hang2023-tsfdo", "--out", str(out)) == 1
    assert not out.exists() and "nothing written" in capsys.readouterr().out


def test_cli_bad_input(cli, tmp_path):
    with pytest.raises(InputError, match="unknown design"):
        cli("verify", "nope")
    with pytest.raises(InputError, match="gains file not found"):
        cli("verify", "li2023-observer", "--gains", str(tmp_path / "missing.json"))
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(InputError, match="not valid JSON"):
        cli("verify", "li2023-controller", "--gains", str(bad))
    bad.write_text(json.dumps({"design": "li2023-controller", "gains": {}}))
    with pytest.raises(InputError) as ei:
        cli("verify", "li2023-controller", "--gains", str(bad))
    assert ei.value.key == "gains.K_c" and ei.value.problem == "missing"
    bad.write_text(json.dumps({"gains": {"L1": [[1, 2, 3]]}}))
    with pytest.raises(InputError, match="shape"):
        cli("verify", "hang2023-tsfdo", "--gains", str(bad))
    bad.write_text(json.dumps({"design": "hang2023-tsfdo", "gains": {"L1": [[0, 1], [0, 1]]}}))
    with pytest.raises(InputError, match="not 'li2023-controller'"):
        cli("verify", "li2023-controller", "--gains", str(bad))
    with pytest.raises(InputError, match="does not apply"):
        cli("design", "hang2023-tsfdo", "--j", "0.5", "--out", str(tmp_path / "x.json"))
    with pytest.raises(InputError, match="omega-hat"):
        cli("design", "zhang2014-hinf", "--omega-hat", "1.5", "--out", str(tmp_path / "x.json"))
