"""Issue 37: ftcsim's export library is compiled here, once, and says what is missing.

fmus/export_library.py compiles fmus/native/ftcsim_export (core.c + fmi2.c / fmi3.c) with the
machine's C compiler and caches it; the library exports every fmiN function of pythonfmu's own
(and FMI 2's model-exchange functions, refused) and nothing else; without a compiler ``ftcsim
build`` stops with one line naming the way out."""
import pytest

from fmus.export_library import defined_functions, export_library, stock_library_path

pytestmark = [pytest.mark.fmu]


@pytest.mark.parametrize("fmi", ["2", "3"])
def test_the_library_exports_what_pythonfmus_does_and_is_cached(fmi):
    lib = export_library(fmi)
    ours = defined_functions(lib.path)
    stock = {f for f in defined_functions(stock_library_path(fmi)) if f.startswith(f"fmi{fmi}")}
    assert stock <= ours and all(f.startswith(f"fmi{fmi}") for f in ours)
    extra = ours - stock
    assert extra == (set() if fmi == "3" else {
        "fmi2EnterEventMode", "fmi2NewDiscreteStates", "fmi2EnterContinuousTimeMode", "fmi2CompletedIntegratorStep",
        "fmi2SetTime", "fmi2SetContinuousStates", "fmi2GetDerivatives", "fmi2GetEventIndicators",
        "fmi2GetContinuousStates", "fmi2GetNominalsOfContinuousStates"})
    built = lib.path.stat().st_mtime_ns
    again = export_library(fmi)
    assert again.path == lib.path and again.sha256 == lib.sha256 and lib.path.stat().st_mtime_ns == built
    assert (lib.path.parent / "build.json").is_file()
    assert lib.record()["variant"] == "ftcsim"


def test_a_build_without_a_compiler_says_so_in_one_line(tmp_path, monkeypatch, capsys):
    from orchestrator.cli.main import main

    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    rc = main(["build", "PDController", "--out", str(tmp_path / "out")])
    lines = capsys.readouterr().err.strip().splitlines()
    assert rc == 1 and len(lines) == 1, lines
    assert "C compiler" in lines[0] and "apt install gcc python3-dev" in lines[0] and "--export-library stock" in lines[0]
    assert not (tmp_path / "out" / "PDController.fmu").exists()
