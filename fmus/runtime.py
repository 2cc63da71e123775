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
import os
import platform
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OWN_PACKAGES = {"plant", "estimator", "controller", "fmus", "lmi", "papers", "orchestrator", "pythonfmu", "pythonfmu3"}

_PROBE = """
import sys, json, importlib
before = set(sys.modules)
for name in sys.argv[1:]:
    importlib.import_module(name)
new = sorted(set(sys.modules) - before)
files = [getattr(sys.modules[m], '__file__', None) for m in new]
optional = sorted({o for m in new for o in getattr(sys.modules[m], 'OPTIONAL_IMPORTS', ())})
print(json.dumps({"modules": new, "files": [f for f in files if f], "optional": optional}))
"""


def import_closure(*modules: str) -> tuple[list[Path], list[str]]:
    """What importing ``modules`` loads, in a fresh process: (the project's source files, relative
    to the project root, and the top-level third-party modules). The FMU build embeds exactly
    those project files (so an FMU carries only the modules it imports) and lists the
    third-party ones in requirements.txt, with those a project module declares in
    ``OPTIONAL_IMPORTS`` (used when present, such as numba for the kernels)."""
    # kernels off in the probe: numba's own imports (llvmlite, scipy if present) are not the
    # FMU's requirements; numba itself comes from plant/kernels' OPTIONAL_IMPORTS
    env = {**os.environ, "FTCSIM_KERNELS": "0"}
    out = subprocess.run([sys.executable, "-c", _PROBE, *modules], capture_output=True, text=True,
                         cwd=str(ROOT), check=True, env=env).stdout
    found = json.loads(out.strip().splitlines()[-1])
    project = set()
    for f in found["files"]:
        path = Path(f).resolve()
        if path.is_relative_to(ROOT) and ".venv" not in path.parts and path.suffix == ".py":
            rel = path.relative_to(ROOT)
            project.add(rel)
            for parent in rel.parents:  # every enclosing package's __init__.py
                if parent != Path(".") and (ROOT / parent / "__init__.py").is_file():
                    project.add(parent / "__init__.py")
    # packages a project module uses when present (its OPTIONAL_IMPORTS, e.g. numba for
    # plant/kernels): listed even if this build's Python lacks them or did not import them
    top = {m.split(".")[0] for m in found["modules"]} | set(found.get("optional", ()))
    third = sorted(m for m in top if m not in sys.stdlib_module_names and m not in OWN_PACKAGES
                   and not m.startswith("_"))
    return sorted(project), third


def imported_third_party(module: str) -> list[str]:
    """Top-level non-stdlib modules that importing ``module`` loads (fresh process)."""
    return import_closure(module)[1]


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


def requirements(third_party: list[str]) -> tuple[list[str], dict]:
    """(requirement lines, {distribution: installed version}) for the top-level modules
    ``third_party``; lower bounds from pyproject.toml where the project declares one."""
    dists = md.packages_distributions()
    bounds = _project_bounds()
    lines, versions = [], {}
    for mod in third_party:
        for dist in dists.get(mod, [mod]):
            try:
                versions[dist] = md.version(dist)
            except md.PackageNotFoundError:  # not installed here: only a declared (optional) dependency
                if dist.lower() in bounds:
                    lines.append(bounds[dist.lower()])
                continue
            lines.append(bounds.get(dist.lower(), f"{dist}>={versions[dist]}"))
    return sorted(set(lines)), versions


def build_info(model_name: str, third_party: list[str], fmi_version: str, builder: str) -> dict:
    reqs, versions = requirements(third_party)
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


def write_runtime_files(folder: Path, model_name: str, third_party: list[str], fmi_version: str,
                        builder: str) -> list[Path]:
    """Write requirements.txt and ftcsim_build.json into ``folder`` (a build staging area;
    pythonfmu copies project files into the FMU's resources/). Returns the two paths."""
    info = build_info(model_name, third_party, fmi_version, builder)
    req = folder / "requirements.txt"
    req.write_text("".join(f"{r}\n" for r in info["requirements"]))
    meta = folder / "ftcsim_build.json"
    meta.write_text(json.dumps(info, indent=2) + "\n")
    return [req, meta]


def generation_tool(original: str | None) -> str:
    return f"ftcsim build, Python {platform.python_version()} ({original})"
