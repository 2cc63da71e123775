"""What a new user meets first (issue 36 items 3 and 5): metric lines with their units, the
scenario listing, shell completion, the exported reader and error, the cache folders through
platformdirs, the campaign report's intervals from scipy.stats, the container's start-up lines."""
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ftcsim
from orchestrator.campaign.report import median_ci, wilson
from orchestrator.cli.main import main
from orchestrator.interop.engines import CONTAINER_START_LINES
from orchestrator.scenario.shipped import scenario_files
from plant import jit
from plant.units import power, pretty, product, ucum

ROOT = Path(__file__).resolve().parents[2]


def test_run_prints_each_metric_with_its_unit(tmp_path, capsys):
    assert main(["run", "li2023_pd", "--mode", "inprocess", "--stop", "1", "--no-plots", "--out",
                 str(tmp_path / "r")]) == 0
    lines = [ln.strip() for ln in capsys.readouterr().out.splitlines() if ln.startswith("  ")]
    units = {ln.split(" = ")[0]: ln.rsplit(" ", 1)[-1] for ln in lines}
    assert units == {"final_attitude_error": "rad", "final_rate_error": "rad/s", "control_energy": "N2.m2.s",
                     "max_abs_u": "N.m"}, lines


def test_units_spelled_one_way_per_medium():
    for legacy in ("(N.m)2.s", "N2.m2.s", "N²·m²·s"):
        assert ucum(legacy) == "N2.m2.s" and pretty(legacy) == "N²·m²·s"
    assert product(power("N.m", 2), "s") == "N2.m2.s" and ucum("rad/s2") == "rad/s2" and pretty("rad/s2") == "rad/s²"
    assert ucum("1/s") == "1/s" and ucum("kg.m2") == "kg.m2" and pretty("kg.m2") == "kg·m²" and ucum(None) is None


def test_scenarios_columns_hold_on_long_names_and_the_arena_is_listed(capsys):
    assert main(["scenarios"]) == 0
    lines = capsys.readouterr().out.splitlines()
    files = scenario_files()
    assert [ln.split()[0] for ln in lines] == list(files)
    width = max(len(n) for n in files)
    starts = {len(ln[:width + 2]) + len(ln[width + 2:]) - len(ln[width + 2:].lstrip()) for ln in lines}
    assert starts == {width + 2}, "the source column starts at the same place on every line"
    assert all(ln[width] == " " for ln in lines)
    arena = [ln for ln in lines if ln.split()[1] == "arena"]
    assert arena and all(ln.split()[0].startswith("arena_") for ln in arena)
    assert any(Path(files[ln.split()[0]]).parent.name == "scenarios" and "arena" in Path(files[ln.split()[0]]).parts
               for ln in arena)


def test_an_arena_scenario_runs_by_name(tmp_path, capsys):
    assert main(["run", "arena_pd_on_zhang2019", "--mode", "inprocess", "--stop", "0.05", "--no-plots", "--quiet",
                 "--out", str(tmp_path / "a")]) == 0, capsys.readouterr().err


def test_bash_completion_knows_commands_options_and_scenarios(tmp_path):
    script = subprocess.run([sys.executable, "-m", "orchestrator.cli.main", "completion", "bash"], cwd=ROOT,
                            capture_output=True, text=True, timeout=120, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert script.returncode == 0, script.stderr
    (tmp_path / "c.bash").write_text(script.stdout)
    probe = f"""source {tmp_path / 'c.bash'}
complete_words() {{ COMP_WORDS=("$@"); COMP_CWORD=$(( $# - 1 )); COMP_LINE="$*"; COMP_POINT=${{#COMP_LINE}}
  COMPREPLY=(); _shtab_ftcsim "ftcsim" "${{@: -1}}" "${{@: -2:1}}"; printf '%s\\n' "${{COMPREPLY[@]}}"; echo ---; }}
complete_words ftcsim camp
complete_words ftcsim run li2023_fa
complete_words ftcsim run --mode ''
"""
    out = subprocess.run(["bash", "-c", probe], capture_output=True, text=True, cwd=tmp_path, timeout=60).stdout
    commands, names, modes = (set(part.split()) for part in out.split("---")[:3])
    assert commands == {"campaign", "campaign-report"}
    assert names == {n for n in scenario_files() if n.startswith("li2023_fa")}
    assert modes == {"fmu", "inprocess"}


def test_read_table_and_input_error_are_exported(tmp_path):
    r = ftcsim.run("li2023_pd", stop=0.5, mode="inprocess", out=tmp_path / "r")
    df = ftcsim.read_table(tmp_path / "r" / "results.parquet")
    assert df.attrs["units"]["ctrl.u[1]"] == "N.m" and len(df) == len(r.df)
    with pytest.raises(ftcsim.InputError) as e:
        ftcsim.run("li2023_pd", parameters={"ctrl.k_pp": 1.0}, mode="inprocess")
    assert e.value.key == "parameters.ctrl.k_pp" and "k_p" in e.value.problem


def test_the_kernel_cache_follows_xdg_and_works_without_platformdirs(monkeypatch, tmp_path):
    monkeypatch.delenv("FTCSIM_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    if sys.platform.startswith("linux"):
        assert jit.cache_root() == str(tmp_path / "xdg" / "ftcsim" / "numba")
    monkeypatch.setitem(sys.modules, "platformdirs", None)  # a host Python without it (an FMU's minimum)
    assert jit.user_cache_dir() == str(tmp_path / "xdg" / "ftcsim")


def test_wilson_interval_is_the_score_interval():
    for k, n in [(0, 5), (3, 10), (42, 50), (50, 50), (1, 1)]:
        z = 1.959963984540054
        p = k / n
        c, h = (p + z * z / (2 * n)) / (1 + z * z / n), z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
        lo, hi = wilson(k, n)
        assert lo == pytest.approx(max(0.0, c - h), abs=1e-12) and hi == pytest.approx(min(1.0, c + h), abs=1e-12)
    assert wilson(0, 0) == (None, None)


def test_median_interval_is_a_bootstrap_of_the_median():
    """For 400 normal draws the percentile-bootstrap interval of the median is near the asymptotic
    one (median +- 1.96 sqrt(pi / 2) sigma / sqrt(n)); the same data give the same interval."""
    x = np.random.default_rng(7).normal(3.0, 2.0, 400)
    med, lo, hi = median_ci(x)
    half = 1.959963984540054 * math.sqrt(math.pi / 2) * 2.0 / math.sqrt(400)
    assert med == pytest.approx(np.median(x)) and lo < med < hi
    assert (hi - lo) / 2 == pytest.approx(half, rel=0.3)
    assert median_ci(x) == (med, lo, hi)
    assert median_ci([1.0, 1.0, 1.0]) == (1.0, 1.0, 1.0) and median_ci([2.0]) == (2.0, None, None)
    assert median_ci([np.nan]) == (None, None, None)


def test_the_container_start_lines_are_recognised_and_nothing_else():
    known = ["FMUContainer 'V2.0'", "Solver configure....", "Container use PARALLEL mode with MONO thread."]
    other = ["Solver configure failed", "cannot load FMU 'x'", "FMUContainer 'V2.0' crashed"]
    assert all(any(p.fullmatch(t) for p in CONTAINER_START_LINES) for t in known)
    assert not any(any(p.fullmatch(t) for p in CONTAINER_START_LINES) for t in other)
