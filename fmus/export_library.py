"""The native export library every FMU carries: pythonfmu's stock one, or ours ("ftcsim").

A pythonfmu(3) FMU's binary (``binaries/<platform>/<model>.so``) is a copy of the package's
``libpythonfmu-export.so``. In pythonfmu 0.7.0 and pythonfmu3 0.3.4 (Linux) it keeps
``std::shared_ptr<PyState> pyState`` as a static and releases it twice when the process exits:
glibc runs the C++ static destructors (``__cxa_atexit``) before ``_dl_fini`` calls the library
destructor ``onLibraryUnload()``, whose ``pyState = nullptr`` releases the destroyed pointer
again, a write into freed memory after which hosts abort in their exit path (OMSimulator 8 of 8
runs with FMI 3 FMUs). The ``ftcsim`` variant removes that second release (the static destructor
is the one release, at exit and at ``dlclose``), and fixes what else crashes a host:

* **FMI 2.0, pythonfmu 0.7.0**: a verified binary correction of the ``.so`` PyPI ships
  (:data:`FMI2_CORRECTIONS`). Its sdist has no C++ sources and GitHub is not reachable from a
  fresh machine, so we change the shipped binary, byte for byte the same on every machine:
  the input's SHA-256, the bytes at each offset and the output's SHA-256 are checked. Two
  corrections: ``onLibraryUnload()`` returns at once (the double release), and the logger passes
  the (empty) category string instead of NULL (OMSimulator's logger threw
  ``basic_string: construction from null`` and aborted). Checks for a NULL instance cannot be
  added in place (no room in the binary): a host calling on after a failed ``fmi2Instantiate``
  still dereferences NULL; see fmus/native/README.md.
* **FMI 3.0, pythonfmu3 0.3.4**: rebuilt from the C++ sources in pythonfmu3's PyPI distribution
  (``pythonfmu3/pythonfmu-export``, SHA-256 of every file checked against
  ``fmus/native/pythonfmu3-0.3.4.sha256``) with ``fmus/native/pythonfmu3-0.3.4.patch``, compiled
  with the machine's C++ compiler (``g++``, ``CXX``) and cached in ``build/native``. Besides the
  double release: every function checks for a NULL instance, nothing is thrown through the C
  interface, a NULL log callback is allowed, and a Python exception releases the instance's
  objects once (they were released again by the destructor).

Only the Linux x86_64 library is corrected; an FMU's Windows DLL stays pythonfmu's (its exit
order differs). ``stock`` keeps pythonfmu's library unchanged (``ftcsim build --export-library stock``).
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
VARIANTS = ("ftcsim", "stock")
DEFAULT = "ftcsim"


class ExportLibraryError(RuntimeError):
    """The corrected library cannot be made here: names what is missing and the way out."""


@dataclass(frozen=True)
class Correction:
    """Bytes ``before`` at file ``offset`` become ``after``; ``why`` in one sentence."""

    offset: int
    before: bytes
    after: bytes
    why: str


# pythonfmu 0.7.0 (PyPI), resources/binaries/linux64/libpythonfmu-export.so
FMI2_STOCK_SHA256 = "4be156a552c16f30eb4395805c59855d8d4086056d0f165442565f6c5fbac0c9"
FMI2_CORRECTIONS = (
    # _ZN12_GLOBAL__N_115onLibraryUnloadEv at 0x16f30 (9 bytes): endbr64; jmp finalizePythonInterpreter@plt
    Correction(0x16F34, bytes.fromhex("e937dcffff"), bytes.fromhex("c30f1f4000"),
               "onLibraryUnload() returns at once (ret; nopl): the static shared_ptr<PyState> is released once, by "
               "its C++ static destructor, not again by the library destructor on the destroyed pointer"),
    # Fmi2Logger::debugLog at 0x17050: xor ecx,ecx; cmpq $0,8(rdx); ...; je +3; mov (rdx),rcx
    Correction(0x17068, bytes.fromhex("7403"), bytes.fromhex("6690"),
               "Fmi2Logger::debugLog passes category.c_str() (\"\" when empty) instead of NULL (je -> 2-byte nop)"),
    # gcc devirtualised debugLog at four call sites (compare the vtable slot with 0x17050, then an
    # inlined copy, which for PyLogger::log(status, message) passes a constant NULL category):
    # jne <the virtual call> becomes jmp, so every message goes through the corrected function
    *(Correction(at, bytes.fromhex("0f85") + rel.to_bytes(4, "little"), b"\xe9" + (rel + 1).to_bytes(4, "little") + b"\x90",
                 f"{where}: the logger call at 0x{at:x} always goes through Fmi2Logger::debugLog (jne -> jmp)")
      for at, rel, where in ((0x18480, 0x10A, "fmi2GetDirectionalDerivative"),
                             (0x187C9, 0x129, "fmi2SetRealInputDerivatives"),
                             (0x18AD0, 0x10A, "fmi2GetRealOutputDerivatives"),
                             (0x1C38C, 0x07E, "PyLogger::log(status, message), used by fmi2Instantiate's fatal error"))),
)
FMI2_CORRECTED_SHA256 = "78b6111fe7103f66056683b30f72f7a29a946386087c953be7ee07ca7634c2ea"

FMI3_VERSION = "0.3.4"
FMI3_PATCH = NATIVE / f"pythonfmu3-{FMI3_VERSION}.patch"
FMI3_SOURCES = NATIVE / f"pythonfmu3-{FMI3_VERSION}.sha256"
FMI3_COMPILE_UNITS = ("src/cppfmu/cppfmu_cs.cpp", "src/cppfmu/fmi_functions.cpp", "src/pythonfmu/PySlaveInstance.cpp")
# as pythonfmu3's CMakeLists.txt: C++17, a shared library, the stable Python ABI, libpython not linked
FMI3_FLAGS = ("-O2", "-fPIC", "-shared", "-std=c++17", "-DPy_LIMITED_API")

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
        raise ExportLibraryError(f"the corrected export library exists for Linux x86_64 only (this is {sys.platform} "
                                 f"{platform.machine()}); build with --export-library stock")


# -- FMI 2.0: the shipped binary, corrected ----------------------------------------------------
def corrected_fmi2_bytes(stock: bytes) -> bytes:
    """pythonfmu 0.7.0's library with :data:`FMI2_CORRECTIONS` applied, every step verified."""
    if _sha256(stock) != FMI2_STOCK_SHA256:
        raise ExportLibraryError(f"pythonfmu's libpythonfmu-export.so has SHA-256 {_sha256(stock)}, not pythonfmu "
                                 f"0.7.0's {FMI2_STOCK_SHA256}: the correction is for that file only (pip install "
                                 "pythonfmu==0.7.0, or build with --export-library stock)")
    data = bytearray(stock)
    for c in FMI2_CORRECTIONS:
        found = bytes(data[c.offset:c.offset + len(c.before)])
        if found != c.before or len(c.before) != len(c.after):
            raise ExportLibraryError(f"unexpected bytes {found.hex()} at 0x{c.offset:x}")  # unreachable after the hash
        data[c.offset:c.offset + len(c.after)] = c.after
    if _sha256(bytes(data)) != FMI2_CORRECTED_SHA256:
        raise ExportLibraryError(f"the corrected library has SHA-256 {_sha256(bytes(data))}, expected "
                                 f"{FMI2_CORRECTED_SHA256}")
    return bytes(data)


def corrected_fmi2() -> ExportLibrary:
    _check_platform()
    target = cache_folder() / f"pythonfmu-0.7.0-ftcsim-{FMI2_CORRECTED_SHA256[:12]}" / "libpythonfmu-export.so"
    if not (target.is_file() and _sha256(target.read_bytes()) == FMI2_CORRECTED_SHA256):
        _publish(corrected_fmi2_bytes(stock_library_path("2").read_bytes()), target)
    return ExportLibrary("2", "ftcsim", target, FMI2_CORRECTED_SHA256,
                         f"pythonfmu 0.7.0's libpythonfmu-export.so (SHA-256 {FMI2_STOCK_SHA256}) with "
                         f"{len(FMI2_CORRECTIONS)} byte corrections (fmus/export_library.py)",
                         tuple(c.why for c in FMI2_CORRECTIONS))


# -- FMI 3.0: rebuilt from pythonfmu3's sources with our patch ----------------------------------
def _expected_sources() -> dict:
    out = {}
    for line in FMI3_SOURCES.read_text().splitlines():
        if line.strip():
            digest, rel = line.split(maxsplit=1)
            out[rel.strip()] = digest
    return out


def fmi3_source_folder() -> Path:
    """pythonfmu3's ``pythonfmu-export`` folder, every file of it checked against its SHA-256."""
    folder = _package_folder("pythonfmu3") / "pythonfmu-export"
    for rel, digest in _expected_sources().items():
        f = folder / rel
        if not f.is_file():
            raise ExportLibraryError(f"{f} is missing: pythonfmu3 {FMI3_VERSION}'s export sources are needed to build "
                                     "the corrected FMI 3 library (pip install pythonfmu3==0.3.4, or --export-library stock)")
        if _sha256(f.read_bytes()) != digest:
            raise ExportLibraryError(f"{f} differs from pythonfmu3 {FMI3_VERSION}'s (SHA-256 {digest}): our patch is for "
                                     "that version (pip install pythonfmu3==0.3.4, or --export-library stock)")
    return folder


def _tool(name: str, env: str | None = None) -> str:
    exe = os.environ.get(env) if env else None
    found = shutil.which(exe or name)
    if found is None:
        raise ExportLibraryError(f"building the corrected FMI 3 export library needs {exe or name} (Debian: apt install "
                                 "g++ patch binutils; or build with --export-library stock)")
    return found


def _compiler_id(cxx: str) -> str:
    out = subprocess.run([cxx, "--version"], capture_output=True, text=True)
    return (out.stdout.splitlines() or ["?"])[0]


def _fmi3_key(cxx: str, include: Path) -> str:
    h = hashlib.sha256()
    for part in (FMI3_PATCH.read_bytes(), FMI3_SOURCES.read_bytes(), " ".join(FMI3_FLAGS).encode(),
                 _compiler_id(cxx).encode(), str(include).encode(), (include / "patchlevel.h").read_bytes()):
        h.update(hashlib.sha256(part).digest())
    return h.hexdigest()[:16]


def defined_functions(library: Path) -> set:
    """Names of the functions ``library`` exports (``nm -D --defined-only``)."""
    out = subprocess.run([_tool("nm"), "-D", "--defined-only", str(library)], capture_output=True, text=True, check=True)
    return {parts[2] for parts in (line.split() for line in out.stdout.splitlines()) if len(parts) == 3 and parts[1] == "T"}


def rebuilt_fmi3() -> ExportLibrary:
    """pythonfmu3's library rebuilt with our patch (compiled once per sources, patch, compiler and
    Python headers; then read from the cache)."""
    _check_platform()
    sources = fmi3_source_folder()
    cxx = _tool("g++", "CXX")
    include = Path(sysconfig.get_paths()["include"])
    if not (include / "Python.h").is_file():
        raise ExportLibraryError(f"no Python.h in {include}: the Python headers are needed to build the corrected FMI 3 "
                                 "export library (Debian: apt install python3-dev; or --export-library stock)")
    folder = cache_folder()
    target = folder / f"pythonfmu3-{FMI3_VERSION}-ftcsim-{_fmi3_key(cxx, include)}" / "libpythonfmu-export.so"
    with _locked(folder, "pythonfmu3"):
        if not target.is_file():
            _compile_fmi3(sources, cxx, include, target)
    return ExportLibrary("3", "ftcsim", target, _sha256(target.read_bytes()),
                         f"pythonfmu3 {FMI3_VERSION}'s pythonfmu-export sources (PyPI; SHA-256 in "
                         f"fmus/native/{FMI3_SOURCES.name}) with fmus/native/{FMI3_PATCH.name}, {_compiler_id(cxx)}",
                         ("no library destructor: the static shared_ptr<PyState> is released once, by its C++ static "
                          "destructor", "every function returns fmi3Error for a NULL instance", "nothing is thrown "
                          "through the C interface (std::terminate in the host)", "a NULL log callback is allowed",
                          "a Python exception releases the instance's Python objects once"))


def _compile_fmi3(sources: Path, cxx: str, include: Path, target: Path) -> None:
    with tempfile.TemporaryDirectory(prefix="ftcsim_pythonfmu3_") as tmp:
        work = Path(tmp) / "pythonfmu-export"
        shutil.copytree(sources / "src", work / "src")
        done = subprocess.run([_tool("patch"), "-p1", "--batch", "--forward", "--silent", "-i", str(FMI3_PATCH)],
                              cwd=work, capture_output=True, text=True)
        if done.returncode != 0:
            raise ExportLibraryError(f"{FMI3_PATCH.name} does not apply: {(done.stdout + done.stderr).strip()[-800:]}")
        out = Path(tmp) / "libpythonfmu-export.so"
        cmd = [cxx, *FMI3_FLAGS, f"-I{include}", f"-I{work / 'src'}", *(str(work / u) for u in FMI3_COMPILE_UNITS),
               "-o", str(out)]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            raise ExportLibraryError(f"compiling the FMI 3 export library failed: {done.stderr.strip()[-2000:]}")
        missing = defined_functions(stock_library_path("3")) - defined_functions(out)
        missing = sorted(f for f in missing if f.startswith("fmi3"))
        if missing:
            raise ExportLibraryError(f"the rebuilt FMI 3 library lacks {missing}")
        _publish(out.read_bytes(), target)
        (target.parent / "build.json").write_text(json.dumps(
            {"command": [Path(c).name if i == 0 else c for i, c in enumerate(cmd)], "compiler": _compiler_id(cxx),
             "python_include": str(include), "sha256": _sha256(out.read_bytes())}, indent=2) + "\n")


# -- what an extracted FMU carries ----------------------------------------------------------------
def exit_safe(folder) -> bool:
    """False if the FMU extracted in ``folder`` is a pythonfmu FMU (``resources/slavemodule.txt``)
    whose Linux binary is not our corrected library: its ``ftcsim_build.json`` must name the
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
    return corrected_fmi2() if fmi == "2" else rebuilt_fmi3()


if __name__ == "__main__":  # pragma: no cover
    for v in sys.argv[1:] or ["2", "3"]:
        lib = export_library(v)
        print(v, lib.path, lib.sha256)
