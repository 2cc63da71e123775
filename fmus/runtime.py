"""What an FMU needs from the host's Python, written into the FMU at build time.

pythonfmu FMUs run their Python code in the host's interpreter (the one the host
process embeds or loads with LD_PRELOAD / python3.dll). The build embeds our packages
and pythonfmu itself, but not third-party packages (numpy): ``resources/requirements.txt``
lists them (pythonfmu's convention: ``pythonfmu deploy -f X.fmu`` pip-installs it), and
``resources/ftcsim_build.json`` records the Python and package versions the FMU was
built and tested with. The same Python version is also written into the
modelDescription's ``generationTool``.
"""
from __future__ import annotations

import importlib.metadata as md
import json
import platform
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OWN_PACKAGES = {"plant", "estimator", "controller", "fmus", "lmi", "papers", "pythonfmu", "pythonfmu3"}

_PROBE = """
import sys, json, importlib
before = set(sys.modules)
importlib.import_module(sys.argv[1])
new = {m.split('.')[0] for m in set(sys.modules) - before}
print(json.dumps(sorted(new)))
"""


def imported_third_party(module: str) -> list[str]:
    """Top-level non-stdlib modules that importing ``module`` loads (fresh process)."""
    out = subprocess.run([sys.executable, "-c", _PROBE, module], capture_output=True, text=True,
                         cwd=str(ROOT), check=True).stdout
    mods = json.loads(out.strip().splitlines()[-1])
    return sorted(m for m in mods if m not in sys.stdlib_module_names and m not in OWN_PACKAGES
                  and not m.startswith("_"))


def _project_bounds() -> dict:
    """distribution name -> requirement spec from pyproject.toml's dependencies."""
    try:
        deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    except (OSError, KeyError):
        return {}
    out = {}
    for d in deps:
        name = d.split(";")[0].strip()
        for sep in ("<", ">", "=", "!", "~", "[", " "):
            name = name.split(sep)[0]
        out[name.lower()] = d.strip()
    return out


def requirements(block_module: str) -> tuple[list[str], dict]:
    """(requirement lines, {distribution: installed version}) for an FMU whose block lives
    in ``block_module``; lower bounds from pyproject.toml where the project declares one."""
    dists = md.packages_distributions()
    bounds = _project_bounds()
    lines, versions = [], {}
    for mod in imported_third_party(block_module):
        for dist in dists.get(mod, [mod]):
            try:
                versions[dist] = md.version(dist)
            except md.PackageNotFoundError:
                continue
            lines.append(bounds.get(dist.lower(), f"{dist}>={versions[dist]}"))
    return sorted(set(lines)), versions


def build_info(model_name: str, block_module: str, fmi_version: str, builder: str) -> dict:
    reqs, versions = requirements(block_module)
    return {
        "model": model_name,
        "fmi_version": fmi_version,
        "built_with": builder,
        "python": platform.python_version(),
        "python_implementation": platform.python_implementation(),
        "platform": f"{sys.platform}-{platform.machine()}",
        "requirements": reqs,
        "versions_at_build": versions,
        "note": "The FMU runs in the host's Python: it must be CPython "
                f"{sys.version_info.major}.{sys.version_info.minor} with these packages importable.",
    }


def write_runtime_files(folder: Path, model_name: str, block_module: str, fmi_version: str, builder: str) -> list[Path]:
    """Write requirements.txt and ftcsim_build.json into ``folder`` (a build staging area;
    pythonfmu copies project files into the FMU's resources/). Returns the two paths."""
    info = build_info(model_name, block_module, fmi_version, builder)
    req = folder / "requirements.txt"
    req.write_text("".join(f"{r}\n" for r in info["requirements"]))
    meta = folder / "ftcsim_build.json"
    meta.write_text(json.dumps(info, indent=2) + "\n")
    return [req, meta]


def generation_tool(original: str | None) -> str:
    return f"ftcsim build, Python {platform.python_version()} ({original})"
