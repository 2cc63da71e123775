"""Bad input around a run's files (issue 23 items 2-3, issue 20 item 2): record steps, formats,
result folders read back, files ftcsim did not write. Each gets one line naming the file or option
and the problem, exit status 2 (InputError in the API), and nothing written or replaced."""
import json
import zipfile

import pytest
from scenario_text import variant, write

import ftcsim
from orchestrator.cli.main import main
from orchestrator.common.errors import InputError

SHORT = "li2023_pd"


def _tree(path):
    return sorted((str(p.relative_to(path)), p.read_bytes() if p.is_file() else None) for p in path.rglob("*"))


def _cli(args, capsys):
    try:
        rc = main(args)
    except SystemExit as e:  # argparse's own errors
        rc = e.code
    return rc, capsys.readouterr().err.strip().splitlines()


RUN_ARGS = {
    "record step not a multiple of the step": (["--record-step", "0.015"], "--record-step", "not a whole multiple of the step 0.01 s"),
    "record step below the step": (["--record-step", "0.005"], "--record-step", "not a whole multiple"),
    "negative record step": (["--record-step", "-1"], "--record-step", "> 0"),
    "zero record step": (["--record-step", "0"], "--record-step", "> 0"),
    "NaN record step": (["--record-step", "nan"], "--record-step", "finite"),
    "infinite record step": (["--record-step", "inf"], "--record-step", "finite"),
    "record step not a number": (["--record-step", "1s"], "--record-step", "invalid float value"),
    "unknown format": (["--format", "xlsx"], "--format", "invalid choice"),
    "HDF5 is no format": (["--format", "hdf5"], "--format", "invalid choice"),
}


@pytest.mark.parametrize("case", sorted(RUN_ARGS))
def test_run_options(case, tmp_path, capsys):
    extra, key, problem = RUN_ARGS[case]
    rc, err = _cli(["run", SHORT, "--mode", "inprocess", "-o", str(tmp_path / "out"), "--quiet", *extra], capsys)
    assert rc == 2 and len(err) == 1 and key in err[0] and problem in err[0], err
    assert list(tmp_path.iterdir()) == []


API_ARGS = {
    "record_step as text": ({"record_step": "0.1"}, "record_step", "finite number"),
    "record_step as bool": ({"record_step": True}, "record_step", "finite number"),
    "record_step off the grid": ({"record_step": 0.025}, "record_step", "not a whole multiple"),
    "format unknown": ({"format": "feather"}, "format", "not a result format"),
}


@pytest.mark.parametrize("case", sorted(API_ARGS))
def test_api_options(case, tmp_path):
    kw, key, problem = API_ARGS[case]
    with pytest.raises(InputError) as e:
        ftcsim.run(SHORT, mode="inprocess", stop=0.1, out=tmp_path / "out", **kw)
    assert e.value.key == key and problem in e.value.problem
    assert list(tmp_path.iterdir()) == []


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A small Parquet result folder to damage."""
    out = tmp_path_factory.mktemp("good") / "run"
    ftcsim.run(SHORT, mode="inprocess", stop=0.2, out=out)
    return out


def _copy(good, tmp_path):
    folder = tmp_path / "copy"
    folder.mkdir()
    for p in good.iterdir():
        (folder / p.name).write_bytes(p.read_bytes())
    return folder


DAMAGE = {
    "truncated Parquet": (lambda f: (f / "results.parquet").write_bytes((f / "results.parquet").read_bytes()[:300]),
                          "results.parquet", "unreadable"),
    "Parquet that is text": (lambda f: (f / "results.parquet").write_text("time,a\n0,1\n"), "results.parquet", "unreadable"),
    "no results file": (lambda f: (f / "results.parquet").unlink(), "results.parquet", "missing"),
    "metrics.json not JSON": (lambda f: (f / "metrics.json").write_text("{"), "metrics.json", "not valid JSON"),
    "metrics.json a list": (lambda f: (f / "metrics.json").write_text("[]"), "metrics.json", "not a JSON object"),
    "signals not names": (lambda f: (f / "metrics.json").write_text(json.dumps({"metrics": {}, "info": {"signals": [1]}})),
                          "signals", "expected an object"),
}


@pytest.mark.parametrize("case", sorted(DAMAGE))
def test_open_refuses_damaged_folders(case, good, tmp_path, capsys):
    damage, where, problem = DAMAGE[case]
    folder = _copy(good, tmp_path)
    damage(folder)
    with pytest.raises(InputError) as e:
        ftcsim.open(folder)
    assert where in str(e.value) and problem in str(e.value), str(e.value)
    # the command line says the same in one line, and writes no report
    rc, err = _cli(["report", str(folder), "--out", str(tmp_path / "rep")], capsys)
    assert rc == 2 and len(err) == 1 and where in err[0] and problem in err[0], err
    assert not (tmp_path / "rep").exists()


def test_open_a_missing_folder(tmp_path):
    with pytest.raises(InputError, match="result folder not found"):
        ftcsim.open(tmp_path / "nowhere")


def test_plot_of_an_unknown_signal(good):
    with pytest.raises(InputError, match="no recorded signal 'ctrl.uu'.*ctrl.u"):
        ftcsim.open(good).plot(["ctrl.uu"])


def test_design_out_refuses_a_file_it_did_not_write(tmp_path, capsys):
    mine = tmp_path / "gains.json"
    mine.write_text('{"fmu_parameters": {}}\n')
    before = _tree(tmp_path)
    for extra in ([], ["--overwrite"]):
        rc, err = _cli(["design", "li2023-observer", "--out", str(mine), *extra], capsys)
        assert rc == 2 and len(err) == 1 and "--out" in err[0] and "not written by `ftcsim design`" in err[0], err
    assert _tree(tmp_path) == before


def test_design_out_replaces_its_own_file_only_with_overwrite(tmp_path, capsys):
    ours = tmp_path / "gains.json"
    ours.write_text(json.dumps({"written_by": "ftcsim design li2023-observer", "fmu_parameters": {}}))
    before = _tree(tmp_path)
    rc, err = _cli(["design", "li2023-observer", "--out", str(ours)], capsys)
    assert rc == 2 and len(err) == 1 and "pass --overwrite" in err[0], err
    assert _tree(tmp_path) == before


@pytest.mark.parametrize("what", ["a text file", "a zip that is no ftcsim FMU"])
def test_build_block_refuses_a_file_it_did_not_build(what, tmp_path, capsys):
    target = tmp_path / "Mine.fmu"
    if what == "a text file":
        target.write_text("my notes")
    else:
        with zipfile.ZipFile(target, "w") as z:
            z.writestr("modelDescription.xml", "<fmiModelDescription/>")
    before = _tree(tmp_path)
    rc, err = _cli(["build", "--block", "pd_block:MinimalPD", "--out", str(target)], capsys)
    assert rc == 2 and len(err) == 1 and "not an FMU ftcsim built" in err[0], err
    assert _tree(tmp_path) == before


def test_build_catalog_refuses_a_foreign_file_in_its_folder(tmp_path, capsys):
    (tmp_path / "PDController.fmu").write_text("someone else's")
    before = _tree(tmp_path)
    rc, err = _cli(["build", "PDController", "--out", str(tmp_path)], capsys)
    assert rc == 2 and len(err) == 1 and "PDController.fmu" in err[0] and "not an FMU ftcsim built" in err[0], err
    assert _tree(tmp_path) == before


def test_overwrite_of_a_folder_ftcsim_did_not_write(tmp_path, capsys):
    scen = write(tmp_path, variant({"stop = 200.0": "stop = 0.1"}))
    out = tmp_path / "theirs"
    out.mkdir()
    (out / "results.parquet").write_text("not ours")
    before = _tree(tmp_path)
    rc, err = _cli(["run", str(scen), "--mode", "inprocess", "-o", str(out), "--overwrite", "--quiet"], capsys)
    assert rc == 2 and len(err) == 1 and "was not written by ftcsim" in err[0], err
    assert _tree(tmp_path) == before
