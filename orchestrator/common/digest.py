"""Digests of what decides a result, shared by every store that resumes (campaign runs; the arena's cells).

A stored result is reused only under the digest of everything that decided it; a changed input gives
another digest, so the result is computed again or the store refuses to mix it in. :func:`digest` is
the SHA-256 of a canonical JSON form (keys sorted, numpy numbers as numbers, non-finite floats as
null); :func:`file_digest` the SHA-256 of a file's bytes (cached by path, size and modification time);
:func:`source_digest` that of the Python sources a module runs: the module and, transitively, every
module of ``packages`` it imports (found by reading the ``import`` statements, also those inside
functions: stable whatever this process imported before), so an in-process block's code is part of
the digest as an FMU's bytes are.

Standard library and numpy only.
"""
from __future__ import annotations

import ast
import hashlib
import importlib.util
import json
import os

from orchestrator.common.jsonio import strict_json

_FILES: dict = {}
_CLOSURES: dict = {}  # (module, packages) -> [(module name, source file)]


def canonical(obj) -> bytes:
    """``obj`` as canonical JSON bytes (sorted keys, no spaces, numpy as plain numbers, NaN as null)."""
    return json.dumps(strict_json(obj), sort_keys=True, separators=(",", ":"), allow_nan=False).encode("utf-8")


def digest(obj, length: int | None = None) -> str:
    """SHA-256 (hex, the first ``length`` characters) of :func:`canonical` ``obj``."""
    h = hashlib.sha256(canonical(obj)).hexdigest()
    return h[:length] if length else h


def file_digest(path) -> str:
    """SHA-256 of a file's bytes (cached by resolved path, size and modification time)."""
    real = os.path.realpath(path)
    st = os.stat(real)
    key = (real, st.st_size, st.st_mtime_ns)
    if key not in _FILES:
        h = hashlib.sha256()
        with open(real, "rb") as f:
            for chunk in iter(lambda: f.read(1 << 20), b""):
                h.update(chunk)
        _FILES[key] = h.hexdigest()
    return _FILES[key]


def _imports(path: str, module: str) -> set[str]:
    """Absolute names of the modules ``path`` (module ``module``) imports, its relative imports resolved."""
    try:
        with open(path, "rb") as f:
            tree = ast.parse(f.read(), path)
    except (OSError, SyntaxError, ValueError):
        return set()
    package = module if path.endswith("__init__.py") else module.rpartition(".")[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                up = parts[: len(parts) - node.level + 1] if node.level > 1 else parts
                base = ".".join(p for p in (*up, base) if p)
            out.add(base)
            out.update(f"{base}.{a.name}" for a in node.names)  # `from pkg import module`
    return out


def _source_file(name: str, roots: dict) -> str | None:
    """The source file of module ``name`` found on disk below its top-level package (nothing imported)."""
    top, _, rest = name.partition(".")
    if top not in roots:
        try:  # a top-level name: find_spec imports no parent, runs nothing
            spec = importlib.util.find_spec(top)
        except (ImportError, ValueError):
            spec = None
        roots[top] = list(getattr(spec, "submodule_search_locations", None) or [])
    for root in roots[top]:
        base = os.path.join(root, *rest.split(".")) if rest else root
        for candidate in (base + ".py", os.path.join(base, "__init__.py")):
            if os.path.isfile(candidate):
                return candidate
    return None


def source_digest(module: str, packages=("plant", "estimator", "controller", "papers", "arena")) -> str:
    """SHA-256 of the sources of ``module`` and of every module of ``packages`` it imports, transitively
    (each by its name and bytes; the parents' ``__init__.py`` included). The closure is found once per
    process; the digest follows every later change of the files' bytes."""
    key = (module, tuple(packages))
    if key not in _CLOSURES:
        roots: dict = {}
        seen: dict = {}
        todo = [module]
        while todo:
            name = todo.pop()
            if name in seen or not name or name.split(".")[0] not in packages:
                continue
            seen[name] = origin = _source_file(name, roots)
            if origin is None:
                continue
            todo.extend(_imports(origin, name))
            parent = name.rpartition(".")[0]
            if parent:
                todo.append(parent)
        _CLOSURES[key] = sorted((n, p) for n, p in seen.items() if p)
    files = _CLOSURES[key]
    return digest([(n, file_digest(p)) for n, p in files])
