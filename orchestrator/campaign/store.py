"""What a campaign folder holds: one Parquet file per finished run (written atomically), the
trajectories, the summary table combined from the runs, and the manifest (versions, FMUs, sessions)."""
from __future__ import annotations

import hashlib
import sys
from importlib import metadata
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from orchestrator.campaign.expand import file_digest
from orchestrator.campaign.schema import conform, schema
from orchestrator.common.errors import InputError
from orchestrator.common.outputs import store_folder
from orchestrator.common.parquet import to_table, write_table
from orchestrator.common.reading import MAX_DATA_BYTES, open_regular, read_bytes, read_json

SUMMARY = "summary.parquet"
MANIFEST = "manifest.json"
CAMPAIGN_COPY = "campaign.toml"
RUNS = "runs"
TRAJECTORIES = "trajectories"
EXECUTION_COLUMNS = ("wall_time_s", "cpu_time_s", "sim_time_s", "worker")


def run_file(spec_or_row) -> str:
    run_id = spec_or_row.run_id if hasattr(spec_or_row, "run_id") else spec_or_row["run_id"]
    key = spec_or_row.key if hasattr(spec_or_row, "key") else spec_or_row["key"]
    return f"{run_id:07d}-{key}.parquet"


def store(folder: Path, result: dict, columns, trajectory_columns=None) -> None:
    """Write one finished run durably: its trajectory, then its row, both in the campaign's
    declared schema (:mod:`orchestrator.campaign.schema`; ``columns``: [(name, type, unit)])."""
    row = conform(result["row"], columns)
    name = run_file(row)
    if result.get("trajectory"):
        tr = result["trajectory"]
        n = len(tr["time"])
        data = {"run_id": np.full(n, row["run_id"], dtype=np.int64)}
        data.update({k: np.asarray(v, dtype=float) for k, v in tr.items()})
        write_table(store_folder(folder, TRAJECTORIES) / name, data,
                    schema(trajectory_columns) if trajectory_columns else None)
    # never through a symbolic link: a runs/ that is a link (into another campaign) is refused, not followed
    write_table(store_folder(folder, RUNS) / name, {n: [row[n]] for n, _, _ in columns}, schema(columns))


def stored(folder: Path) -> dict:
    """{(run_id, key): file} of the run files in a campaign folder (by their names; see :func:`read_run`)."""
    out = {}
    runs = store_folder(folder, RUNS, create=False)
    if not runs.is_dir():
        return out
    for p in runs.glob("*.parquet"):
        rid, _, key = p.stem.partition("-")
        if rid.isdigit() and key:
            out[(int(rid), key)] = p
    return out


class DamagedRun(Exception):
    """A run file that does not hold what its name says, in the campaign's schema."""


def read_run(path: Path, run_id: int, key: str, columns):
    """The run file ``path`` as a one-row table in the declared schema, verified: readable, one row,
    the run id and key of its name, only declared columns of castable types. Raises DamagedRun."""
    try:  # one file through the one reader (regular, bounded); no dataset discovery (10x faster than read_table)
        with open_regular(path, "run file", limit=MAX_DATA_BYTES) as fh, pq.ParquetFile(fh) as f:
            t = f.read()
    except InputError as e:
        raise DamagedRun(e.problem) from None
    except Exception as e:
        raise DamagedRun(f"unreadable ({' '.join(str(e).split())[:120]})") from None
    if t.num_rows != 1:
        raise DamagedRun(f"holds {t.num_rows} rows, not 1")
    declared = [n for n, _, _ in columns]
    extra = [n for n in t.column_names if n not in declared]
    if extra:
        raise DamagedRun(f"column {extra[0]!r} is not in the campaign's schema")
    if "run_id" not in t.column_names or "key" not in t.column_names:
        raise DamagedRun("has no run_id or key column")
    rid, k = t.column("run_id")[0].as_py(), t.column("key")[0].as_py()
    if rid != run_id or k != key:
        raise DamagedRun(f"holds run {rid} (key {k}), not run {run_id} (key {key})")
    try:
        return to_table(t, schema(columns))
    except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError, ValueError) as e:
        raise DamagedRun(f"columns not of the campaign's types ({' '.join(str(e).split())[:120]})") from None


def verified(folder: Path, plan, columns) -> tuple[dict, dict]:
    """({(run_id, key): table} of the sound stored runs of ``plan``, {file name: problem} of the damaged ones)."""
    have = stored(folder)
    good, damaged = {}, {}
    for s in plan:
        p = have.get((s.run_id, s.key))
        if p is None:
            continue
        try:
            good[(s.run_id, s.key)] = read_run(p, s.run_id, s.key, columns)
        except DamagedRun as e:
            damaged[f"{RUNS}/{p.name}"] = str(e)
    return good, damaged


def combine(folder: Path, plan, columns) -> tuple[int, dict]:
    """Write summary.parquet from the sound stored runs of ``plan`` (run-id order, declared schema);
    returns (row count, {file name: problem} of damaged run files left out)."""
    good, damaged = verified(folder, plan, columns)
    sch = schema(columns)
    tables = [good[(s.run_id, s.key)] for s in plan if (s.run_id, s.key) in good]
    table = pa.concat_tables(tables) if tables else sch.empty_table()
    write_table(folder / SUMMARY, table, sch)
    return table.num_rows, damaged


def _versions() -> dict:
    out = {"python": sys.version.split()[0]}
    for pkg in ("ftcsim", "numpy", "scipy", "fmpy", "pythonfmu", "pythonfmu3", "dask", "distributed", "pyarrow",
                "pandas"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def _fmus(c) -> list:
    seen = {}
    for sc in c.bases:
        for inst in sc.instances.values():
            if inst.fmu is None or str(inst.fmu) in seen:
                continue
            md = inst.model_description
            seen[str(inst.fmu)] = {"path": str(inst.fmu), "sha256": file_digest(inst.fmu), "model": md.modelName,
                                   "fmi_version": md.fmiVersion, "guid": md.guid, "generation_tool": md.generationTool,
                                   "generated": md.generationDateAndTime}
    return list(seen.values())


def manifest(c, plan) -> dict:
    return {
        "campaign": c.name, "description": c.description, "campaign_file": str(c.path.resolve()),
        "campaign_sha256": c.digest, "runs": len(plan), "draws": c.runs, "seed": c.seed, "mode": c.mode,
        "variants": [{"name": v.name, "scenario": v.scenario, "fmus": v.fmus, "gains": v.gains,
                      "parameters": v.parameters, "dropped_parameters": v.dropped} for v in c.variants],
        "grid": [{"parameter": r, "values": vals} for r, vals in c.grid],
        "dispersions": [{"parameter": d.ref, "distribution": d.distribution, "apply": d.apply, "shared": d.shared,
                         "elements": [f"{d.inst}.{n}" for n in d.names]} for d in c.dispersions],
        "settling": c.settling, "requirements": c.requirements,
        "trajectories": c.trajectories, "trajectory_step": c.trajectory_step,
        "versions": _versions(), "fmus": _fmus(c), "sessions": [], "status": "running",
    }


def read_manifest(folder: Path) -> dict:
    try:
        return read_json(folder / MANIFEST, "manifest", strict=False)
    except InputError:
        return {}


def started_with(folder: Path) -> str | None:
    """SHA-256 of the campaign file a campaign folder was started with: the manifest's, or, when
    manifest.json is damaged, that of the folder's copy of the campaign file (None if neither)."""
    digest = read_manifest(folder).get("campaign_sha256")
    if isinstance(digest, str):
        return digest
    try:
        return hashlib.sha256(read_bytes(folder / CAMPAIGN_COPY, "campaign file")).hexdigest()
    except InputError:
        return None


def manifest_damaged(folder: Path) -> bool:
    return not isinstance(read_manifest(folder).get("campaign_sha256"), str)
