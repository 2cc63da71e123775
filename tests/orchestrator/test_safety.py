"""Issue 8: ftcsim never deletes what it did not create, never loses a computed result, checks
output paths and sizes before a run, and stops cleanly on SIGINT / SIGTERM."""
import json
import os
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest
from scenario_text import PD, variant, write

from orchestrator.cli.main import main
from orchestrator.common.outputs import MARKER, OutputFolder
from orchestrator.results.files import metrics_and_info, read_results

ROOT = Path(__file__).resolve().parents[2]
SHORT = variant({"stop = 200.0": "stop = 0.5"})


def _run(argv, capsys):
    rc = main(argv)
    cap = capsys.readouterr()
    return rc, cap.err.strip().splitlines()


def _tree(folder: Path) -> dict:
    """Every path below ``folder`` with its size (files) or None (folders)."""
    return {str(p.relative_to(folder)): (p.stat().st_size if p.is_file() else None) for p in folder.rglob("*")}


# -- output folders -----------------------------------------------------------------------------
def test_out_holding_an_unrelated_file_is_refused_and_untouched(tmp_path, capsys):
    scen = write(tmp_path, SHORT)
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("four years of work")
    rc, err = _run(["run", str(scen), "--out", str(out), "--quiet", "--mode", "inprocess"], capsys)
    assert rc == 2 and len(err) == 1 and "was not written by ftcsim" in err[0] and "--out" in err[0]
    assert (out / "thesis.tex").read_text() == "four years of work"
    rc, err = _run(["run", str(scen), "--out", str(out), "--quiet", "--mode", "inprocess", "--overwrite"], capsys)
    assert rc == 2 and "was not written by ftcsim" in err[0]  # --overwrite does not change that
    assert sorted(p.name for p in out.iterdir()) == ["thesis.tex"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml", "mine"]  # no temporary leftovers


def test_out_dot_is_refused(tmp_path, capsys, monkeypatch):
    scen = write(tmp_path, SHORT)
    monkeypatch.chdir(tmp_path)
    before = _tree(tmp_path)
    rc, err = _run(["run", str(scen), "--out", ".", "--quiet", "--mode", "inprocess"], capsys)
    assert rc == 2 and len(err) == 1 and "--out" in err[0]
    assert _tree(tmp_path) == before


def test_previous_result_is_replaced_only_with_overwrite(tmp_path, capsys):
    scen = write(tmp_path, SHORT)
    out = tmp_path / "run"
    assert _run(["run", str(scen), "--out", str(out), "--quiet", "--no-plots", "--mode", "inprocess"], capsys)[0] == 0
    assert (out / MARKER).is_file() and (out / "results.parquet").is_file()
    first = (out / "results.parquet").stat().st_mtime_ns
    rc, err = _run(["run", str(scen), "--out", str(out), "--quiet", "--no-plots", "--mode", "inprocess"], capsys)
    assert rc == 2 and "pass --overwrite" in err[0]
    assert (out / "results.parquet").stat().st_mtime_ns == first
    rc, _ = _run(["run", str(scen), "--out", str(out), "--quiet", "--no-plots", "--mode", "inprocess", "--overwrite"],
                 capsys)
    assert rc == 0 and (out / "results.parquet").stat().st_mtime_ns != first
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml", "run"]


@pytest.mark.parametrize("name", ["../escape", "/tmp/absolute", "", "a/b", "..", "x\x01y", "n" * 300, "dir\\x",
                                  "with space", "~home"])
def test_hostile_scenario_names_touch_nothing(name, tmp_path, capsys, monkeypatch):
    work = tmp_path / "work"
    work.mkdir()
    scen = write(work, SHORT.replace('name = "li2023_pd"', f"name = {json.dumps(name)}"))
    monkeypatch.chdir(work)
    outside = _tree(tmp_path)
    rc, err = _run(["run", str(scen), "--quiet", "--mode", "inprocess"], capsys)
    assert rc == 2 and len(err) == 1 and "scenario.name" in err[0], err
    assert _tree(tmp_path) == outside  # not even results/ was created


def test_two_commands_on_one_out_cannot_both_succeed(tmp_path, capsys):
    scen = write(tmp_path, SHORT)
    out = tmp_path / "shared"
    holder = OutputFolder(out, "run").check()  # another command holds the folder
    try:
        rc, err = _run(["run", str(scen), "--out", str(out), "--quiet", "--mode", "inprocess"], capsys)
        assert rc == 2 and "another ftcsim command is writing" in err[0]
    finally:
        holder.discard()
    assert not out.exists()
    assert _run(["run", str(scen), "--out", str(out), "--quiet", "--no-plots", "--mode", "inprocess"], capsys)[0] == 0


def test_publish_refuses_a_folder_that_appeared_meanwhile(tmp_path):
    out = tmp_path / "late"
    folder = OutputFolder(out, "run").check()
    (folder.staging() / "results.csv").write_text("time\n0\n")
    out.mkdir()
    (out / "keep.txt").write_text("someone else's")
    from orchestrator.common.errors import SimulationError

    with pytest.raises(SimulationError, match="is kept in"):
        folder.publish()
    assert (out / "keep.txt").read_text() == "someone else's"
    kept = [p for p in tmp_path.iterdir() if p.name.startswith(".late.tmp-")]
    assert len(kept) == 1 and (kept[0] / "results.csv").is_file()  # the computed result is not lost


def test_output_paths_are_checked_before_the_run(tmp_path, capsys):
    scen = write(tmp_path, PD)  # a full 200 s run: refusing it must not take its time
    a_file = tmp_path / "file"
    a_file.write_text("x")
    ro = tmp_path / "readonly"
    ro.mkdir()
    ro.chmod(0o555)
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "target_dir", target_is_directory=True)
    try:
        for out, problem in ((a_file / "sub", "is a file"), (a_file, "not a directory"),
                             (link, "symbolic link")) + (() if os.geteuid() == 0 else ((ro / "out", "not writable"),)):
            t0 = time.perf_counter()
            rc, err = _run(["run", str(scen), "--out", str(out), "--quiet", "--mode", "inprocess"], capsys)
            assert rc == 2 and len(err) == 1 and problem in err[0], (out, err)
            assert time.perf_counter() - t0 < 20.0
    finally:
        ro.chmod(0o755)
    assert not (tmp_path / "target_dir").exists()


def test_export_ssp_keeps_an_existing_file_unless_overwrite(tmp_path, capsys, fmu_dir):
    scen = write(tmp_path, SHORT)
    target = tmp_path / "system.ssp"
    target.write_text("a package someone else made")
    argv = ["export-ssp", str(scen), "--out", str(target), "--fmu-dir", str(fmu_dir), "--quiet"]
    for extra in ([], ["--overwrite"]):  # never replaced: ftcsim did not write it (issue 35)
        rc, err = _run(argv + extra, capsys)
        assert rc == 2 and len(err) == 1 and "not written by ftcsim" in err[0] and str(target) in err[0], err
        assert target.read_text() == "a package someone else made"
    target.unlink()
    assert _run(argv, capsys)[0] == 0 and zipfile.is_zipfile(target)
    rc, err = _run(argv, capsys)  # ftcsim's own package: replaced with --overwrite only
    assert rc == 2 and "--overwrite" in err[0]
    rc, err = _run(argv + ["--overwrite"], capsys)
    assert rc == 0 and zipfile.is_zipfile(target)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml", "system.ssp"]  # no temporary leftovers


# -- never lose a computed result ----------------------------------------------------------------
def test_short_fasmc_run_keeps_everything_and_metrics_are_strict_json(tmp_path, capsys, scenarios):
    text = (scenarios / "li2023_fasmc.toml").read_text().replace("stop = 200.0", "stop = 2.0")
    scen = write(tmp_path, text)
    out = tmp_path / "short"
    rc, err = _run(["run", str(scen), "--out", str(out), "--quiet", "--no-plots", "--mode", "inprocess"], capsys)
    assert rc == 0, err
    json.loads((out / "metrics.json").read_text(), parse_constant=lambda c: pytest.fail(f"non-strict JSON constant {c}"))
    m = metrics_and_info(out)
    assert m["complete"] and m["t_end"] == 2.0
    assert m["fault_rms"] is None and m["observer_error_max_after_faults"] is None  # windows after the run: null
    assert m["observer_error_max_settled_before_faults"] is None
    header, data = read_results(out)
    assert data.shape[0] == 201


def test_post_processing_failure_keeps_results_csv(tmp_path, capsys, monkeypatch):
    import orchestrator.results.files as results

    def broken(result, scenario):
        raise ZeroDivisionError("a bug in a metric")

    monkeypatch.setattr(results, "compute_metrics", broken)
    scen = write(tmp_path, SHORT)
    out = tmp_path / "kept"
    rc, err = _run(["run", str(scen), "--out", str(out), "--quiet", "--no-plots", "--mode", "inprocess"], capsys)
    assert rc == 1 and len(err) == 1 and "post-processing failed" in err[0] and "results kept" in err[0]
    _, data = read_results(out)
    assert data.shape[0] == 51
    m = metrics_and_info(out)
    assert "ZeroDivisionError" in m["post_processing_errors"][0] and m["complete"] is True


@pytest.mark.parametrize("metrics,key", [("settle_time = [0, 1]", "metrics.settle_time"),
                                         ("fault_window = 1.0", "metrics.fault_window"),
                                         ("fault_window = [5.0, 1.0]", "metrics.fault_window"),
                                         ("fault_onset = \"soon\"", "metrics.fault_onset")])
def test_metrics_values_are_checked_before_the_run(metrics, key, tmp_path, capsys, scenarios):
    text = (scenarios / "li2023_fasmc.toml").read_text().replace("settle_time = 15.0", "", 1)
    text = text.replace("fault_onset = 40.0\nfault_window = [50.0, 200.0]", "") + metrics + "\n"
    scen = write(tmp_path, text)
    out = tmp_path / "m"
    rc, err = _run(["run", str(scen), "--out", str(out), "--quiet", "--mode", "inprocess"], capsys)
    assert rc == 2 and len(err) == 1 and f": {key}:" in err[0], err
    assert not out.exists()


def test_huge_step_count_is_refused_before_any_fmu_starts(tmp_path, capsys):
    scen = write(tmp_path, SHORT)
    t0 = time.perf_counter()
    rc, err = _run(["run", str(scen), "--out", str(tmp_path / "o"), "--step", "1e-12", "--quiet"], capsys)
    # the option that made the count wrong is named, not the scenario file's timing.step (issue 35)
    assert rc == 2 and len(err) == 1 and "command line: --step:" in err[0] and "steps" in err[0]
    assert time.perf_counter() - t0 < 10.0 and not (tmp_path / "o").exists()


# -- interruption, temporary folders, non-ASCII paths --------------------------------------------
def _cli(args, env=None, **kw):
    return subprocess.Popen([sys.executable, "-m", "orchestrator.cli", *args], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


@pytest.mark.fmu
@pytest.mark.slow
@pytest.mark.parametrize("sig,status", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_signal_part_way_keeps_an_incomplete_readable_run(sig, status, tmp_path, fmu_dir, scenarios):
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    out = tmp_path / "interrupted"
    env = dict(os.environ, TMPDIR=str(tmpdir), FTCSIM_FMU_DIR=str(fmu_dir))
    # at 1 ms (200000 steps) the run lasts long enough to be interrupted whatever the blocks' speed
    # (with the compiled kernels the 10 ms run is over in about 2 s)
    p = _cli(["run", str(scenarios / "li2023_fasmc.toml"), "--out", str(out), "--quiet", "--no-plots", "--step", "0.001",
              "--record-step", "0.001"],
             env=env)
    lock = tmp_path / ".interrupted.ftcsim-lock"
    deadline = time.time() + 60
    while not lock.exists() and p.poll() is None and time.time() < deadline:
        time.sleep(0.05)
    time.sleep(4.0)  # FMUs loaded, stepping
    p.send_signal(sig)
    _, err = p.communicate(timeout=120)
    lines = err.strip().splitlines()
    assert p.returncode == status, err
    assert len(lines) == 1 and "stopped" in lines[0] and "Traceback" not in err, err
    header, data = read_results(out)
    m = metrics_and_info(out)
    assert m["complete"] is False and (out / "INCOMPLETE").is_file()
    assert 1 < data.shape[0] < 200001 and np.isfinite(data).all()
    assert data[-1, 0] == m["t_end"]
    assert list(tmpdir.iterdir()) == []  # FMU extraction folders removed
    assert sorted(p.name for p in tmp_path.iterdir()) == ["interrupted", "tmp"]  # no staging or lock left


@pytest.mark.fmu
def test_run_with_a_non_ascii_temporary_folder_completes(tmp_path, fmu_dir):
    tmpdir = tmp_path / "tempo_ü_日本"
    tmpdir.mkdir()
    out = tmp_path / "résultats"
    scen = write(tmp_path, SHORT)
    env = dict(os.environ, TMPDIR=str(tmpdir), FTCSIM_FMU_DIR=str(fmu_dir))
    p = _cli(["run", str(scen), "--out", str(out), "--quiet", "--no-plots"], env=env)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 0, err
    _, data = read_results(out)
    assert data.shape[0] == 51 and list(tmpdir.iterdir()) == []


def test_non_ascii_instance_name_is_refused(tmp_path, capsys, fmu_dir):
    text = SHORT.replace("[instances.ctrl]", '[instances."ctrlé"]').replace("[instances.ctrl.parameters]",
                                                                          '[instances."ctrlé".parameters]')
    scen = write(tmp_path, text)
    rc, err = _run(["run", str(scen), "--out", str(tmp_path / "o"), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1 and "instances.ctrlé" in err[0] and "identifier" in err[0]
