"""Bad input of issue 20 items 4 to 6 (campaign files, time limits, step bounds): one line naming the
file and the key, exit status 2, no traceback, nothing written. In-process, nothing runs."""
import time

import pytest

import ftcsim
from orchestrator.cli.main import main
from orchestrator.common.errors import InputError

CAMPAIGN = '[campaign]\nscenario = "li2023_pd"\nmode = "inprocess"\nruns = 2\nstop = 0.1\n'
GRID_1E9 = "[grid]\n" + "".join(f'"{ref}" = [{", ".join(str(1.0 + k) for k in range(1000))}]\n'
                                for ref in ("ctrl.k_p", "ctrl.k_d", "plant.fault_scale"))

# (text added to CAMPAIGN or replacing its [campaign] keys, key, problem)
CAMPAIGN_CASES = {
    "distribution as a list": ('[dispersions."plant.fault_scale"]\ndistribution = ["normal"]\nmean = 1\nstd = 0.1\n',
                               "dispersions.plant.fault_scale.distribution", "got list"),
    "distribution as a number": ('[dispersions."plant.fault_scale"]\ndistribution = 3\nmean = 1\nstd = 0.1\n',
                                 "dispersions.plant.fault_scale.distribution", "got int"),
    "distribution as a table": ('[dispersions."plant.fault_scale"]\ndistribution = { a = 1 }\nmean = 1\nstd = 0.1\n',
                                "dispersions.plant.fault_scale.distribution", "got dict"),
    "400-digit seed": ({"runs = 2": "runs = 2\nseed = " + "9" * 400}, "campaign.seed", "a number of 400 digits"),
    "seed of 2**63": ({"runs = 2": f"runs = 2\nseed = {2**63}"}, "campaign.seed", "at most 2**63 - 1"),
    "negative seed": ({"runs = 2": "runs = 2\nseed = -1"}, "campaign.seed", "must be >= 0"),
    "overflowing choice weights": (
        '[dispersions."ctrl.k_p"]\ndistribution = "choice"\nvalues = [10.0, 20.0]\nweights = [1e308, 1e308]\n', None, None),
    "infinite choice weight": ('[dispersions."ctrl.k_p"]\ndistribution = "choice"\nvalues = [10.0, 20.0]\n'
                               'weights = [inf, 1.0]\n', "dispersions.ctrl.k_p.weights", "must be finite"),
    "all-zero choice weights": ('[dispersions."ctrl.k_p"]\ndistribution = "choice"\nvalues = [10.0, 20.0]\n'
                                'weights = [0.0, 0.0]\n', "dispersions.ctrl.k_p.weights", "positive sum"),
    "grid of 1e9 points": (GRID_1E9, "grid", "2000000000 runs: more than 1000000"),
    "negative time limit": ({"runs = 2": "runs = 2\ntime_limit = -1.0"}, "campaign.time_limit", "must be > 0"),
    "zero time limit": ({"runs = 2": "runs = 2\ntime_limit = 0"}, "campaign.time_limit", "must be > 0"),
    "time limit as a string": ({"runs = 2": 'runs = 2\ntime_limit = "1h"'}, "campaign.time_limit", "expected a number"),
    "NaN time limit": ({"runs = 2": "runs = 2\ntime_limit = nan"}, "campaign.time_limit", "must be finite"),
    "time limit key typo": ({"runs = 2": "runs = 2\ntimelimit = 10"}, "campaign.timelimit", "time_limit"),
}


def _one_line(capsys):
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err and "internal error" not in err, err
    return err


@pytest.mark.parametrize("case", CAMPAIGN_CASES, ids=list(CAMPAIGN_CASES))
def test_bad_campaign_files(tmp_path, capsys, case):
    change, key, problem = CAMPAIGN_CASES[case]
    text = CAMPAIGN
    if isinstance(change, dict):
        for a, b in change.items():
            text = text.replace(a, b)
    else:
        text += change
    path = tmp_path / "c.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    t0 = time.monotonic()
    rc = main(["campaign", str(path), "--out", str(out), "--workers", "0", "--quiet", "--run", "0"])
    if key is None:  # overflowing relative weights are fine: 1e308 and 1e308 are equal weights; the run is made
        assert rc == 0 and capsys.readouterr().err == ""
        return
    err = _one_line(capsys)
    assert rc == 2 and f"{path}: {key}: " in err and problem in err, err
    assert not out.exists()
    assert time.monotonic() - t0 < 60  # the grid is counted, not built


def test_equal_overflowing_weights_draw_both_values_evenly(tmp_path):
    from orchestrator.campaign import expand as E
    from orchestrator.campaign import spec as S

    path = tmp_path / "c.toml"
    path.write_text(CAMPAIGN.replace("runs = 2", "runs = 400") + CAMPAIGN_CASES["overflowing choice weights"][0])
    c = S.load(path)
    kp = [s.requested["ctrl.k_p"] for s in E.expand(c)]
    assert set(kp) == {10.0, 20.0} and abs(kp.count(10.0) - 200) < 4 * 10  # binomial(400, 1/2): sd 10


SCENARIO_CASES = {
    "h_max 1e-300": ('[scenario]\nextends = "li2023_pd"\n[instances.plant.parameters]\nh_max = 1e-300\n',
                     "instances.plant.parameters.h_max", "internal steps per communication step"),
    "h_max 1e-12": ('[scenario]\nextends = "li2023_pd"\n[instances.plant.parameters]\nh_max = 1e-12\n',
                    "instances.plant.parameters.h_max", "more than 100000"),
    "adaptive min_step 1e-300": ('[scenario]\nextends = "li2023_pd"\n[timing]\nstep_policy = "adaptive"\n'
                                 "min_step = 1e-300\n", "timing.min_step", "steps, more than the 1e+08"),
    "negative scenario time limit": ('[scenario]\nextends = "li2023_pd"\n[timing]\ntime_limit = -3.0\n',
                                     "timing.time_limit", "must be > 0"),
    "scenario time limit as a string": ('[scenario]\nextends = "li2023_pd"\n[timing]\ntime_limit = "1 min"\n',
                                        "timing.time_limit", "expected a number"),
    "adaptive min_step 1e-7 over 200 s": ('[scenario]\nextends = "li2023_pd"\n[timing]\nstep_policy = "adaptive"\n'
                                          "min_step = 1e-7\n", "timing.min_step", "use a larger min_step"),
}


@pytest.mark.parametrize("case", SCENARIO_CASES, ids=list(SCENARIO_CASES))
def test_step_settings_that_would_never_finish(tmp_path, capsys, case):
    text, key, problem = SCENARIO_CASES[case]
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    assert main(["run", str(path), "--mode", "inprocess", "--out", str(out), "--quiet"]) == 2
    err = _one_line(capsys)
    assert f"{path}: {key}: " in err and problem in err, err
    assert not out.exists()


def test_an_absurd_h_max_given_as_a_parameter_override_is_refused_too():
    with pytest.raises(InputError, match="h_max = 1e-20 s gives"):
        ftcsim.load("li2023_pd", mode="inprocess", parameters={"plant.h_max": 1e-20})


CLI_CASES = {
    "run, negative": (["run", "li2023_pd", "--time-limit", "-1"], "must be a number of seconds > 0"),
    "run, NaN": (["run", "li2023_pd", "--time-limit", "nan"], "got nan"),
    "run, infinite": (["run", "li2023_pd", "--time-limit", "inf"], "got inf"),
    "campaign, negative": (["campaign", "li2023_methods", "--time-limit", "-5"], "got -5.0"),
    "compare, negative": (["compare", "x.fmu", "--time-limit", "-1"], "got -1.0"),
}


@pytest.mark.parametrize("case", CLI_CASES, ids=list(CLI_CASES))
def test_bad_time_limits_on_the_command_line(tmp_path, capsys, case):
    argv, problem = CLI_CASES[case]
    out = tmp_path / "out"
    assert main(argv + ["--out", str(out)]) == 2
    err = _one_line(capsys)
    assert "command line: --time-limit: " in err and problem in err, err
    assert not out.exists()


@pytest.mark.parametrize("bad", [-1.0, float("nan"), "10", True])
def test_bad_time_limits_in_the_api(bad, tmp_path):
    with pytest.raises(InputError, match="api: time_limit: "):
        ftcsim.run("li2023_pd", mode="inprocess", stop=0.1, time_limit=bad)
    with pytest.raises(InputError, match="api: time_limit: "):
        ftcsim.campaign("li2023_methods", tmp_path / "out", workers=0, time_limit=bad)
    assert not (tmp_path / "out").exists()
