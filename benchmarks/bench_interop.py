"""Benchmark: our master vs libcosim on the same system, same FMUs, same step.

µs per macro step for li2023_fasmc (plant + FAFEO + FASMC + the attitude command), one
run each, full scenario (200 s, 10 ms):

* our master, ordered exchange (the scenario's sources in the master);
* our master, Jacobi exchange;
* our master running the exported SSP package in Jacobi mode (the command as a source
  FMU, exactly the component set libcosim runs);
* libcosim (``libcosimpy``) running the exported SSP package, in a fresh process,
  recording the same variables with a time-series observer; timed around
  ``execution.step(n)`` only (loading and instantiation excluded, as for the master,
  whose ``wall_time`` covers the stepping loop only);
* Ecos (``ecospy``, in-process) and the fmu-manipulation-toolbox container (a compiled C
  master around the same FMUs, driven by fmpy), each in a fresh process, timed around their
  stepping without recording (``orchestrator/interop/engines.py``).

Also the FMI 3.0 FMUs in our master (ordered), if ``build/fmus/fmi3`` exists.
Usage: ``python benchmarks/bench_interop.py [--scenario scenarios/li2023_fasmc.toml] [--json FILE]``
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from orchestrator.cosim.runner import run_scenario  # noqa: E402
from orchestrator.interop.engines import run_engine  # noqa: E402
from orchestrator.interop.libcosim import run_libcosim_subprocess  # noqa: E402
from orchestrator.scenario.ssp import export_ssp, load_ssp  # noqa: E402
from orchestrator.scenario.toml import load  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    from papers.registry import scenario_files

    default = scenario_files()["li2023_fasmc"]
    ap.add_argument("--scenario", default=str(default))
    ap.add_argument("--json", help="write the numbers here")
    args = ap.parse_args(argv)

    scenario = load(args.scenario)
    n = scenario.n_steps
    rows = {}
    with tempfile.TemporaryDirectory(prefix="ftcsim_bench_") as tmp:
        ssp = export_ssp(scenario, Path(tmp) / "system.ssp")
        # the other engines first, each in its own process, before this process loads any FMU;
        # each timed around its stepping only (libcosim records with an observer, the others
        # run without recording here)
        lc = run_libcosim_subprocess(ssp, Path(tmp) / "lc.npz")
        rows["libcosim (SSP, Jacobi)"] = float(lc["wall"]) / n
        for engine, label in (("ecos", "Ecos in-process (SSP)"), ("container", "toolbox container (C master, fmpy)")):
            try:
                z = run_engine(engine, ssp, Path(tmp) / f"{engine}.npz", recording=False)
                rows[label] = float(z["wall"]) / n
            except (RuntimeError, OSError) as e:  # an engine missing here: say so, measure the rest
                print(f"  {label}: not run ({' '.join(str(e).split())[:160]})")
        for ex in ("ordered", "jacobi"):
            r = run_scenario(load(args.scenario), exchange=ex)
            assert r.complete, r.error
            rows[f"ftcsim master, {ex}"] = r.wall_time / r.steps
        r = run_scenario(load_ssp(ssp), exchange="jacobi")
        assert r.complete, r.error
        rows["ftcsim master, SSP package, jacobi"] = r.wall_time / r.steps
        fmi3 = ROOT / "build" / "fmus" / "fmi3"
        if all((fmi3 / f"{i.model_name}.fmu").is_file() for i in scenario.instances.values()):
            r = run_scenario(load(args.scenario, fmu_dir=fmi3), exchange="ordered")
            assert r.complete, r.error
            rows["ftcsim master, FMI 3.0 FMUs, ordered"] = r.wall_time / r.steps

    print(f"{scenario.name}: {n} macro steps of {scenario.step:g} s, {len(scenario.instances)} FMUs "
          f"(+ the source FMU in the SSP runs), one run each")
    for k, v in rows.items():
        print(f"  {k:42s} {v * 1e6:9.1f} µs/step")
    lc_us = rows["libcosim (SSP, Jacobi)"]
    jac = rows["ftcsim master, SSP package, jacobi"]
    for k in ("ftcsim master, ordered", "ftcsim master, jacobi", "ftcsim master, SSP package, jacobi"):
        print(f"  ratio {k} / libcosim = {rows[k] / lc_us:.2f}")
    for k in ("libcosim (SSP, Jacobi)", "Ecos in-process (SSP)", "toolbox container (C master, fmpy)"):
        if k in rows:
            print(f"  ratio ftcsim master (SSP, jacobi) / {k} = {jac / rows[k]:.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps({k: v * 1e6 for k, v in rows.items()}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
