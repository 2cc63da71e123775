"""An FMU runs the code it carries: its embedded packages in a namespace of their own (issue 20).

An FMU embeds the project's modules its block imports (``resources/plant/...``,
``resources/controller/...``, a user's own package ...). The host may already have imported
packages of those names: our own master imports ``plant``, ``controller``, ``papers``; another FMU
imported its copy first. A module found in ``sys.modules`` is never loaded again, so an FMU built
from edited code (a FASMC with beta x3, a do_step that raises) silently ran the host's copy.

First, when the host already has every module the FMU embeds, with the same content (each file's
SHA-256: the modules already imported, and for the others the files the host's import system
would load, found without importing anything), the FMU uses them: that is its own code, loaded
once (our master running FMUs built from its installation; no second copy, no second compile of
the numba kernels, whose cache is tied to module names). Otherwise (an FMU built from edited code,
a host without ftcsim) each FMU content (:func:`content_digest` of the files it embeds, computed
from the files themselves, so a hand-edited copy of an FMU is another content) gets a private
package name ``_ftcsim_<digest>``, and its modules are loaded below it, from the FMU's resources
folder only:
``resources/controller/fasmc.py`` is the module ``_ftcsim_<digest>.controller.fasmc``. The code
inside keeps its ordinary imports (``from plant.block import Block``, relative imports,
imports inside functions): every module of the namespace gets builtins whose ``__import__``
maps the embedded top-level names (``plant``, ``controller`` ...) into the namespace; every other
name (numpy, pythonfmu, the standard library) is the host's. ``importlib.import_module`` with an
embedded name is not redirected (our block code does not use it). Two FMUs with the same digest
share one namespace (the same code); modules are registered in ``sys.modules`` under their
private names, so pickling, dataclasses and numba's caching find them.

The modules are compiled from the FMU's files without writing bytecode next to them (the
extracted FMU stays as it was). This module uses the standard library only: the generated slave
script loads it from the FMU's resources by file name, before any package of the FMU exists.
"""
from __future__ import annotations

import builtins
import hashlib
import importlib
import importlib.machinery
import importlib.util
import os
import sys
import threading
from contextlib import contextmanager

PREFIX = "_ftcsim_"  # private package names: _ftcsim_<digest>; plant/kernels strips it from cache names
_LOCK = threading.RLock()
_SPACES: dict = {}  # private package name -> Space
_HASHES: dict = {}  # (file, mtime, size) -> sha256 of the host's module files
_DIGESTS: dict = {}  # (resources folder, tops) -> content digest


def _sha256(path: str) -> str | None:
    try:
        st = os.stat(path)
        key = (path, st.st_mtime_ns, st.st_size)
        h = _HASHES.get(key)
        if h is None:
            with open(path, "rb") as f:
                h = _HASHES[key] = hashlib.sha256(f.read()).hexdigest()
        return h
    except OSError:
        return None


def _inside(path: str, folder: str) -> bool:
    path, folder = os.path.abspath(path), os.path.abspath(folder)
    return path == folder or path.startswith(folder + os.sep)


def embedded_modules(folder: str, tops) -> dict:
    """Dotted module name -> file of every Python module below ``folder`` under the names ``tops``."""
    out = {}
    for top in tops:
        single = os.path.join(folder, top + ".py")
        if os.path.isfile(single):
            out[top] = single
        for root, _, files in os.walk(os.path.join(folder, top)):
            for f in files:
                if f.endswith(".py"):
                    rel = os.path.relpath(os.path.join(root, f), folder)[:-3].split(os.sep)
                    out[".".join(rel[:-1] if rel[-1] == "__init__" else rel)] = os.path.join(root, f)
    return out


def content_digest(folder: str, tops) -> str:
    """SHA-256 (hex, 16 digits) of the modules embedded below ``folder`` (names and contents),
    once per folder."""
    key = (os.path.abspath(folder), tuple(sorted(tops)))
    digest = _DIGESTS.get(key)
    if digest is None:
        h = hashlib.sha256()
        for name, path in sorted(embedded_modules(folder, tops).items()):
            h.update(name.encode() + b"\0" + bytes.fromhex(_sha256(path) or "00"))
        digest = _DIGESTS[key] = h.hexdigest()[:16]
    return digest


def host_has_the_same_code(folder: str, tops) -> bool:
    """True if every module embedded below ``folder`` is, in this process, either imported from a
    file with the same content or would be imported (by the path finder, outside ``folder``) from
    one. Nothing is imported to find out."""
    mine = embedded_modules(folder, tops)
    locations: dict = {}  # package -> its submodule search locations in the host
    path = [p for p in sys.path if isinstance(p, str) and not _inside(p or ".", folder)]
    for name in sorted(mine, key=lambda n: n.count(".")):
        module = sys.modules.get(name)
        if module is not None:
            origin = getattr(module, "__file__", None)
            search = getattr(module, "__path__", None)
        else:
            parent, _, _ = name.rpartition(".")
            where = locations.get(parent) if parent else path
            spec = importlib.machinery.PathFinder.find_spec(name, where) if where is not None else None
            origin = spec.origin if spec is not None else None
            search = spec.submodule_search_locations if spec is not None else None
        if not origin or _inside(origin, folder) or _sha256(origin) != _sha256(mine[name]):
            return False
        if search is not None:
            locations[name] = list(search)
    return True


@contextmanager
def _without(folder: str):
    """sys.path without ``folder`` (pythonfmu puts the FMU's resources first) while the host's
    packages are imported: a package first imported from an FMU would stand for the host's."""
    removed = [(i, p) for i, p in enumerate(sys.path) if isinstance(p, str) and _inside(p or ".", folder)]
    for i, _ in reversed(removed):
        del sys.path[i]
    try:
        yield
    finally:
        for i, p in removed:
            sys.path.insert(i, p)


class _SourceLoader(importlib.machinery.SourceFileLoader):
    """Loads a module of the namespace with the namespace's builtins, writing no bytecode."""

    def __init__(self, fullname, path, space):
        super().__init__(fullname, path)
        self._space = space

    def exec_module(self, module):
        module.__dict__["__builtins__"] = self._space.builtins
        super().exec_module(module)

    def set_data(self, path, data, *, _mode=0o666):  # never write __pycache__ into the FMU
        return None


class _RootLoader:
    """The namespace's root package: an empty module."""

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        module.__dict__["__builtins__"] = _SPACES[module.__name__].builtins


class Space:
    """Where one FMU content's code runs. ``shared``: the host's modules (the same files); else the
    private namespace: a meta-path finder for ``<name>.*`` and the builtins (with the redirecting
    ``__import__``) its modules run with."""

    def __init__(self, name: str, folder: str, tops, shared: bool = False):
        self.name, self.folder, self.tops, self.shared = name, os.path.abspath(folder), frozenset(tops), shared
        self.digest = name[len(PREFIX):]
        self._import_host = builtins.__import__
        self.builtins = dict(builtins.__dict__)
        self.builtins["__import__"] = self._import

    # -- the finder (sys.meta_path) ----------------------------------------------------------
    def find_spec(self, fullname, path=None, target=None):
        if fullname == self.name:
            spec = importlib.machinery.ModuleSpec(fullname, _RootLoader(), is_package=True)
            spec.submodule_search_locations = []
            return spec
        if not fullname.startswith(self.name + "."):
            return None
        parts = fullname[len(self.name) + 1:].split(".")
        if parts[0] not in self.tops:
            return None
        base = os.path.join(self.folder, *parts)
        init = os.path.join(base, "__init__.py")
        if os.path.isfile(init):
            return importlib.util.spec_from_file_location(fullname, init, loader=_SourceLoader(fullname, init, self),
                                                          submodule_search_locations=[base])
        if os.path.isfile(base + ".py"):
            return importlib.util.spec_from_file_location(fullname, base + ".py",
                                                          loader=_SourceLoader(fullname, base + ".py", self))
        return None

    # -- the import statement inside the namespace --------------------------------------------
    def _import(self, name, globals=None, locals=None, fromlist=(), level=0):
        if level == 0 and name.partition(".")[0] in self.tops:
            module = self._import_host(f"{self.name}.{name}", globals, locals, fromlist, 0)
            return module if fromlist else sys.modules[f"{self.name}.{name.partition('.')[0]}"]
        return self._import_host(name, globals, locals, fromlist, level)

    # -- what the slave script asks for --------------------------------------------------------
    def module(self, dotted: str):
        """The module ``dotted`` (an embedded name such as ``fmus.adapter``) this FMU runs."""
        if self.shared:
            with _without(self.folder):
                return importlib.import_module(dotted)
        return importlib.import_module(f"{self.name}.{dotted}")

    def attr(self, ref: str):
        """``"pkg.module:attr"`` of the namespace."""
        module, _, attr = ref.partition(":")
        return getattr(self.module(module), attr)

    def check(self, resources) -> None:
        """Refuse an instance of another FMU's files: pythonfmu imports the slave script by name,
        so a copy of an FMU with edited files (same script name) would get this FMU's class."""
        if not resources or os.path.abspath(resources) == self.folder:
            return
        other = content_digest(resources, self.tops)
        if other == self.digest and not os.path.isdir(self.folder):
            self.folder = os.path.abspath(resources)  # the first extraction was removed: the same files here
        if other != self.digest:
            raise ImportError(f"{resources}: this FMU's code (digest {other}) differs from that of an FMU with the "
                              f"same slave module name already loaded in this process from {self.folder} (digest "
                              f"{self.digest}); rebuild it with `ftcsim build` (its slave module is then named after "
                              "its code) or run it in another process")


def install(folder: str, tops) -> Space:
    """Where the FMU whose files lie in ``folder`` (its resources) runs its code, for the top-level
    names ``tops``: created once per process and content (the first FMU extraction of that content
    serves every later instance: same digest, same files)."""
    name = PREFIX + content_digest(folder, tops)
    with _LOCK:
        space = _SPACES.get(name)
        if space is None or not (space.shared or os.path.isdir(space.folder)):
            if space is not None:  # that extraction was removed: serve from this one
                sys.meta_path.remove(space)
            space = _SPACES[name] = Space(name, folder, tops, shared=host_has_the_same_code(folder, tops))
            if not space.shared:
                sys.meta_path.insert(0, space)
        return space
