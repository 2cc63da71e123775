"""Hostile FMUs, SSP packages, gains files and command lines: one clear line naming the file, the
key and the problem, exit status 2, nothing written and nothing extracted outside its folder."""
import json
import re
import zipfile
from pathlib import Path

import pytest
from scenario_text import PD, variant, write

from orchestrator.cli.main import main

SHORT = variant({"stop = 200.0": "stop = 0.5"})


def _run(argv, capsys):
    rc = main(argv)
    return rc, capsys.readouterr().err.strip().splitlines()


SLAVE_SCRIPT = "<the slave script>"  # for drop: the FMU's resources/<slavemodule.txt>.py


def _copy_fmu(src: Path, dst: Path, drop=(), add=(), rename=None) -> Path:
    """``src`` rewritten to ``dst`` without the members ``drop``, with extra members ``add``
    ((name, bytes) or ZipInfo pairs) and ``rename`` {old: new} applied to member names."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        script = f"resources/{zin.read('resources/slavemodule.txt').decode().strip()}.py"  # named after its code
        for item in zin.infolist():
            if item.filename in drop or (item.filename == script and SLAVE_SCRIPT in drop):
                continue
            zout.writestr((rename or {}).get(item.filename, item.filename), zin.read(item.filename))
        for name, data in add:
            zout.writestr(name, data)
    return dst


def _with_fmu(tmp_path, fmu: Path) -> Path:
    return write(tmp_path, SHORT.replace('fmu = "PDController"', f'fmu = "{fmu.as_posix()}"'))


def _symlink_entry(name, target):
    info = zipfile.ZipInfo(name)
    info.external_attr = (0o120777 << 16)
    return info, target


FMU_CASES = {
    "entry climbing out": (dict(add=[("../../evil.txt", b"x")]), "points outside the archive"),
    "absolute entry": (dict(add=[("/tmp/evil.txt", b"x")]), "points outside the archive"),
    "symbolic link entry": (dict(add=[_symlink_entry("resources/link", "/etc/passwd")]), "symbolic link"),
    "no binary for this platform": (dict(drop=["binaries/linux64/PDController.so"]), "no binary for this platform"),
    "no slave script": (dict(drop=[SLAVE_SCRIPT]), "slave script"),
}


@pytest.mark.parametrize("case", sorted(FMU_CASES))
def test_hostile_fmu_is_refused_before_loading(case, tmp_path, capsys, fmu_dir):
    kw, problem = FMU_CASES[case]
    bad = _copy_fmu(fmu_dir / "PDController.fmu", tmp_path / "Bad.fmu", **kw)
    scen = _with_fmu(tmp_path, bad)
    out = tmp_path / "out"
    rc, err = _run(["run", str(scen), "--out", str(out), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1, err
    assert f"{scen}: instances.ctrl.fmu:" in err[0] and problem in err[0], err[0]
    assert not out.exists() and not (tmp_path.parent / "evil.txt").exists()
    rc = main(["validate", str(bad)])  # validate does not call it valid either
    assert rc == 1 and problem in capsys.readouterr().out


def test_fmu_with_a_path_as_model_identifier_is_refused(tmp_path, capsys, fmu_dir):
    with zipfile.ZipFile(fmu_dir / "PDController.fmu") as z:
        xml = z.read("modelDescription.xml").decode()
    xml = xml.replace('modelIdentifier="PDController"', 'modelIdentifier="../../PDController"')
    bad = _copy_fmu(fmu_dir / "PDController.fmu", tmp_path / "Bad.fmu", drop=["modelDescription.xml"],
                    add=[("modelDescription.xml", xml.encode())])
    rc, err = _run(["run", str(_with_fmu(tmp_path, bad)), "--out", str(tmp_path / "o"), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1 and "not a plain name" in err[0]


# -- SSP packages ---------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def package(tmp_path_factory, fmu_dir):
    folder = tmp_path_factory.mktemp("ssp")
    scen = write(folder, SHORT)
    assert main(["export-ssp", str(scen), "--out", str(folder / "pd.ssp"), "--quiet"]) == 0
    return folder / "pd.ssp"


def _edit_ssp(src: Path, dst: Path, ssd=None, ssv=None, add=()):
    """Copy of package ``src`` with the SSD text transformed by ``ssd`` and every SSV by ``ssv``."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "SystemStructure.ssd" and ssd:
                data = ssd(data.decode()).encode()
            if item.filename.endswith(".ssv") and ssv:
                data = ssv(data.decode()).encode()
            zout.writestr(item, data)
        for name, data in add:
            zout.writestr(name, data)
    return dst


SSP_CASES = {
    "component source outside": (dict(ssd=lambda t: t.replace('source="resources/PDController.fmu"',
                                                               'source="../PDController.fmu"')), "outside the package"),
    "component source absolute": (dict(ssd=lambda t: t.replace('source="resources/PDController.fmu"',
                                                                'source="/tmp/PDController.fmu"')), "outside the package"),
    "NaN parameter in an SSV": (dict(ssv=lambda t: re.sub(r'value="[^"]+"', 'value="NaN"', t, count=1)), "must be finite"),
    "infinite stop time": (dict(ssd=lambda t: re.sub(r'stopTime="[^"]+"', 'stopTime="INF"', t)), "must be finite"),
    "zero step": (dict(ssd=lambda t: re.sub(r'baseStepSize="[^"]+"', 'baseStepSize="0.0"', t)), "baseStepSize"),
    "component name with a path": (dict(ssd=lambda t: t.replace('name="ctrl"', 'name="../ctrl"')), "identifier"),
    "entry climbing out": (dict(add=[("../../evil.ssv", b"<x/>")]), "points outside the archive"),
}


@pytest.mark.parametrize("case", sorted(SSP_CASES))
def test_hostile_ssp_is_refused(case, tmp_path, capsys, package):
    kw, problem = SSP_CASES[case]
    bad = _edit_ssp(package, tmp_path / "bad.ssp", **kw)
    out = tmp_path / "out"
    rc, err = _run(["run", str(bad), "--out", str(out), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1, err
    assert err[0].startswith(f"ftcsim: error: {bad}:") and problem in err[0], err[0]
    assert not out.exists() and not (tmp_path.parent / "evil.ssv").exists()


# -- gains files and design inputs ----------------------------------------------------------------
def _gains(tmp_path, data) -> Path:
    p = tmp_path / "gains.json"
    p.write_text(data if isinstance(data, str) else json.dumps(data))
    return p


GAINS_CASES = {
    "boolean gain": ({"design": "x", "fmu_parameters": {"PDController": {"k_p": True}}},
                     "fmu_parameters.PDController.k_p", "expected a number"),
    "key typo": ({"fmu_parameter": {"PDController": {"k_p": 1.0}}}, "fmu_parameters", "typo"),
    "NaN (not strict JSON)": ('{"fmu_parameters": {"PDController": {"k_p": NaN}}}', "-", "strict JSON"),
    "unknown parameter": ({"fmu_parameters": {"PDController": {"k_pp": 1.0}}}, "fmu_parameters.PDController.k_pp",
                          "no parameter"),
    "no model of the scenario": ({"fmu_parameters": {"FASMC": {"beta": 1.0}}}, "fmu_parameters", "no instance"),
    "not an object": ("[1, 2]", "-", "JSON object"),
}


@pytest.mark.parametrize("case", sorted(GAINS_CASES))
def test_bad_gains_file(case, tmp_path, capsys, fmu_dir):
    data, key, problem = GAINS_CASES[case]
    g = _gains(tmp_path, data)
    rc, err = _run(["run", str(write(tmp_path, SHORT)), "--gains", str(g), "--out", str(tmp_path / "o"), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1 and err[0].startswith(f"ftcsim: error: {g}: {key}:") and problem in err[0], err


def test_gains_directory_and_non_utf8(tmp_path, capsys, fmu_dir):
    scen = write(tmp_path, SHORT)
    rc, err = _run(["run", str(scen), "--gains", str(tmp_path), "--out", str(tmp_path / "o"), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1 and "is a directory" in err[0]
    bad = tmp_path / "latin1.json"
    bad.write_bytes('{"fmu_parameters": {"PDController": {"k_p": 1.0}}, "note": "Müller"}'.encode("latin-1"))
    rc, err = _run(["run", str(scen), "--gains", str(bad), "--out", str(tmp_path / "o"), "--quiet"], capsys)
    assert rc == 2 and len(err) == 1 and "not UTF-8" in err[0]
    assert not (tmp_path / "o").exists()


DESIGN_ARGS = {
    "phi NaN": (["design", "li2023-observer", "--phi", "nan", "--out", "X"], "--phi", "finite"),
    "negative radius": (["design", "li2023-observer", "--eps", "-1", "--out", "X"], "--eps", "positive"),
    "option of another design": (["design", "li2023-observer", "--alpha", "1", "--out", "X"], "--alpha", "does not apply"),
    "design name typo": (["design", "li2023-observr", "--out", "X"], "NAME", "did you mean 'li2023-observer'"),
    "out is a directory": (["design", "li2023-observer", "--out", "."], "--out", "is a directory"),
    "effectiveness above 1": (["design", "zhang2014-hinf", "--omega-hat", "1.5", "--out", "X"], "--omega-hat", "in (0, 1]"),
}


@pytest.mark.parametrize("case", sorted(DESIGN_ARGS))
def test_bad_design_arguments(case, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv, key, problem = DESIGN_ARGS[case]
    rc, err = _run(argv, capsys)
    assert rc == 2 and len(err) == 1 and f"command line: {key}:" in err[0] and problem in err[0], err
    assert not (tmp_path / "X").exists()


def test_verify_refuses_booleans_and_foreign_files(tmp_path, capsys):
    g = _gains(tmp_path, {"design": "hang2023-tsfdo", "gains": {"L1": [[True, 0.0], [0.0, 1.0]]}})
    rc, err = _run(["verify", "hang2023-tsfdo", "--gains", str(g)], capsys)
    assert rc == 2 and len(err) == 1 and f"{g}: gains.L1:" in err[0] and "numbers only" in err[0]
    g = _gains(tmp_path, {"design": "li2023-observer", "gains": {}})
    rc, err = _run(["verify", "hang2023-tsfdo", "--gains", str(g)], capsys)
    assert rc == 2 and "file is for 'li2023-observer'" in err[0]


CLI_CASES = {
    "unknown scenario name": (["run", "li2023_pdd"], "SCENARIO", "did you mean 'li2023_pd'"),
    "step NaN": (["run", "li2023_pd", "--step", "nan"], "--step", "finite"),
    "negative step": (["run", "li2023_pd", "--step", "-0.01"], "--step", "finite number > 0"),
    "unknown FMU to build": (["build", "NoSuchFMU", "--out", "unused"], "build", "unknown FMU"),
    "unknown option": (["run", "li2023_pd", "--stepp", "0.1"], "command line", "unrecognized arguments"),
}


@pytest.mark.parametrize("case", sorted(CLI_CASES))
def test_bad_command_line(case, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv, key, problem = CLI_CASES[case]
    try:
        rc = main(argv)
    except SystemExit as e:  # argparse's own errors
        rc = e.code
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and key in err[0] and problem in err[0], err
    assert list(tmp_path.iterdir()) == []


# -- reports ---------------------------------------------------------------------------------------
def test_report_refuses_malformed_folders_and_foreign_out(tmp_path, capsys):
    empty = tmp_path / "empty"
    empty.mkdir()
    rc, err = _run(["report", str(empty), "--out", str(tmp_path / "rep")], capsys)
    assert rc == 2 and len(err) == 1 and "results.csv" in err[0] and "not a result folder" in err[0]
    broken = tmp_path / "broken"
    broken.mkdir()
    (broken / "results.csv").write_text("time,a\n0,1\n")
    (broken / "metrics.json").write_text("{not json")
    rc, err = _run(["report", str(broken), "--out", str(tmp_path / "rep")], capsys)
    assert rc == 2 and "metrics.json" in err[0] and "not valid JSON" in err[0]
    (broken / "metrics.json").write_text("{}")
    (broken / "results.csv").write_text("time,a\n0,x\n")
    rc, err = _run(["report", str(broken), "--out", str(tmp_path / "rep")], capsys)
    assert rc == 2 and "results.csv" in err[0] and "unreadable" in err[0]
    assert not (tmp_path / "rep").exists()


def test_deep_extends_chain_and_deep_nesting_are_refused(tmp_path, capsys):
    for k in range(12):
        nxt = f'extends = "s{k + 1}.toml"\n' if k < 11 else ""
        (tmp_path / f"s{k}.toml").write_text(f'[scenario]\nname = "s{k}"\n{nxt}')
    rc, err = _run(["run", str(tmp_path / "s0.toml"), "--out", str(tmp_path / "o")], capsys)
    assert rc == 2 and len(err) == 1 and "scenario.extends" in err[0] and "deeper than" in err[0]
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * 5000 + "]" * 5000 + "\n")
    rc, err = _run(["run", str(deep), "--out", str(tmp_path / "o")], capsys)
    assert rc == 2 and len(err) == 1 and str(deep) in err[0]
    bad = tmp_path / "latin1.toml"
    bad.write_bytes(PD.replace("Flexible spacecraft", "Flexibles Raumfahrzeug für").encode("latin-1"))
    rc, err = _run(["run", str(bad), "--out", str(tmp_path / "o")], capsys)
    assert rc == 2 and "not UTF-8" in err[0]
    rc, err = _run(["run", str(tmp_path), "--out", str(tmp_path / "o")], capsys)
    assert rc == 2 and "is a directory" in err[0]
    assert not (tmp_path / "o").exists()
