"""Malformed arena files and arguments of ``ftcsim arena``: one message naming the file and the key,
exit status 2, nothing written."""
import pytest

from orchestrator.cli.main import main
from tests.arena.reduced import ARENA, write

CASES = {
    "top-level typo": ({"[arena]": "[arenna]\n[arena]"}, "arenna", "unknown key"),
    "arena key typo": ({"draws = 2": "drawz = 2"}, "arena.drawz", "did you mean 'draws'"),
    "zero draws": ({"draws = 2": "draws = 0"}, "arena.draws", "must be in 1"),
    "draws not whole": ({"draws = 2": "draws = 2.5"}, "arena.draws", "expected a whole number"),
    "negative seed": ({"seed = 7": "seed = -1"}, "arena.seed", "must be >= 0"),
    "unknown mode": ({'mode = "inprocess"': 'mode = "cloud"'}, "arena.mode", "unknown mode 'cloud'"),
    "unknown hardware": ({'hardware = ["ideal", "realistic"]': 'hardware = ["ideal", "perfect"]'}, "arena.hardware[1]",
                         "unknown 'perfect'"),
    "unknown fault class": ({'faults = ["none", "bias"]': 'faults = ["none", "loe"]'}, "arena.faults[1]",
                            "unknown 'loe'"),
    "fault class twice": ({'faults = ["none", "bias"]': 'faults = ["bias", "bias"]'}, "arena.faults",
                          "twice"),
    "NaN stop": ({"stop = 6.0": "stop = nan"}, "arena.stop", "expected a finite number"),
    "negative stop": ({"stop = 6.0": "stop = -6.0"}, "arena.stop", "must be > 0"),
    "loss above 1": ({"loss = [0.3, 0.7]": "loss = [0.3, 1.7]"}, "dispersions.loss", "must lie in [0.0, 1.0]"),
    "range reversed": ({"onset = [1.0, 3.0]": "onset = [3.0, 1.0]"}, "dispersions.onset", "high 1.0 < low 3.0"),
    "range not a pair": ({"onset = [1.0, 3.0]": "onset = 2.0"}, "dispersions.onset", "expected [low, high]"),
    "missing band": ({"band = 0.02\n": ""}, "plants.hang2023.band", "missing"),
    "unknown wheels": ({'wheels = "wheels_hr12_12"': 'wheels = "wheels_hr12_13"'}, "plants.hang2023.wheels",
                       "unknown parameter set 'wheels_hr12_13' (did you mean 'wheels_hr12_12'?)"),
    "realistic without gyro": ({'gyro = "gyro_stim300"\nattitude_sensor = "angle_small"': 'attitude_sensor = "angle_small"'},
                               "plants.hang2023.gyro", "missing (realistic hardware is flown)"),
    "missing mission": ({"mission = 60.0\nband = 0.02": "band = 0.02"}, "plants.hang2023.mission", "missing"),
    "zero mission": ({"mission = 60.0\nband = 0.02": "mission = 0.0\nband = 0.02"}, "plants.hang2023.mission",
                     "must be > 0"),
    "missing claims": ({'paper = "002"\nclaims = ["loe_step"]': 'paper = "002"'}, "methods.hinf.claims", "missing"),
    "unknown claim": ({'claims = ["loe_step"]': 'claims = ["loe_stp"]'}, "methods.hinf.claims[0]", "unknown 'loe_stp'"),
    "claims not a list": ({'claims = ["loe_step"]': 'claims = "loe_step"'}, "methods.hinf.claims", "expected a list"),
    "settle_from is gone": ({"mission = 60.0\nband = 0.02": "mission = 60.0\nsettle_from = 1.0\nband = 0.02"},
                            "plants.hang2023.settle_from", "unknown key"),
    "persistence negative": ({"persistence = 0.2": "persistence = -0.2"}, "detection.persistence", "must be >= 0"),
    "false-alarm target zero": ({"false_alarms_per_hour = 10.0": "false_alarms_per_hour = 0.0"},
                                "detection.false_alarms_per_hour", "must be > 0"),
    "confidence above 1": ({"bootstrap = 200": "bootstrap = 200\nconfidence = 1.5"}, "statistics.confidence",
                           "strictly between 0 and 1"),
    "min_pairs below 2": ({"bootstrap = 200": "bootstrap = 200\nmin_pairs = 1"}, "statistics.min_pairs", "must be"),
    "plant name with a slash": ({"[plants.hang2023]": '[plants."hang/2023"]'}, "plants.hang/2023", "is not a name"),
    "unknown method in a cell": ({'method = "hinf"\nplant': 'method = "hinff"\nplant'}, "cells[0].method",
                                 "unknown method 'hinff'"),
    "unknown plant in a cell": ({'plant = "zhang2019"\nscenario': 'plant = "zhang2020"\nscenario'}, "cells[1].plant",
                                "unknown plant 'zhang2020'"),
    "scenario escapes the folder": ({'scenario = "scenarios/arena_hinf_on_hang2023.toml"':
                                     'scenario = "../arena_hinf_on_hang2023.toml"'}, "cells[0].scenario",
                                    "leaves the arena file's folder"),
    "absolute scenario path": ({'scenario = "scenarios/arena_hinf_on_hang2023.toml"': 'scenario = "/etc/passwd"'},
                               "cells[0].scenario", "leaves the arena file's folder"),
    "missing scenario file": ({'scenario = "scenarios/arena_hinf_on_hang2023.toml"':
                               'scenario = "scenarios/nothing.toml"'}, "cells[0].scenario", "no such file"),
    "unknown gains label": ({'gains = "own"': 'gains = "mine"'}, "cells[0].gains", "unknown 'mine'"),
    "a fixed threshold is refused": ({"estimate_from = 0.5": "estimate_from = 0.5\nthreshold = 0.05"},
                                     "cells[1].threshold", "unknown key"),
    "truth without estimate": ({'gains = "own"': 'gains = "own"\ntruth = "faults.fault"'}, "cells[0].truth",
                               "applies only with an estimate"),
    "cell twice": ({'[[cells]]\nmethod = "fasmc"\nplant = "zhang2019"\nscenario = "scenarios/arena_fasmc_on_zhang2019.toml"':
                    '[[cells]]\nmethod = "hinf"\nplant = "hang2023"\nscenario = "scenarios/arena_fasmc_on_zhang2019.toml"'},
                   "cells[1]", "listed twice"),
    "estimate not a signal": ({'estimate = "est.f_hat"': 'estimate = "est.nothing"'}, "cells[1].scenario",
                              "record.variables"),
    "TOML syntax": ({"draws = 2": "draws = = 2"}, "file", "not valid TOML"),
}


def _run(argv, capsys):
    rc = main(argv)
    return rc, capsys.readouterr().err.strip().splitlines()


@pytest.mark.parametrize("case", sorted(CASES))
def test_malformed_arena_file(case, tmp_path, capsys):
    repl, key, problem = CASES[case]
    text = ARENA
    for a, b in repl.items():
        assert a in text, a
        text = text.replace(a, b, 1)
    path = write(tmp_path, text)
    before = sorted(p.name for p in tmp_path.iterdir())
    out = tmp_path / "out"
    rc, err = _run(["arena", str(path), "--out", str(out), "--workers", "0", "--quiet"], capsys)
    assert rc == 2, err
    assert len(err) == 1, err
    assert err[0].startswith(f"ftcsim: error: {path}: {key}:"), err[0]
    assert problem in err[0], err[0]
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # no temporary leftovers


@pytest.mark.parametrize("argv,key,problem", [
    (["--workers", "-1"], "--workers", "must be >= 0"),
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--workers", "not both"),
    (["--scheduler", "not-an-address"], "--scheduler", ""),
    (["--batch", "3"], "--batch", "sizes its tasks itself"),
    (["--draws", "0"], "--draws", "must be in 1"),
    (["--stop", "-1"], "--stop", "must be > 0"),
    (["--stop", "nan"], "--stop", "expected a finite number"),
    (["--faults", "bias,loe"], "--faults[1]", "unknown 'loe'"),
    (["--faults", "bias", "bias"], "--faults", "twice"),
    (["--hardware", "perfect"], "--hardware[0]", "unknown 'perfect'"),
    (["--only", "fasmc_on_li2023"], "--only", "no cell 'fasmc_on_li2023'"),
    (["--only", "fasmc_on_zhang2019", "fasmc_on_zhang2019"], "--only", "twice"),
    (["--time-limit", "-5"], "--time-limit", "expected a number of seconds >= 0"),
    (["--scheduler-file"], "--scheduler-file", "scheduler file not found"),
])
def test_bad_arguments(argv, key, problem, tmp_path, capsys):
    path = write(tmp_path)
    if argv == ["--scheduler-file"]:
        argv = ["--scheduler-file", str(tmp_path / "no-such-file.json")]
    rc, err = _run(["arena", str(path), "--out", str(tmp_path / "out"), *argv], capsys)
    assert rc == 2 and len(err) == 1 and f": {key}: " in err[0] and problem in err[0], err
    assert not (tmp_path / "out").exists()


def test_missing_arena_file_and_wrong_suffix(tmp_path, capsys):
    rc, err = _run(["arena", str(tmp_path / "none.toml"), "--out", str(tmp_path / "out")], capsys)
    assert rc == 2 and err == [f"ftcsim: error: {tmp_path / 'none.toml'}: file: no such file"], err
    (tmp_path / "a.json").write_text("{}")
    rc, err = _run(["arena", str(tmp_path / "a.json"), "--out", str(tmp_path / "out")], capsys)
    assert rc == 2 and "file: an arena file is a .toml file" in err[0], err
    assert not (tmp_path / "out").exists()


def test_out_holding_something_else_is_refused(tmp_path, capsys):
    path = write(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    (out / "precious.txt").write_text("mine")
    rc, err = _run(["arena", str(path), "--out", str(out), "--workers", "0", "--quiet"], capsys)
    assert rc == 2 and "command line: --out:" in err[0] and "not an arena folder" in err[0], err
    assert sorted(p.name for p in out.iterdir()) == ["precious.txt"]


def test_runs_the_cluster_lost_end_in_a_message_to_rerun(tmp_path, capsys, monkeypatch):
    """Campaigns that come back short (workers lost runs) leave the arena folder resumable: nothing
    stored, no page, exit status 1 and a message to rerun the same command."""
    from types import SimpleNamespace

    import arena.app as app

    def lost(items, **kw):
        return [(None, SimpleNamespace(total=2 if "draws" in str(f) else 1, stored=0, lost=2 if "draws" in str(f) else 1,
                                       interrupted=0, folder=o)) for f, o, _ in items]

    monkeypatch.setattr(app.api, "campaigns", lost)
    path = write(tmp_path)
    out = tmp_path / "out"
    rc, err = _run(["arena", str(path), "--out", str(out), "--workers", "0", "--quiet"], capsys)
    assert rc == 1 and len(err) == 1 and "runs could not be computed; rerun the same command" in err[0], err
    assert (out / "arena.json").is_file() and not (out / "leaderboard.html").exists()
    assert sorted(p.name for p in (out / "cells").iterdir()) == sorted(
        f"{c}.{hw}" for c in ("hinf_on_hang2023", "fasmc_on_zhang2019", "pd_on_zhang2019") for hw in ("ideal", "realistic"))
