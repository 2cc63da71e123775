"""Building an FMU in a process that has already run one of our FMUs (a notebook, a test worker).
An FMU whose code differs from the installed one runs its own copy (fmus/embedded.py), and the
pythonfmu it imports first is its embedded copy, which then stands for the package and has no
native binaries: the build must still produce a complete FMU. (An FMU with the installed code
uses the installed pythonfmu.)"""
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

CODE = textwrap.dedent("""
    import sys, zipfile
    from fmpy import simulate_fmu
    from papers.registry import fmu_specs  # the caller's catalog, read before any FMU runs here
    import importlib
    simulate_fmu(sys.argv[1], stop_time=0.02, output_interval=0.01)   # runs the FMU in this process
    builder = importlib.import_module(sys.argv[3] + ".builder")
    print("builder from", builder.__file__)
    from fmus.build import build_fmu
    out = build_fmu(fmu_specs()["PDController"], sys.argv[2], sys.argv[4])
    print(sorted(n for n in zipfile.ZipFile(out).namelist() if n.startswith("binaries/")), flush=True)
""")


@pytest.mark.fmu
def test_build_after_running_an_fmu_in_the_same_process(any_fmu_dir, tmp_path):
    fmi, folder = any_fmu_dir
    package = "pythonfmu" if fmi == "2" else "pythonfmu3"
    edited = tmp_path / "edited" / "PDController.fmu"  # another version of the code: run privately
    edited.parent.mkdir()
    with zipfile.ZipFile(folder / "PDController.fmu") as zin, zipfile.ZipFile(edited, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            zout.writestr(item, data + b"# edited\n" if item.filename == "resources/controller/pd.py" else data)
    done = subprocess.run([sys.executable, "-c", CODE, str(edited), str(tmp_path), package, fmi],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    lines = done.stdout.strip().splitlines()
    assert "resources" in lines[0], lines[0]  # the premise: the package is the FMU's copy now
    with zipfile.ZipFile(tmp_path / "PDController.fmu") as z:
        names = z.namelist()
    assert any(n.startswith("binaries/") and n.endswith(".so") for n in names), names
