"""Bad input to ``ftcsim fdir calibrate``: one line naming the option or file, the key and the problem,
exit 2, nothing written (no draws folder, no calibration file); the API names its own arguments."""
import re
import subprocess
import sys

import pytest

from orchestrator import api
from orchestrator.cli.main import main
from orchestrator.common.errors import InputError
from orchestrator.scenario.shipped import campaign_file

SHIPPED = campaign_file("zhang2019_fdir_calibration").read_text()


def _campaign(tmp_path, old=None, new=None, name="c.toml"):
    text = SHIPPED if old is None else SHIPPED.replace(old, new)
    assert old is None or text != SHIPPED
    (tmp_path / name).write_text(text)
    return str(tmp_path / name)


def _run(tmp_path, capsys, *args, campaign=None):
    argv = ["fdir", "calibrate", campaign or _campaign(tmp_path), "--draws", str(tmp_path / "draws"),
            "--out", str(tmp_path / "cal.json"), "--workers", "0", *args]
    rc = main(argv)
    err = capsys.readouterr().err.strip()
    assert not (tmp_path / "draws").exists(), "nothing may be written"
    return rc, err


@pytest.mark.parametrize("args,key", [
    (["--detector", "det", "--rate", "0"], "--rate"),
    (["--detector", "det", "--rate", "nan"], "--rate"),
    (["--detector", "det", "--rate", "1", "--level", "1.5"], "--level"),
    (["--detector", "dte", "--rate", "1"], "--detector"),
    (["--detector", "est", "--rate", "1"], "--detector"),
    (["--detector", "det", "--rate", "1", "--runs", "0"], "--runs"),
])
def test_bad_options_are_one_line_exit_2(tmp_path, capsys, args, key):
    rc, err = _run(tmp_path, capsys, *args)
    assert rc == 2 and len(err.splitlines()) == 1 and key in err, err
    assert not (tmp_path / "cal.json").exists()


@pytest.mark.parametrize("old,new,key", [
    ('trajectories = ["est.f_hat"]', 'trajectories = ["ctrl.u"]', "campaign.trajectories"),
    ("trajectory_step = 0.01", "trajectory_step = 0.02", "campaign.trajectory_step"),
    ('[dispersions."plant.sigma_init"]', '[dispersions."det.drift"]\ndistribution = "uniform"\nlow = 1.0\nhigh = 2.0\n\n'
                                         '[dispersions."plant.sigma_init"]', "dispersions.det.drift"),
    ("trajectory_step = 0.01\n", 'trajectory_step = 0.01\n\n[[variants]]\nname = "a"\n\n[[variants]]\nname = "b"\n', "variants"),
    ('"det.drift" = 2.0', '"det.drift" = -2.0', "det.drift"),  # the block's own refusal, named (issue 35)
])
def test_a_campaign_the_calibration_cannot_use_is_named(tmp_path, capsys, old, new, key):
    rc, err = _run(tmp_path, capsys, "--detector", "det", "--rate", "1", campaign=_campaign(tmp_path, old, new))
    assert rc == 2 and len(err.splitlines()) == 1 and key in err and "c.toml" in err, err


def test_an_output_that_is_not_ours_is_never_touched(tmp_path, capsys):
    (tmp_path / "cal.json").write_text('{"mine": 1}')
    rc, err = _run(tmp_path, capsys, "--detector", "det", "--rate", "1")
    assert rc == 2 and "--out" in err and "not written by `ftcsim fdir calibrate`" in err
    assert (tmp_path / "cal.json").read_text() == '{"mine": 1}'
    rc, err = main(["fdir", "calibrate", _campaign(tmp_path), "--detector", "det", "--rate", "1", "--draws",
                    str(tmp_path / "d"), "--out", str(tmp_path / "cal.txt")]), capsys.readouterr().err
    assert rc == 2 and "ends in .json" in err


def test_the_draws_folder_and_the_campaign_are_named_as_this_command_names_them(tmp_path, capsys):
    (tmp_path / "draws").write_text("a file")
    rc = main(["fdir", "calibrate", _campaign(tmp_path), "--detector", "det", "--rate", "1", "--draws",
               str(tmp_path / "draws"), "--out", str(tmp_path / "cal.json"), "--workers", "0"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "--draws" in err and "not a directory" in err and len(err.splitlines()) == 1, err
    assert (tmp_path / "draws").read_text() == "a file" and not (tmp_path / "cal.json").exists()
    rc = main(["fdir", "calibrate", str(tmp_path), "--detector", "det", "--rate", "1", "--draws", str(tmp_path / "d"),
               "--out", str(tmp_path / "cal.json")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "CAMPAIGN" in err and "not found" in err, err


def test_the_command_line_is_registered_and_argparse_errors_are_one_line(tmp_path):
    p = subprocess.run([sys.executable, "-m", "orchestrator.cli", "fdir", "calibrate", "x.toml", "--rate", "1"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1
    assert re.search(r"--detector|--draws|--out", p.stderr)
    p = subprocess.run([sys.executable, "-m", "orchestrator.cli", "fdir", "calibrate", str(tmp_path / "none.toml"),
                        "--detector", "det", "--rate", "1", "--draws", str(tmp_path / "d"), "--out", str(tmp_path / "c.json")],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and "none.toml" in p.stderr and len(p.stderr.strip().splitlines()) == 1


def test_the_api_names_its_arguments(tmp_path):
    with pytest.raises(InputError) as e:
        api.fdir_calibrate(_campaign(tmp_path), detector="det", rate_per_hour=-1, draws=tmp_path / "d", out=tmp_path / "c.json")
    assert e.value.key == "rate_per_hour"
    with pytest.raises(InputError) as e:
        api.fdir_calibrate(_campaign(tmp_path), detector="nope", rate_per_hour=1, draws=tmp_path / "d", out=tmp_path / "c.json")
    assert e.value.key == "detector" and "did you mean" in e.value.problem or "instances" in e.value.problem
