"""The native export library every FMU carries: ours ("ftcsim", built from source here) or pythonfmu's ("stock").

A pythonfmu(3) FMU's binary (``binaries/<platform>/<model>.so``) is a native library that embeds
Python and drives the FMU's Python slave class. pythonfmu 0.7.0's and pythonfmu3 0.3.4's own
``libpythonfmu-export.so`` crash their host when anything goes wrong inside the FMU: a NULL
instance after a failed instantiation, calls after a Python exception (which freed the
instance), resource URIs with any percent-escape but ``%20``, a static pointer released twice at
exit (fmus/native/README.md). The ``ftcsim`` variant is this project's own library,
``fmus/native/ftcsim_export/`` (C: ``core.c`` with the front end ``fmi2.c`` or ``fmi3.c``),
compiled here with the machine's C compiler (``cc``, or ``CC``) against the Python headers and the
FMI 2.0 / 3.0 headers fmpy ships, and cached in ``build/native`` (key: sources, flags, compiler,
Python and FMI headers). It drives the same Python-side protocol as pythonfmu's library, so the
FMUs' Python side is unchanged, and it keeps the FMI state machine: NULL and freed instances
refused, every Python exception a status with a logged message, every call after an error
refused with the error's message, resource URIs decoded (RFC 3986), no double release.

Only the Linux x86_64 library is ours; an FMU's Windows DLL stays the package's. ``stock`` keeps
pythonfmu's library unchanged (``ftcsim build --export-library stock``), for comparison.
"""
from __future__ import annotations

import fcntl
import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NATIVE = Path(__file__).resolve().parent / "native"
SOURCES = NATIVE / "ftcsim_export"
VARIANTS = ("ftcsim", "stock")
DEFAULT = "ftcsim"

# what each FMI version compiles (the core and its front end) and the headers it needs from fmpy
FRONT_ENDS = {"2": ("core.c", "fmi2.c"), "3": ("core.c", "fmi3.c")}
FMI_HEADERS = {"2": ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
               "3": ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
# C11, a shared library exporting only the fmi* functions, libpython not linked (the host provides it,
# as for pythonfmu's library: `ftcsim host-env`)
FLAGS = ("-O2", "-fPIC", "-shared", "-std=c11", "-D_GNU_SOURCE", "-fvisibility=hidden", "-pthread", "-Wall")
LIBRARY_NAME = "libftcsim-export.so"


class ExportLibraryError(RuntimeError):
    """Our export library cannot be made here: names what is missing and the way out."""


# where each package keeps its Linux x86_64 library, and where an FMU carries it
_PACKAGE_BINARY = {"2": ("pythonfmu", "linux64"), "3": ("pythonfmu3", "x86_64-linux")}


@dataclass(frozen=True)
class ExportLibrary:
    """One Linux x86_64 export library for FMI version ``fmi``: ``path`` (a file to copy into
    ``binaries/<platform>/<model>.so``), its ``sha256``, the ``variant`` and where it comes from."""

    fmi: str
    variant: str
    path: Path
    sha256: str
    origin: str
    fixes: tuple = ()

    @property
    def platform_folder(self) -> str:
        return _PACKAGE_BINARY[self.fmi][1]

    def record(self) -> dict:
        """What ``resources/ftcsim_build.json`` says about the FMU's binary."""
        return {"variant": self.variant, "platform": self.platform_folder, "sha256": self.sha256,
                "origin": self.origin, "fixes": list(self.fixes),
                "other_platforms": "the package's own binaries, unchanged"}


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _package_folder(package: str) -> Path:
    import importlib.util

    spec = importlib.util.find_spec(package)
    if spec is None or not spec.submodule_search_locations:
        raise ExportLibraryError(f"{package} is not installed (pip install -e .)")
    return Path(next(iter(spec.submodule_search_locations)))


def stock_library_path(fmi: str) -> Path:
    """The Linux x86_64 library that pythonfmu (``fmi`` "2") or pythonfmu3 ("3") ships."""
    package, folder = _PACKAGE_BINARY[fmi]
    return _package_folder(package) / "resources" / "binaries" / folder / "libpythonfmu-export.so"


def cache_folder() -> Path:
    """``build/native`` of the project when writable, else ``native`` in ftcsim's user cache folder
    (platformdirs: ``$XDG_CACHE_HOME/ftcsim/native`` or ``~/.cache/ftcsim/native`` on Linux)."""
    import platformdirs

    for folder in (ROOT / "build" / "native", Path(platformdirs.user_cache_dir("ftcsim", appauthor=False)) / "native"):
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError:
            continue
        if os.access(folder, os.W_OK | os.X_OK):
            return folder
    raise ExportLibraryError("no writable folder for the export library cache (build/native, ~/.cache/ftcsim)")


@contextmanager
def _locked(folder: Path, name: str):
    """One process at a time makes a library (``make -j`` builds FMI 2 and 3 side by side)."""
    with open(folder / f".{name}.lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        yield


def _publish(data: bytes, target: Path) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    staged = target.with_name(f".{target.name}.partial")
    staged.write_bytes(data)
    os.replace(staged, target)


def _check_platform() -> None:
    if sys.platform != "linux" or platform.machine() not in ("x86_64", "AMD64"):
        raise ExportLibraryError(f"ftcsim's export library is built for Linux x86_64 only (this is {sys.platform} "
                                 f"{platform.machine()}); build with --export-library stock")


# -- ours: compiled from fmus/native/ftcsim_export ------------------------------------------------
def _compiler() -> str:
    """The C compiler: ``CC`` if set, else ``cc``, ``gcc``, ``clang``."""
    wanted = os.environ.get("CC")
    for name in ([wanted] if wanted else ["cc", "gcc", "clang"]):
        found = shutil.which(name)
        if found:
            return found
    raise ExportLibraryError(f"building ftcsim's export library needs a C compiler ({wanted or 'cc, gcc or clang'} "
                             "not found; Debian: apt install gcc python3-dev; or set CC), or build with "
                             "--export-library stock (pythonfmu's own library, which crashes its host on errors)")


def _compiler_id(cc: str) -> str:
    out = subprocess.run([cc, "--version"], capture_output=True, text=True)
    return (out.stdout.splitlines() or ["?"])[0]


def python_include() -> Path:
    include = Path(sysconfig.get_paths()["include"])
    if not (include / "Python.h").is_file():
        raise ExportLibraryError(f"no Python.h in {include}: the Python headers are needed to build ftcsim's export "
                                 "library (Debian: apt install python3-dev; or --export-library stock)")
    return include


def fmi_include(fmi: str) -> Path:
    """fmpy's copy of the FMI 2.0 / 3.0 headers (``fmpy/c-code``)."""
    folder = _package_folder("fmpy") / "c-code"
    missing = [h for h in FMI_HEADERS[fmi] if not (folder / h).is_file()]
    if missing:
        raise ExportLibraryError(f"fmpy's FMI headers {missing} are missing in {folder} (pip install fmpy)")
    return folder


def _key(fmi: str, cc: str, include: Path, headers: Path) -> str:
    h = hashlib.sha256()
    parts = [fmi.encode(), " ".join(FLAGS).encode(), _compiler_id(cc).encode(), str(include).encode(),
             (include / "patchlevel.h").read_bytes()]
    parts += [(SOURCES / f).read_bytes() for f in sorted(p.name for p in SOURCES.iterdir() if p.suffix in (".c", ".h"))]
    parts += [(headers / f).read_bytes() for f in FMI_HEADERS[fmi]]
    for part in parts:
        h.update(hashlib.sha256(part).digest())
    return h.hexdigest()[:16]


def defined_functions(library: Path) -> set:
    """Names of the functions ``library`` exports (``nm -D --defined-only``)."""
    nm = shutil.which("nm")
    if nm is None:
        raise ExportLibraryError("checking the export library needs nm (Debian: apt install binutils)")
    out = subprocess.run([nm, "-D", "--defined-only", str(library)], capture_output=True, text=True, check=True)
    return {parts[2] for parts in (line.split() for line in out.stdout.splitlines()) if len(parts) == 3 and parts[1] == "T"}


FIXES = ("every entry point refuses a NULL or freed instance with an error status",
         "the FMI state machine: a call out of order is an error; after an error only reset, set/free FMU state, "
         "debug logging and free instance are served, after a fatal error only free instance; each refusal is logged",
         "every Python exception becomes a status with a logged category and message (never a crash)",
         "resource URIs decoded per RFC 3986 (file:/, file:///, file://localhost/, any percent-escape)",
         "warnings and errors are logged whatever loggingOn says; FMI 2 messages have their '%' escaped",
         "no library destructor touches Python; the interpreter is never finalised; C memory released once at unload")


def ftcsim_library(fmi: str) -> ExportLibrary:
    """Our export library for FMI version ``fmi``, compiled once per sources, flags, compiler and
    headers, then read from the cache (``build/native/ftcsim-export-fmi<v>-<key>/``)."""
    _check_platform()
    cc = _compiler()
    include = python_include()
    headers = fmi_include(fmi)
    folder = cache_folder()
    target = folder / f"ftcsim-export-fmi{fmi}-{_key(fmi, cc, include, headers)}" / LIBRARY_NAME
    with _locked(folder, f"ftcsim-export-fmi{fmi}"):
        if not target.is_file():
            _compile(fmi, cc, include, headers, target)
    return ExportLibrary(fmi, "ftcsim", target, _sha256(target.read_bytes()),
                         f"ftcsim's export library (fmus/native/ftcsim_export: {' + '.join(FRONT_ENDS[fmi])}) "
                         f"compiled with {_compiler_id(cc)}", FIXES)


def _compile(fmi: str, cc: str, include: Path, headers: Path, target: Path) -> None:
    with tempfile.TemporaryDirectory(prefix="ftcsim_export_") as tmp:
        out = Path(tmp) / LIBRARY_NAME
        cmd = [cc, *FLAGS, f"-I{include}", f"-I{headers}", *(str(SOURCES / f) for f in FRONT_ENDS[fmi]), "-o", str(out)]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            raise ExportLibraryError(f"compiling ftcsim's FMI {fmi} export library failed: {done.stderr.strip()[-2000:]}")
        prefix = f"fmi{fmi}"
        stock = {f for f in defined_functions(stock_library_path(fmi)) if f.startswith(prefix)}
        ours = defined_functions(out)
        if stock - ours or {f for f in ours if not f.startswith(prefix)}:
            raise ExportLibraryError(f"the FMI {fmi} export library exports {sorted(ours ^ stock)[:8]} differently "
                                     "from pythonfmu's")
        _publish(out.read_bytes(), target)
        (target.parent / "build.json").write_text(json.dumps(
            {"command": [Path(c).name if i == 0 else c for i, c in enumerate(cmd)], "compiler": _compiler_id(cc),
             "python_include": str(include), "sha256": _sha256(out.read_bytes())}, indent=2) + "\n")


# -- what an extracted FMU carries ----------------------------------------------------------------
def exit_safe(folder) -> bool:
    """False if the FMU extracted in ``folder`` is a pythonfmu FMU (``resources/slavemodule.txt``)
    whose Linux binary is not our export library: its ``ftcsim_build.json`` must name the
    ``ftcsim`` variant and the binary must have the SHA-256 recorded there. Other FMUs (C code,
    other exporters) are not concerned."""
    folder = Path(folder)
    resources = folder / "resources"
    if not (resources / "slavemodule.txt").is_file():
        return True
    try:
        record = json.loads((resources / "ftcsim_build.json").read_text()).get("export_library") or {}
        binaries = list((folder / "binaries" / str(record.get("platform", ""))).glob("*.so"))
        return (record.get("variant") == "ftcsim" and len(binaries) == 1
                and _sha256(binaries[0].read_bytes()) == record.get("sha256"))
    except (OSError, ValueError, AttributeError):
        return False


# -- the choice ---------------------------------------------------------------------------------
def stock(fmi: str) -> ExportLibrary:
    path = stock_library_path(fmi)
    package = _PACKAGE_BINARY[fmi][0]
    return ExportLibrary(fmi, "stock", path, _sha256(path.read_bytes()), f"{package}'s own libpythonfmu-export.so")


def export_library(fmi: str, variant: str = DEFAULT) -> ExportLibrary:
    """The Linux x86_64 library the FMUs of FMI version ``fmi`` ("2" / "3") carry."""
    if variant not in VARIANTS:
        raise ExportLibraryError(f"export library {variant!r}: expected one of {', '.join(VARIANTS)}")
    if variant == "stock":
        return stock(fmi)
    return ftcsim_library(fmi)


if __name__ == "__main__":  # pragma: no cover
    for v in sys.argv[1:] or ["2", "3"]:
        lib = export_library(v)
        print(v, lib.path, lib.sha256)
