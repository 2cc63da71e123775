"""`ftcsim design NAME ... --out FILE` and `ftcsim verify NAME [--gains FILE]`.

The designs are the papers' own (``papers.registry.designs()``): each names a module with
``run_design(**options) -> (result, summary)``, ``gains_from_file(get) -> gains`` and
``verify_report(gains or None, source) -> (ok, title, {check: holds})``. This module parses and
checks the command line and the gains file, and writes a design's result: designs return
results, they write nothing.

Exit status: 0 all checks hold, 1 a design is infeasible/unverified or a verification check
fails, 2 bad input (raised as :class:`orchestrator.common.errors.InputError`). `design` writes its
JSON file only after every check passed.
"""
from __future__ import annotations

import difflib
import json
import math
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import load_json_object, strict_json
from orchestrator.common.outputs import OutputFile
from orchestrator.scenario.shipped import designs, resolve
from plant.naming import split_name

_CHECKS = {
    "finite": (lambda x: True, "a finite number"),
    "positive": (lambda x: x > 0, "a positive number"),
    "unit_interval": (lambda x: 0.0 < x <= 1.0, "in (0, 1]"),
    "fraction": (lambda x: 0.0 <= x < 1.0, "in [0, 1)"),
}


def _designs():
    return designs()


def _options():
    """Every design option (name -> OptionSpec) and which designs use it."""
    opts, users = {}, {}
    for name, (_, spec) in _designs().items():
        for o in spec.options:
            opts.setdefault(o.name, o)
            users.setdefault(o.name, []).append(name)
    return opts, users


def register(subparsers):
    """Add the `design` and `verify` subcommands to an argparse subparsers object."""
    names = ", ".join(_designs())
    d = subparsers.add_parser("design", help="solve a paper's LMIs for gains and write a parameter file")
    d.add_argument("name", help=f"one of {names}")
    d.add_argument("--out", required=True, help="parameter file (JSON) to write; an existing file is replaced only if "
                                                "`ftcsim design` wrote it and --overwrite is given")
    d.add_argument("--overwrite", action="store_true", help="replace a design file ftcsim wrote at --out")
    opts, users = _options()
    for name, o in opts.items():
        d.add_argument(f"--{name.replace('_', '-')}", dest=name, type=float, nargs=o.nargs,
                       help=f"{o.help} ({', '.join(users[name])})")
    d.set_defaults(func=run_design)
    v = subparsers.add_parser("verify", help="check a gain set (published or designed) against its paper")
    v.add_argument("name", help=f"one of {names}")
    v.add_argument("--gains", help="parameter file written by `ftcsim design` (default: the published gains)")
    v.set_defaults(func=run_verify)
    return d, v


def _spec(name):
    known = _designs()
    if name not in known:
        close = difflib.get_close_matches(name, known, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise InputError("command line", "NAME", f"unknown design '{name}'{hint} (known: {', '.join(known)})")
    return known[name][1]


def _checked_options(args, spec) -> dict:
    opts, users = _options()
    own = {o.name: o for o in spec.options}
    out = {}
    for name in opts:
        value = getattr(args, name, None)
        if value is None:
            continue
        flag = f"--{name.replace('_', '-')}"
        if name not in own:
            raise InputError("command line", flag, f"does not apply to {spec.name} (used by {', '.join(users[name])})")
        ok, what = _CHECKS[own[name].check]
        for x in value if isinstance(value, list) else [value]:
            if not math.isfinite(x) or not ok(x):
                raise InputError("command line", flag, f"must be {what}, got {x}")
        out[name] = value
    return out


WRITTEN_BY = "written_by"  # the key that marks a design file as ftcsim's: "ftcsim design NAME"


def written_by_ftcsim(path: Path) -> bool:
    """True if ``path`` is a design file ``ftcsim design`` wrote (a JSON object with its mark)."""
    try:
        doc = load_json_object(path, "design file")
    except InputError:
        return False
    return str(doc.get(WRITTEN_BY, "")).startswith("ftcsim design ")


def run_design(args) -> int:
    spec = _spec(args.name)
    options = _checked_options(args, spec)
    # the one publisher: --out checked (a design file ftcsim wrote is replaced only with --overwrite; nothing
    # else ever), locked, written beside it and renamed into place once every check passed
    out = OutputFile(args.out, "a design file", written_by_ftcsim, args.overwrite,
                     foreign="was not written by `ftcsim design`").check()
    try:
        import lmi  # cvxpy: 1 s to import, only for `ftcsim design`, once the arguments are checked

        module = resolve(spec.module)
        try:
            result, summary = module.run_design(**options)
        except lmi.LMIError as exc:
            print(f"design {args.name} failed: {exc}")
            print("nothing written")
            return 1
        text = json.dumps(strict_json({WRITTEN_BY: f"ftcsim design {args.name}", **result}), indent=2,
                          allow_nan=False) + "\n"
        out.write(lambda tmp: tmp.write_text(text, encoding="utf-8"))
    finally:
        out.release()
    print(f"design {args.name}: {summary}; all checks passed; wrote {args.out}")
    return 0


# ---------------------------------------------------------------------------------------
# verify

def load_json(path) -> dict:
    """A JSON object from ``path``; every problem is an ``InputError`` naming the file."""
    return load_json_object(path, "gains file")


def field_getter(data, path):
    """``get(dotted, shape)``: a field of a gains file as a float array of ``shape`` (``()`` for a
    scalar, ``None`` for the raw value); missing fields, booleans, strings and non-finite values
    are ``InputError``s naming the file and the field."""

    def get(dotted, shape=None):
        cur = data
        for part in dotted.split("."):
            if isinstance(cur, dict) and part in cur:
                cur = cur[part]
            elif isinstance(cur, list) and part.isdigit() and int(part) < len(cur):
                cur = cur[int(part)]
            else:
                raise InputError(path, dotted, "missing")
        if shape is None:
            return cur
        if isinstance(shape, str):
            raise InputError(path, dotted, f"must be a {shape}")
        if _has_non_number(cur):
            raise InputError(path, dotted, "must hold numbers only (no booleans, strings or nulls)")
        try:
            a = np.asarray(cur, dtype=float)
        except (TypeError, ValueError):
            raise InputError(path, dotted, "not a numeric array") from None
        if shape == () and a.ndim != 0:
            raise InputError(path, dotted, f"expected a number, got shape {a.shape}")
        if shape != () and a.shape != tuple(shape):
            raise InputError(path, dotted, f"shape {a.shape}, expected {tuple(shape)}")
        if not np.all(np.isfinite(a)):
            raise InputError(path, dotted, "contains non-finite values")
        return a if shape != () else float(a)

    return get


VERIFIED = ("gains", "settings", "performance")  # the sections of a design file that `verify` reads


def _arrays(values: dict) -> dict:
    """{'K[1,2]': x, 'theta_1': y} -> {'K': array (1-based indices), 'theta_1': 0-d array}."""
    groups: dict = {}
    for name, x in values.items():
        base, idx = split_name(str(name))
        groups.setdefault(base, []).append((idx, x))
    out = {}
    for base, items in groups.items():
        if _has_non_number([x for _, x in items]):
            out[base] = None
            continue
        if len(items) == 1 and items[0][0] == ():
            out[base] = np.asarray(float(items[0][1]))
            continue
        shape = tuple(max(ix[d] for ix, _ in items) for d in range(len(items[0][0])))
        a = np.full(shape, np.nan)
        for ix, x in items:
            a[tuple(i - 1 for i in ix)] = x
        out[base] = a
    return out


def _verified(data: dict, base: str):
    """(where, value) of ``base`` in the sections verify reads; a ``cases`` list (002's bank of gain
    cases: one row of K and one omega_hat per slot) read as the FMU's slots; (None, None) if absent."""
    for section in VERIFIED:
        table = data.get(section)
        if isinstance(table, dict) and base in table:
            return f"{section}.{base}", table[base]
    cases = data.get("cases")
    field = {"K": "K", "case_omega_hat": "omega_hat"}.get(base)
    if isinstance(cases, list) and field and all(isinstance(c, dict) and field in c for c in cases):
        return f"cases[*].{field}", [np.ravel(np.asarray(c[field], dtype=float)).tolist() for c in cases]
    return None, None


def check_applied(data: dict, path) -> None:
    """Refuse a design file whose ``fmu_parameters`` (what ``ftcsim run --gains`` applies) are not the
    values ``verify`` checks: every parameter applied must be found in the verified sections with the
    same value, so an edited or foreign ``fmu_parameters`` can never run under a verdict of other gains."""
    per_model = data.get("fmu_parameters")
    if per_model is None:
        return
    if not isinstance(per_model, dict):
        raise InputError(path, "fmu_parameters", "not an object {model: {parameter: value}}")
    for model, values in per_model.items():
        if not isinstance(values, dict):
            raise InputError(path, f"fmu_parameters.{model}", "expected an object {parameter: value}")
        for base, applied in _arrays(values).items():
            key = f"fmu_parameters.{model}.{base}"
            where, verified = _verified(data, base)
            if where is None:
                raise InputError(path, key, f"applied by runs, but `verify` checks no {base!r} in this file "
                                            f"({', '.join(VERIFIED)}): the file does not say what was verified")
            try:
                v = np.asarray(verified, dtype=float)
            except (TypeError, ValueError):
                v = None
            if applied is None or v is None:
                raise InputError(path, key, "must hold numbers only")
            if where.startswith("cases"):  # the FMU's slots hold the cases in order, unused slots zero
                pad = np.zeros_like(applied)
                pad[: len(v)] = v.reshape((len(v),) + applied.shape[1:]) if v.size else pad[:0]
                v = pad
            if v.size != applied.size or not np.array_equal(v.reshape(applied.shape), applied):
                raise InputError(path, key, f"differs from {where}, which `verify` checks: runs would apply gains "
                                            "that were not verified")


def _has_non_number(x) -> bool:
    if isinstance(x, list):
        return any(_has_non_number(v) for v in x)
    return isinstance(x, bool) or not isinstance(x, (int, float))


def run_verify(args) -> int:
    spec = _spec(args.name)
    path = args.gains
    data = None if path is None else load_json(path)  # the file is read and checked before the design's imports
    if data is not None and data.get("design") not in (None, args.name):
        raise InputError(path, "design", f"file is for '{data.get('design')}', not '{args.name}'")
    if data is not None:
        check_applied(data, path)  # what runs apply (fmu_parameters) is what is verified (gains, settings)
    module = resolve(spec.module)
    if path is None:
        ok, title, holds = module.verify_report(None)
    else:
        gains = module.gains_from_file(field_getter(data, path))
        ok, title, holds = module.verify_report(gains, source=path)
    print(title)
    for name, good in holds.items():
        print(f"  {'holds' if good else 'FAILS'}  {name}")
    failed = [n for n, good in holds.items() if not good]
    print(f"  => {'all checks hold' if ok else str(len(failed)) + ' check(s) fail'}")
    return 0 if ok else 1
