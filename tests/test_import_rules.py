"""The import rule (pyproject.toml: [tool.importlinter], run by `make lint`) holds for the project and
fails on a planted circle or an upward import, both written inside functions (where grimp, under
import-linter, still sees them). The plants go into a copy of the packages in a temporary folder."""
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("plant", "estimator", "controller", "diagnosis", "lmi", "fmus", "papers", "orchestrator", "ftcsim")
LINT = Path(sys.executable).parent / "lint-imports"

pytestmark = pytest.mark.skipif(not LINT.is_file(), reason="import-linter is not installed (a test extra)")


def _lint(folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(LINT), "--config", str(folder / "pyproject.toml"), "--no-cache"], cwd=folder,
                          capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def copy(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("project")
    for p in PACKAGES:
        shutil.copytree(ROOT / p, folder / p, ignore=shutil.ignore_patterns("__pycache__", "*.toml", "*.md", "*.npz"))
    shutil.copy(ROOT / "pyproject.toml", folder)
    return folder


def _plant(folder: Path, module: str, code: str) -> Path:
    path = folder / (module.replace(".", "/") + ".py")
    original = path.read_text()
    path.write_text(original + "\n\ndef _planted():\n" + "".join(f"    {line}\n" for line in code.splitlines()))
    return path, original


def test_the_project_keeps_the_import_rule():
    done = _lint(ROOT)
    assert done.returncode == 0, done.stdout[-3000:]
    assert "0 broken" in done.stdout


def test_a_planted_circle_inside_a_function_fails_the_rule(copy):
    assert _lint(copy).returncode == 0  # the copy itself is clean
    path, original = _plant(copy, "orchestrator.common.errors", "from orchestrator.common import jsonio  # jsonio imports errors")
    try:
        done = _lint(copy)
    finally:
        path.write_text(original)
    assert done.returncode != 0
    assert "no import circle among our modules BROKEN" in done.stdout, done.stdout[-3000:]
    assert "orchestrator.common.errors" in done.stdout and "orchestrator.common.jsonio" in done.stdout


def test_an_upward_import_inside_a_function_fails_the_rule(copy):
    path, original = _plant(copy, "plant.so3", "import orchestrator.api")
    try:
        done = _lint(copy)
    finally:
        path.write_text(original)
    assert done.returncode != 0
    assert "models, LMI and the FMI layer know no host and no paper BROKEN" in done.stdout, done.stdout[-3000:]
    assert "plant.so3 -> orchestrator.api" in done.stdout


def test_an_import_of_basilisk_below_the_bridge_fails_the_rule(copy):
    """bsk is an optional extra (issue 32): only orchestrator.interop.basilisk (and the faces above it) may
    import it; a plant importing it (inside a function) breaks the rule."""
    path, original = _plant(copy, "plant.so3", "import Basilisk.simulation.spacecraft")
    try:
        done = _lint(copy)
    finally:
        path.write_text(original)
    assert done.returncode != 0
    assert "bsk stays optional" in done.stdout and "BROKEN" in done.stdout, done.stdout[-3000:]
    assert "plant.so3 -> Basilisk" in done.stdout
