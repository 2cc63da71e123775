"""Compiled kernels for the blocks' hot arithmetic (numba), and the switch between them and
the readable numpy reference code.

The pattern (every block that has a kernel follows it; paper helpers adding blocks too):

* The block's numpy code stays the reference: readable, cited against the paper, and what
  runs when kernels are off. The kernel is a plain function of floats and float64 arrays in a
  ``kernels/`` folder beside the block (``plant/kernels/flexible.py``, ``estimator/kernels/fafeo.py``,
  ``controller/kernels/attitude.py``, ...) decorated with :func:`jit`, written with explicit loops in the
  same order of operations where it is cheap to do so; it computes exactly what the reference
  computes (the test ``tests/plant/test_kernels.py`` compares both on random states to
  1e-12 relative; bit equality is not asked: numpy's BLAS sums in another order).
* The block decides once, in ``initialize``, with ``self._kernels = kernels.enabled()`` (``plant.kernels``
  re-exports this module's switch), and
  then calls either the kernel or the reference. Nothing else changes: state, outputs,
  ``get_state``/``set_state`` are the same on both paths.
* Kernels are used when numba imports and ``FTCSIM_KERNELS`` is not ``0`` (read when this
  module is first imported; tests switch with :func:`set_enabled`). Without numba (a host
  Python that only has numpy) the blocks run their reference code: an FMU needs nothing
  more than numpy, and lists numba in its requirements because it runs faster with it
  (``OPTIONAL_IMPORTS``, picked up by ``fmus/runtime.py``).
* Compiled code is cached on disk (``cache=True``) in a per-user folder, never next to the
  source: an FMU's Python files run from a temporary extraction folder, which must stay
  untouched and which changes with every extraction. :class:`KernelCacheLocator` files the
  cache of a kernel module under its module name and the hash of its source (and of
  ``plant/kernels/common.py``, ``plant/actuator.py``, ``plant/linalg3.py`` and ``plant/timing.py``, which its
  compiled code contains), so the install, the FMUs extracted
  anywhere and every pytest-xdist worker share one warm cache. Folder: ``FTCSIM_CACHE_DIR``
  if set, else the user's cache folder (:func:`user_cache_dir`, platformdirs: ``$XDG_CACHE_HOME`` or
  ``~/.cache`` on Linux, ``~/Library/Caches`` on macOS, ``%LOCALAPPDATA%`` on Windows) + ``ftcsim/numba``;
  if that cannot be written, the system temporary folder.
* Kernel rules: ``fastmath`` off (IEEE semantics, no reassociation), ``error_model="numpy"``,
  no global arrays (pass them), functions called from a kernel live in the same module or in
  ``plant/kernels/common.py``, constants from ``plant/timing.py`` (the cache stamp covers these files). A
  reference function that is plain float arithmetic is not copied into a kernel: ``common.py``
  compiles the function itself (``solve_sym3 = jit(linalg3.solve_sym3)``), and its file joins
  the cache stamp (``_STAMPED``); the FMU build embeds it with the rest of the import closure.
"""
from __future__ import annotations

import hashlib
import os
import sys
import tempfile

OPTIONAL_IMPORTS = ("numba",)  # fmus/runtime.py lists these in an FMU's requirements.txt

_ENV = os.environ.get("FTCSIM_KERNELS", "1").strip().lower()
_WANTED = _ENV not in ("0", "false", "no", "off")
REASON = ""  # why kernels are off ("" when they are on)



class _Without:
    """Import hook refusing ``scipy.linalg`` while numba probes for BLAS (see :func:`_import_numba`)."""

    def find_spec(self, name, path=None, target=None):
        if name == "scipy.linalg" or name.startswith("scipy.linalg."):
            raise ImportError("not during numba's BLAS probe (plant/jit.py)")
        return None


def _import_numba():
    """``import numba``, keeping scipy.linalg (and its Fortran runtime) out of the process.

    numba's ``numba.np.arraymath`` imports ``scipy.linalg.cython_blas`` when first loaded, only to
    know whether ``np.dot``-style inner products may call BLAS (our kernels never do; numba
    retries that import by itself when some other code compiles a BLAS call). Loading
    scipy.linalg costs every process that imports the kernels about 0.35 s (measured: 1.40 s
    for ``import numba, numba.np.arraymath`` against 1.05 s for this module, 3 runs each) and
    brings libgfortran. So the probe runs with scipy.linalg refused, unless it is already imported.
    (It was first added because libgfortran's exit-time ``free()`` aborted processes after
    pythonfmu's exit-time double release had written into freed memory; the FMUs' corrected
    export library removed that, fmus/native/README.md, and a process with scipy.linalg imported
    now exits cleanly, tests/fmus/test_host_exit.py. The import cost is why the hook stays.)"""
    import numba as nb

    if "scipy.linalg" not in sys.modules and "numba.np.arraymath" not in sys.modules:
        hook = _Without()
        sys.meta_path.insert(0, hook)
        try:
            import numba.np.arraymath  # noqa: F401
        finally:
            sys.meta_path.remove(hook)
    return nb


try:
    if not _WANTED:
        raise ImportError("FTCSIM_KERNELS=0")
    numba = _import_numba()
except ImportError as e:  # no numba in this Python, or switched off: reference code only
    numba = None
    REASON = "FTCSIM_KERNELS=0" if not _WANTED else f"numba is not importable ({e})"

_enabled = numba is not None


def enabled() -> bool:
    """True if blocks initialised now use their compiled kernels."""
    return _enabled


def set_enabled(on: bool) -> bool:
    """Switch kernels on or off for blocks initialised from now on (tests, benchmarks).
    Returns the previous setting. Cannot switch on without numba."""
    global _enabled
    previous = _enabled
    if on and numba is None:
        raise RuntimeError(f"kernels cannot be switched on: {REASON}")
    _enabled = bool(on)
    return previous


def cache_root() -> str:
    """The folder compiled kernels are cached in (created on use)."""
    explicit = os.environ.get("FTCSIM_CACHE_DIR")
    if explicit:
        return os.path.join(os.path.abspath(explicit), "numba")
    return os.path.join(user_cache_dir(), "numba")


def user_cache_dir() -> str:
    """ftcsim's folder in the user's cache folder: platformdirs' ``user_cache_dir("ftcsim")``
    (``$XDG_CACHE_HOME/ftcsim`` or ``~/.cache/ftcsim`` on Linux, ``~/Library/Caches/ftcsim`` on macOS,
    ``%LOCALAPPDATA%\\ftcsim\\Cache`` on Windows). An FMU needs nothing but numpy: in a host Python
    without platformdirs the XDG rule (``$XDG_CACHE_HOME`` or ``~/.cache``) + ``ftcsim``, platformdirs'
    answer on Linux. Imported here, when a kernel is first cached, so that an FMU's import probe
    (kernels off) never lists platformdirs among its requirements."""
    try:
        import platformdirs
    except ImportError:
        return os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "ftcsim")
    return platformdirs.user_cache_dir("ftcsim", appauthor=False)


_PLANT = os.path.dirname(os.path.abspath(__file__))
# what a kernel's compiled code contains besides its own module: plant/kernels/common.py's functions,
# the reference functions common.py compiles (plant/actuator.py, plant/linalg3.py, plant/timing.py) and
# the constants it takes from plant/timing.py (numba freezes module globals into the code). By path:
# a kernel module that moves changes its module name, hence its cache folder, too.
_STAMPED = (os.path.join(_PLANT, "kernels", "common.py"),
            *(os.path.join(_PLANT, f) for f in ("actuator.py", "linalg3.py", "timing.py")),
            os.path.abspath(__file__))  # and the compile options below
_OURS: set = set()  # code objects of the functions decorated with jit
_HASHES: dict = {}


def _source_hash(path: str) -> str:
    """sha256 of a kernel module's source and of the files in ``_STAMPED``."""
    h = _HASHES.get(path)
    if h is None:
        digest = hashlib.sha256()
        for p in (path, *_STAMPED):
            with open(p, "rb") as f:
                digest.update(f.read())
        h = _HASHES[path] = digest.hexdigest()
    return h


def _writable(path: str) -> bool:
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
        return True
    except OSError:
        return False


if numba is not None:
    from numba.core import caching as _caching

    _Base = getattr(_caching, "_CacheLocator", None) or _caching.CacheLocator
    _Impl = getattr(_caching, "CacheImpl", None) or _caching._CacheImpl

    class KernelCacheLocator(_Base):
        """Numba cache locator for this project's kernels: the folder is
        ``cache_root()/<module>-<source hash>``, independent of where the source file lies
        (installed tree or an FMU's extracted resources); the source stamp is the same hash.
        Functions not decorated with :func:`jit` are left to numba's own locators."""

        def __init__(self, py_func, py_file):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            self._stamp = _source_hash(py_file)
            folder = f"{py_func.__module__}-{self._stamp[:16]}"
            root = cache_root()
            if not _writable(root):
                root = os.path.join(tempfile.gettempdir(), f"ftcsim-numba-{os.getuid() if hasattr(os, 'getuid') else 0}")
            self._cache_path = os.path.join(root, folder)

        def get_cache_path(self):
            return self._cache_path

        def get_source_stamp(self):
            return self._stamp

        def get_disambiguator(self):
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func, py_file):
            if py_func.__code__ not in _OURS or not os.path.isfile(py_file):
                return None
            self = cls(py_func, py_file)
            try:
                self.ensure_cache_path()
            except OSError:
                return None
            return self

    if KernelCacheLocator not in _Impl._locator_classes:
        _Impl._locator_classes.insert(0, KernelCacheLocator)


def pack(fields: tuple, values: dict):
    """A kernel's named parameter pack: ``values`` as a float64 array in the order of ``fields``, the
    names the kernel module declares (its code reads the entries through index constants of the same
    names, frozen into the compiled code). A missing or unknown name is a ``ValueError``: the block and
    the kernel cannot drift apart."""
    import numpy as np

    if set(values) != set(fields):
        missing, unknown = sorted(set(fields) - set(values)), sorted(set(values) - set(fields))
        raise ValueError(f"parameter pack {fields}: missing {missing}, unknown {unknown}")
    return np.array([float(values[f]) for f in fields])


_WARNED: list = []  # the one warning of this process about an unreadable cache


def _warn_unreadable(path: str, error: BaseException) -> None:
    """One line on stderr per process: a damaged cache entry is recompiled (issue 20)."""
    if not _WARNED:
        _WARNED.append(path)
        detail = " ".join(str(error).split())[:120]
        print(f"ftcsim: warning: numba kernel cache entry {path} is unreadable ({type(error).__name__}: {detail}); "
              "recompiling (further damaged entries are recompiled silently)", file=sys.stderr, flush=True)


def _discard_index(cache) -> str:
    """Remove the damaged index of ``cache`` (a file of our cache folder; numba writes a new one)."""
    path = getattr(getattr(cache, "_cache_file", None), "_index_path", "?")
    try:
        os.remove(path)
    except OSError:
        pass
    return path


def _guard_cache(dispatcher) -> None:
    """Make a damaged cache entry (truncated, overwritten, from a crashed writer) a recompilation
    with one warning instead of an error in every run that loads it: numba's own loader raises
    whatever unpickling the file raises."""
    cache = getattr(dispatcher, "_cache", None)
    if cache is None:
        return
    load, save = cache.load_overload, cache.save_overload

    def load_overload(sig, target_context):
        try:
            return load(sig, target_context)
        except Exception as e:  # noqa: BLE001 - any unreadable entry: compile instead
            _warn_unreadable(_discard_index(cache), e)
            return None

    def save_overload(sig, data):
        try:
            save(sig, data)
        except Exception as e:  # noqa: BLE001 - a damaged index: start it again, else run uncached
            _warn_unreadable(_discard_index(cache), e)
            try:
                save(sig, data)
            except Exception:  # noqa: BLE001 - the compiled code works without its cache entry
                pass

    cache.load_overload, cache.save_overload = load_overload, save_overload


def jit(fn):
    """Compile ``fn`` with numba (nopython, cached, IEEE arithmetic) when kernels are
    available; without numba return it unchanged (blocks then call their reference code).
    A damaged cache entry is recompiled with one warning (:func:`_guard_cache`)."""
    if numba is None:
        return fn
    _OURS.add(fn.__code__)
    dispatcher = numba.njit(cache=True, fastmath=False, error_model="numpy")(fn)
    _guard_cache(dispatcher)
    return dispatcher
