"""The environment a host that is not Python needs to run our FMUs (``ftcsim host-env``).

A pythonfmu FMU runs its Python code in the host process's embedded CPython. A host that is
itself Python (fmpy, ecospy, libcosimpy, OMSimulator's Python API) already has it. Any other host
(OMSimulator's or Ecos's command line, Ecos's proxy server, a C program, Simulink on Linux) needs:

* ``LD_PRELOAD`` = the shared libpython of the Python the FMUs were built with: the FMU binary
  leaves every ``Py*`` symbol undefined, and ``dlopen`` fails with ``undefined symbol:
  _Py_NoneStruct`` without it;
* ``PYTHONPATH`` = that environment's site-packages: the interpreter the FMU starts is the base
  installation, which does not see a virtual environment's packages, and the FMU's ``import
  numpy`` fails inside ``fmi2Instantiate`` (which then returns NULL: OMSimulator and Ecos's CLI
  go on and crash);
* ``PYTHONHOME`` only when the Python was moved after it was built (its compiled-in prefix no
  longer exists).

The project's own packages need no path: every FMU carries its own copy.
"""
from __future__ import annotations

import os
import shlex
import sys
import sysconfig
from pathlib import Path


class HostEnvError(RuntimeError):
    """This Python cannot host the FMUs outside a Python process (no shared libpython)."""


def libpython() -> Path:
    """The shared libpython of this interpreter (what ``LD_PRELOAD`` must name)."""
    if not sysconfig.get_config_var("Py_ENABLE_SHARED"):
        raise HostEnvError(f"{sys.executable} (Python {sys.version.split()[0]}) was built without --enable-shared: it "
                           "has no libpython for a non-Python host to preload; use a Python built with it (pyenv: "
                           "PYTHON_CONFIGURE_OPTS=--enable-shared, Debian's python3 has it)")
    libdir = Path(sysconfig.get_config_var("LIBDIR") or "")
    for name in (sysconfig.get_config_var("INSTSONAME"), sysconfig.get_config_var("LDLIBRARY")):
        if name and (libdir / name).is_file():
            return libdir / name
    multiarch = sysconfig.get_config_var("MULTIARCH") or ""
    for name in (sysconfig.get_config_var("INSTSONAME"), sysconfig.get_config_var("LDLIBRARY")):
        if name and multiarch and (libdir / multiarch / name).is_file():
            return libdir / multiarch / name
    raise HostEnvError(f"no shared libpython found in {libdir} for {sys.executable}")


def site_packages() -> list[str]:
    """This environment's package folders (purelib, then platlib if it differs)."""
    paths = sysconfig.get_paths()
    return list(dict.fromkeys(paths[k] for k in ("purelib", "platlib") if paths.get(k)))


def host_environment() -> dict:
    """Variable -> value of the environment a non-Python host needs (see the module docstring)."""
    env = {"LD_PRELOAD": str(libpython()), "PYTHONPATH": os.pathsep.join(site_packages())}
    prefix = sysconfig.get_config_var("prefix")
    if prefix and not (Path(prefix) / "lib").is_dir():
        env["PYTHONHOME"] = sys.base_prefix
    return env


def shell_lines(env: dict | None = None) -> list[str]:
    """``export NAME=value`` lines (POSIX shell quoting)."""
    env = host_environment() if env is None else env
    return [f"export {k}={shlex.quote(v)}" for k, v in env.items()]
