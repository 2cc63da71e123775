"""`ftcsim design NAME ... --out FILE` and `ftcsim verify NAME [--gains FILE]`.

Designs (see each module's docstring for the paper readings):
  li2023-observer    estimator.design_li2023   000 Theorem 1 (23)-(24)
  li2023-controller  controller.design_li2023  000 Theorem 2 (41)-(44)
  zhang2014-hinf     papers.p002_zhang2014.design  002 Theorem 2 (22)
  hang2023-tsfdo     papers.p003_hang2023.design    003 Theorem 1 (3.4)

Exit status: 0 all checks hold, 1 a design is infeasible/unverified or a verification check
fails, 2 bad input (raised as :class:`orchestrator.errors.InputError`). `design` writes its
JSON file only after every check passed.
"""
from __future__ import annotations

import json
import math

import numpy as np

from .errors import InputError

NAMES = ("li2023-observer", "li2023-controller", "zhang2014-hinf", "hang2023-tsfdo")
_OPTION_USE = {  # which design uses which option
    "phi": ("li2023-observer", "li2023-controller"),
    "eps": ("li2023-observer", "li2023-controller"),
    "mu": ("li2023-controller",),
    "varsigma": ("li2023-controller",),
    "omega_hat": ("zhang2014-hinf",),
    "j": ("zhang2014-hinf",),
    "kappa": ("zhang2014-hinf",),
    "alpha": ("hang2023-tsfdo",),
}


def register(subparsers):
    """Add the `design` and `verify` subcommands to an argparse subparsers object."""
    d = subparsers.add_parser("design", help="solve a paper's LMIs for gains and write a parameter file")
    d.add_argument("name", help=f"one of {', '.join(NAMES)}")
    d.add_argument("--out", required=True, help="parameter file (JSON) to write")
    d.add_argument("--phi", type=float, help="pole-disk centre (li2023-*)")
    d.add_argument("--eps", type=float, help="pole-disk radius (li2023-*)")
    d.add_argument("--mu", type=float, help="bound on ||s(0)|| (li2023-controller)")
    d.add_argument("--varsigma", type=float, help="bound on ||v|| (li2023-controller)")
    d.add_argument("--omega-hat", type=float, nargs="+", help="effectiveness cases (zhang2014-hinf)")
    d.add_argument("--j", type=float, help="relative effectiveness half-width (zhang2014-hinf)")
    d.add_argument("--kappa", type=float, nargs="+", help="kappa values to search (zhang2014-hinf)")
    d.add_argument("--alpha", type=float, help="fixed decay rate instead of the search (hang2023-tsfdo)")
    d.set_defaults(func=run_design)
    v = subparsers.add_parser("verify", help="check a gain set (published or designed) against its paper")
    v.add_argument("name", help=f"one of {', '.join(NAMES)}")
    v.add_argument("--gains", help="parameter file written by `ftcsim design` (default: the published gains)")
    v.set_defaults(func=run_verify)
    return d, v


def _check_name(name):
    if name not in NAMES:
        raise InputError("command line", "NAME", f"unknown design '{name}' (known: {', '.join(NAMES)})")


def _positive(name, x, allow_zero=False):
    if x is not None and (not math.isfinite(x) or x < 0 or (x == 0 and not allow_zero)):
        raise InputError("command line", f"--{name.replace('_', '-')}", f"must be a positive number, got {x}")


def run_design(args) -> int:
    import lmi

    _check_name(args.name)
    for opt, users in _OPTION_USE.items():
        if getattr(args, opt, None) is not None and args.name not in users:
            raise InputError("command line", f"--{opt.replace('_', '-')}", f"does not apply to {args.name}")
    for opt in ("eps", "mu", "varsigma", "alpha"):
        _positive(opt, getattr(args, opt, None))
    for w in args.omega_hat or ():
        if not (0.0 < w <= 1.0):
            raise InputError("command line", "--omega-hat", f"effectiveness must be in (0, 1], got {w}")
    if args.j is not None and not (0.0 <= args.j < 1.0):
        raise InputError("command line", "--j", f"must be in [0, 1), got {args.j}")
    for k in args.kappa or ():
        _positive("kappa", k)
    kw = {k: v for k, v in (("phi", args.phi), ("eps", args.eps)) if v is not None}
    try:
        if args.name == "li2023-observer":
            from estimator.design_li2023 import design

            r = design(out=args.out, **kw)
            summary = f"gamma_1 = {r['performance']['gamma_1']:.4f} (000 A.1: {r['published']['gamma_1']})"
        elif args.name == "li2023-controller":
            from controller.design_li2023 import design

            kw.update({k: v for k, v in (("mu", args.mu), ("varsigma", args.varsigma)) if v is not None})
            r = design(out=args.out, **kw)
            summary = f"gamma_2 = {r['performance']['gamma_2']:.4f} (000 A.2: {r['published']['gamma_2']})"
        elif args.name == "zhang2014-hinf":
            from papers.p002_zhang2014 import design as dz

            kw = {}
            if args.omega_hat:
                kw["omega_hats"] = tuple(args.omega_hat)
            if args.j is not None:
                kw["j"] = args.j
            if args.kappa:
                kw["kappas"] = tuple(sorted(args.kappa))
            r = dz.design(out=args.out, **kw)
            summary = "; ".join(f"omega_hat={c['omega_hat']:g}: J* = {c['J_star']:.4f}, kappa = {c['kappa']:.3g}, "
                                f"K = {np.round(c['K'], 4).tolist()}" for c in r["cases"])
        else:
            from papers.p003_hang2023.design import design

            r = design(alpha=args.alpha, out=args.out)
            summary = (f"alpha = {r['performance']['alpha']:.4g}, beta = {r['performance']['beta']:.4g}, "
                       f"L1 = {np.round(r['gains']['L1'], 4).tolist()}")
    except lmi.LMIError as exc:
        print(f"design {args.name} failed: {exc}")
        print("nothing written")
        return 1
    print(f"design {args.name}: {summary}; solver {r.get('solver') or r['cases'][0]['solver']['solver']}; "
          f"all checks passed; wrote {args.out}")
    return 0


# ---------------------------------------------------------------------------------------
# verify


def _load(path):
    try:
        with open(path) as f:
            text = f.read()
    except OSError as exc:
        raise InputError(path, "-", f"cannot read file: {exc.strerror or exc}") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(path, "-", f"not valid JSON: {exc.msg} at line {exc.lineno}") from None
    if not isinstance(data, dict):
        raise InputError(path, "-", "top level must be a JSON object")
    return data


def _get(data, path, dotted, shape=None):
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
    try:
        a = np.asarray(cur, dtype=float)
    except (TypeError, ValueError):
        raise InputError(path, dotted, "not a numeric array") from None
    if shape == () and a.ndim == 0:
        pass
    elif a.shape != tuple(shape):
        raise InputError(path, dotted, f"shape {a.shape}, expected {tuple(shape)}")
    if not np.all(np.isfinite(a)):
        raise InputError(path, dotted, "contains non-finite values")
    return a if shape != () else float(a)


def _print_report(title, rep):
    print(title)
    for name, ok in rep["holds"].items():
        print(f"  {'holds' if ok else 'FAILS'}  {name}")
    print(f"  => {'all checks hold' if rep['all_hold'] else str(len(rep['failed'])) + ' check(s) fail'}")


def run_verify(args) -> int:
    _check_name(args.name)
    path = args.gains
    data = _load(path) if path else None
    if data is not None and data.get("design") not in (None, args.name):
        raise InputError(path, "design", f"file is for '{data.get('design')}', not '{args.name}'")
    ok = True
    if args.name == "li2023-observer":
        from estimator import design_li2023 as de

        if data is None:
            g = de.published_gains()
            src = "000 Appendix A.1 (published)"
        else:
            g = {"K": _get(data, path, "gains.K", (8, 3, 3)), "F1": _get(data, path, "gains.F1", (8, 3, 3)),
                 "G1": _get(data, path, "gains.G1", (8, 8, 3)), "F2": _get(data, path, "settings.F2", (3, 3)),
                 "G2": _get(data, path, "settings.G2", (8, 3)), "theta_1": _get(data, path, "settings.theta_1", ()),
                 "theta_2": _get(data, path, "settings.theta_2", ()),
                 "gamma_1": _get(data, path, "performance.gamma_1", ()) * (1 + 1e-6)}
            src = path
        rep = de.verify(**g)
        _print_report(f"verify li2023-observer ({src}): gamma_1 = {g['gamma_1']:.4f}, max H-inf = "
                      f"{rep['max_hinf']:.4f}, max disk excess = {rep['max_disk_excess']:.4g}", rep)
        ok = rep["all_hold"]
    elif args.name == "li2023-controller":
        from controller import design_li2023 as dc

        if data is None:
            g = dc.published_gains()
            K_c, gamma, src = g["K_c"], g["gamma_2"], "000 Appendix A.2 (published), disk read as O(-20, 20)"
            kw = {}
        else:
            K_c = _get(data, path, "gains.K_c", (8, 3, 3))
            gamma = _get(data, path, "performance.gamma_2", ()) * (1 + 1e-6)
            kw = {"phi": _get(data, path, "settings.phi_2", ()), "eps": _get(data, path, "settings.eps_2", ())}
            src = path
        rep = dc.verify(K_c, gamma, **kw)
        _print_report(f"verify li2023-controller ({src}): gamma_2 = {gamma:.4f}, max H-inf = {rep['max_hinf']:.4f}",
                      rep)
        ok = rep["all_hold"]
    elif args.name == "zhang2014-hinf":
        from papers.p002_zhang2014 import design as dz

        if data is None:
            cases = [(w, np.asarray(p["K"]), p["J_star"], dz.DEFAULT_J) for w, p in dz.PUBLISHED.items()]
            src = "002 Table 2 (published)"
        else:
            raw = _get(data, path, "cases")
            if not isinstance(raw, list) or not raw:
                raise InputError(path, "cases", "must be a non-empty list")
            cases = []
            for i in range(len(raw)):
                cases.append((_get(data, path, f"cases.{i}.omega_hat", ()), _get(data, path, f"cases.{i}.K", (1, 2)),
                              _get(data, path, f"cases.{i}.J_star", ()), _get(data, path, f"cases.{i}.j", ())))
            src = path
        for w, K, J, j in cases:
            rep = dz.verify(K, J, w, j)
            _print_report(f"verify zhang2014-hinf ({src}), omega_hat = {w:g}, omega in "
                          f"[{rep['interval'][0]:.3g}, {rep['interval'][1]:.3g}]: max H-inf = {rep['worst']['hinf']:.4f}"
                          f" (gamma 2.5, holds for omega >= {rep['omega_min_for_hinf']:.3g}), J* = {J:.4f}, "
                          f"simulated J_c = {rep['J_c_simulated']:.4f}", rep)
            ok &= rep["all_hold"]
    else:
        from papers.p003_hang2023 import design as dh

        if data is None:
            L1, src = dh.L1_PUBLISHED, "003 section 4 (published, signs as read)"
        else:
            L1, src = _get(data, path, "gains.L1", (2, 2)), path
        rep = dh.verify(L1)
        _print_report(f"verify hang2023-tsfdo ({src}): error-matrix abscissae {np.round(rep['abscissa'], 4).tolist()}",
                      rep)
        ok = rep["all_hold"]
    return 0 if ok else 1
