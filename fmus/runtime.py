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

import functools
import hashlib
import importlib.metadata as md
import json
import os
import platform
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OWN_PACKAGES = {"plant", "estimator", "controller", "diagnosis", "fmus", "lmi", "papers", "arena", "orchestrator", "pythonfmu",
                "pythonfmu3"}
# What a host process that runs our FMUs imports from its own installation before the first one
# loads (orchestrator/cosim/host.py): a pythonfmu FMU puts its resources folder first on sys.path,
# and a package of ours that an FMU embeds, first imported from there, would point into a temporary
# folder for the rest of the process. (lmi and orchestrator are never embedded.)
HOST_IMPORTS = ("arena", "controller", "diagnosis", "estimator", "fmus.adapter", "papers", "plant")

_PROBE = """
import sys, json, importlib
args = sys.argv[1:]
paths = args[:args.index("--")]
sys.path[0:0] = paths
before = set(sys.modules)
for name in args[args.index("--") + 1:]:
    importlib.import_module(name)
new = sorted(set(sys.modules) - before)
optional = sorted({o for m in new for o in getattr(sys.modules[m], "OPTIONAL_IMPORTS", ())})
print(json.dumps({"by_module": {m: getattr(sys.modules[m], '__file__', None) for m in new}, "optional": optional}))
"""


@functools.lru_cache(maxsize=1)
def installed_distributions() -> dict:
    """``importlib.metadata.packages_distributions()``, read once per process: it walks every
    installed distribution's file list (about 0.8 s here), and a build asks for it per FMU."""
    return md.packages_distributions()


def _probe_cache_file(modules) -> Path | None:
    """Where the probe of the project's ``modules`` is kept: the user's cache folder
    (``plant.jit.cache_root()``'s sibling ``embedding``), under a hash of the interpreter, the
    installed distributions (name, version), every source file of the project's packages and the
    modules; None if the project cannot be read. The FMI 2.0 and 3.0 builds of one source tree
    then probe each block once (0.23 s per FMU)."""
    from plant.jit import cache_root

    tree = _installation_digest()
    if tree is None:
        return None
    key = hashlib.sha256(json.dumps([tree, list(modules)]).encode()).hexdigest()
    return Path(cache_root()).parent / "embedding" / f"{key}.json"


def _installation_digest() -> str | None:
    """SHA-256 of the interpreter, the installed distributions, the project folder and its source
    files. The sources are stat-ed on every call (a few ms) and read again only when one changed, so
    a block edited in a long-lived process (a notebook) is probed again on its next build."""
    try:
        files = sorted(f for d in sorted(OWN_PACKAGES - {"pythonfmu", "pythonfmu3"}) for f in (ROOT / d).rglob("*.py"))
        stats = tuple((str(f.relative_to(ROOT)), st.st_mtime_ns, st.st_size) for f in files for st in (f.stat(),))
    except OSError:
        return None
    return _sources_digest(stats)


@functools.lru_cache(maxsize=8)
def _sources_digest(stats: tuple) -> str | None:
    h = hashlib.sha256(json.dumps([sys.executable, sys.version, str(ROOT)]).encode())
    # the distributions as this process found them (installed_distributions() is read once per process)
    h.update(json.dumps(sorted(f"{d}=={md.version(d)}" for ds in installed_distributions().values() for d in ds)).encode())
    try:
        for rel, _, _ in stats:
            h.update(rel.encode() + b"\0" + (ROOT / rel).read_bytes() + b"\0")
    except OSError:
        return None
    return h.hexdigest()


def _cached_probe(modules):
    path = _probe_cache_file(modules)
    try:
        found = json.loads(path.read_text(encoding="utf-8")) if path is not None else None
    except (OSError, ValueError):
        return None
    # anything else than what _PROBE prints (a damaged or edited entry): probed again
    ok = (isinstance(found, dict) and isinstance(found.get("by_module"), dict) and isinstance(found.get("optional"), list)
          and all(isinstance(k, str) and (v is None or isinstance(v, str)) for k, v in found["by_module"].items())
          and all(isinstance(o, str) for o in found["optional"]))
    return found if ok else None


def _keep_probe(modules, found) -> None:
    path = _probe_cache_file(modules)
    if path is None:
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(found), encoding="utf-8")
        os.replace(tmp, path)
    except OSError:  # an unwritable cache: the next build probes again
        pass


@dataclass
class Embedding:
    """What an FMU built from some modules must carry, from importing them in a fresh process."""

    project: list  # source files of the project, relative to the project root
    user: list  # (absolute source file, path below resources/, module name) of the block's own code
    third_party: list  # top-level modules of installed distributions (requirements.txt)
    problems: list  # what can be neither embedded nor required (empty: buildable)


def system_folders() -> set:
    """The Python installation's folders: the standard library and every site-packages."""
    import site
    import sysconfig

    paths = sysconfig.get_paths()
    folders = {paths[k] for k in ("stdlib", "platstdlib", "purelib", "platlib") if k in paths}
    folders.update(site.getsitepackages())
    folders.add(site.getusersitepackages())
    return {Path(f).resolve() for f in folders}


def _relative_to_module(name: str, path: Path):
    """(root, relative file) of a module file found on sys.path as ``name`` (``a.b`` ->
    ``a/b.py`` or ``a/b/__init__.py``), or None when the file does not follow its name."""
    parts = name.split(".")
    rel = Path(*parts, "__init__" + path.suffix) if path.stem == "__init__" else Path(*parts[:-1], parts[-1] + path.suffix)
    if path.parts[-len(rel.parts):] != rel.parts:
        return None
    return Path(*path.parts[: -len(rel.parts)]), rel


def embedding(*modules: str, user_paths=(), user_packages=()) -> Embedding:
    """Import ``modules`` in a fresh process (``user_paths`` first on its sys.path) and sort what
    it loaded: the project's files (under the project root), the user's own code (modules found
    in one of ``user_paths``, or belonging to a top-level package of ``user_packages``, wherever
    that lives, e.g. an installed package of the user's), the standard library and pythonfmu
    (never embedded), and installed third-party distributions (listed in requirements.txt,
    never embedded). Anything else is a problem: a compiled module of the user's, a module from
    a folder that is neither the project nor a user path and no distribution's, a user package
    named like a project package."""
    user_paths = [Path(p).resolve() for p in user_paths]
    system = system_folders()
    problems = [f"{p} is a folder of the Python installation (standard library or site-packages): its modules are "
                "never embedded; give the folder of the block's own code" for p in user_paths if p in system]
    if problems:
        return Embedding([], [], [], problems)
    # kernels off in the probe: numba's own imports (llvmlite, scipy if present) are not the
    # FMU's requirements; numba itself comes from plant/kernels' OPTIONAL_IMPORTS
    found = None if user_paths else _cached_probe(modules)
    if found is None:
        env = {**os.environ, "FTCSIM_KERNELS": "0"}
        out = subprocess.run([sys.executable, "-c", _PROBE, *map(str, user_paths), "--", *modules],
                             capture_output=True, text=True, cwd=str(ROOT), env=env)
        if out.returncode != 0:
            last = (out.stderr.strip().splitlines() or ["(no message)"])[-1]
            raise ImportError(f"importing {', '.join(modules)} in a fresh Python failed: {last}")
        found = json.loads(out.stdout.strip().splitlines()[-1])
        if not user_paths:
            _keep_probe(modules, found)
    dists = installed_distributions()
    project, user, third = set(), [], set()
    for name, file in sorted(found["by_module"].items()):
        top = name.split(".")[0]
        if file is None:  # namespace packages, built-ins
            if top in dists and top not in user_packages and top not in OWN_PACKAGES:
                third.add(top)
            continue
        path = Path(file).resolve()
        where = _relative_to_module(name, path)
        root = where[0] if where else None
        if root == ROOT:
            if path.suffix == ".py":
                project.add(where[1])
            continue
        mine = top in user_packages or (root is not None and root in user_paths)
        if mine and top not in sys.stdlib_module_names:
            if top in OWN_PACKAGES or top == "ftcsim":
                problems.append(f"module {name} ({path}) has the name of one of ftcsim's packages ({top}); rename it")
            elif path.suffix != ".py" or where is None:
                problems.append(f"module {name} ({path}) is not a plain Python source file: it cannot be embedded in "
                                "the FMU (only .py modules can)")
            else:
                user.append((path, where[1], name))
            continue
        if top in sys.stdlib_module_names or top in OWN_PACKAGES or top.startswith("_"):
            continue
        if top in dists:
            third.add(top)
        else:
            problems.append(f"module {name} ({path}) is imported by the block but is neither in the project, nor in "
                            "the block's package or folder, nor in an installed distribution: it can be neither "
                            "embedded nor listed in requirements.txt (add its folder with --path, or install it)")
    # packages a project module uses when present (its OPTIONAL_IMPORTS, e.g. numba for
    # plant/kernels): listed even if this build's Python lacks them or did not import them
    third.update(found.get("optional", ()))
    return Embedding(sorted(project), sorted(user, key=lambda x: str(x[1])), sorted(third), problems)


def import_closure(*modules: str) -> tuple[list[Path], list[str]]:
    """What importing ``modules`` loads, in a fresh process: (the project's source files, relative
    to the project root, and the top-level third-party modules). The FMU build embeds exactly
    those project files (so an FMU carries only the modules it imports) and lists the
    third-party ones in requirements.txt, with those a project module declares in
    ``OPTIONAL_IMPORTS`` (used when present, such as numba for the kernels)."""
    e = embedding(*modules)
    return e.project, e.third_party


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
    dists = installed_distributions()
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


def build_info(model_name: str, third_party: list[str], fmi_version: str, builder: str, extra=None) -> dict:
    reqs, versions = requirements(third_party)
    return {**(extra or {}),
        "model": model_name,
        "fmi_version": fmi_version,
        "built_with": builder,
        "python": platform.python_version(),
        "python_implementation": platform.python_implementation(),
        "platform": f"{sys.platform}-{platform.machine()}",
        "requirements": reqs,
        "versions_at_build": versions,
        "start_values": "modelDescription",  # fmus/configure.py: it starts from its modelDescription's start values
        "note": "The FMU runs in the host's Python: it must be CPython "
                f"{sys.version_info.major}.{sys.version_info.minor} with these packages importable.",
    }


def write_runtime_files(folder: Path, model_name: str, third_party: list[str], fmi_version: str,
                        builder: str, extra: dict | None = None) -> list[Path]:
    """Write requirements.txt and ftcsim_build.json into ``folder`` (a build staging area;
    pythonfmu copies project files into the FMU's resources/). Returns the two paths."""
    info = build_info(model_name, third_party, fmi_version, builder, extra)
    req = folder / "requirements.txt"
    req.write_text("".join(f"{r}\n" for r in info["requirements"]))
    meta = folder / "ftcsim_build.json"
    meta.write_text(json.dumps(info, indent=2) + "\n")
    return [req, meta]


def generation_tool(original: str | None) -> str:
    return f"ftcsim build, Python {platform.python_version()} ({original})"
