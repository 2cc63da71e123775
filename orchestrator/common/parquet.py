"""Parquet files with a declared schema, units in the field metadata, written atomically.

:func:`write_table` writes to a temporary file in the destination folder, flushes and fsyncs it,
checks its size against what was written, then renames it over the destination (``os.replace``):
a reader sees the old file or the new one, never a part. A failed write (full disk, file-size
limit, a value that does not fit the schema) raises, removes the temporary file and leaves any
previous file byte-identical. Units travel as field metadata ``b"unit"``; :func:`read_table`
returns them in ``df.attrs["units"]``.
"""
from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from orchestrator.common.reading import read_parquet

UNIT_KEY = b"unit"


def _with_units(schema: pa.Schema, units: Mapping[str, str] | None) -> pa.Schema:
    if not units:
        return schema
    fields = []
    for f in schema:
        u = units.get(f.name)
        if u is not None:
            md = dict(f.metadata or {})
            md[UNIT_KEY] = str(u).encode("utf-8")
            f = f.with_metadata(md)
        fields.append(f)
    return pa.schema(fields, metadata=schema.metadata)


def _exact(values, typ: pa.DataType) -> bool:
    """True if ``values`` (a list or a numpy array) hold only values of ``typ``'s kind (or None): the
    fast path of :func:`to_table` converts them as they are (pyarrow would truncate 1.5 into an int64)."""
    if isinstance(values, np.ndarray):
        kind = values.dtype.kind
        return (pa.types.is_floating(typ) and kind in "fiu") or (pa.types.is_integer(typ) and kind in "iu")
    if not isinstance(values, list):
        return False
    if pa.types.is_floating(typ):
        ok = (float, int, np.floating, np.integer)
    elif pa.types.is_integer(typ):
        ok = (int, np.integer)
    elif pa.types.is_string(typ) or pa.types.is_large_string(typ):
        ok = (str,)
    elif pa.types.is_boolean(typ):
        return all(v is None or isinstance(v, (bool, np.bool_)) for v in values)
    else:
        return False
    return all(v is None or (isinstance(v, ok) and not isinstance(v, (bool, np.bool_))) for v in values)


def to_table(df_or_table, schema: pa.Schema | None = None, units: Mapping[str, str] | None = None) -> pa.Table:
    """A pyarrow Table of ``df_or_table`` (DataFrame, Table or {column: values}) with ``schema``
    (columns in its order; a column missing from the data becomes nulls of the declared type;
    a column the schema does not declare is an error) and ``units`` in the field metadata."""
    if (schema is not None and not units and isinstance(df_or_table, Mapping) and set(df_or_table) <= set(schema.names)
            and all(_exact(df_or_table[f.name], f.type) for f in schema if f.name in df_or_table)):
        # {column: values} already of the declared types, straight in: no inference, no cast per column
        # (a campaign stores one row per run this way; 3 ms -> 0.3 ms a row of 50 columns)
        n = len(next(iter(df_or_table.values()))) if df_or_table else 0
        return pa.Table.from_pydict({f.name: df_or_table[f.name] if f.name in df_or_table else [None] * n
                                     for f in schema}, schema=schema)
    if isinstance(df_or_table, pa.Table):
        if schema is not None and not units and df_or_table.schema.equals(schema, check_metadata=True):
            return df_or_table  # already in the declared schema (a campaign's summary of its run files)
        table = df_or_table
    elif isinstance(df_or_table, pd.DataFrame):
        table = pa.Table.from_pandas(df_or_table, preserve_index=False)
    else:
        table = pa.table(df_or_table)
    if schema is not None:
        extra = [c for c in table.column_names if c not in schema.names]
        if extra:
            raise ValueError(f"column {extra[0]!r} is not in the declared schema")
        cols = [table.column(f.name).cast(f.type) if f.name in table.column_names
                else pa.nulls(table.num_rows, type=f.type) for f in schema]
        table = pa.Table.from_arrays(cols, schema=schema)
    else:
        table = table.replace_schema_metadata(None)  # no pandas index metadata: plain columns
    return table.cast(_with_units(table.schema, units)) if units else table


def write_table(path, df_or_table, schema: pa.Schema | None = None, units: Mapping[str, str] | None = None) -> None:
    """Write ``df_or_table`` to ``path`` atomically (see the module docstring); the folder is
    created if needed. Raises OSError (the previous file untouched) if the write fails."""
    path = Path(path)
    table = to_table(df_or_table, schema, units)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f".tmp-{os.getpid()}-{path.name}"
    try:
        with open(tmp, "wb") as f:
            pq.write_table(table, f)
            f.flush()
            written = f.tell()
            os.fsync(f.fileno())
        size = os.stat(tmp).st_size
        if size != written or size == 0:
            raise OSError(f"{path}: wrote {size} of {written} bytes")
        os.replace(tmp, path)
    finally:
        try:
            tmp.unlink()
        except FileNotFoundError:
            pass


def units_of(schema: pa.Schema) -> dict:
    """{column: unit} from the field metadata of ``schema``."""
    return {f.name: f.metadata[UNIT_KEY].decode("utf-8") for f in schema
            if f.metadata and UNIT_KEY in f.metadata}


def read_table(path, columns=None) -> pd.DataFrame:
    """A Parquet file (or a dataset folder) as a DataFrame; ``df.attrs["units"]`` = {column: unit}. A
    file is read through the one reader (:func:`orchestrator.common.reading.read_parquet`: a regular
    file of bounded size, whatever bytes its name holds; a damaged file is an ``InputError``)."""
    if os.path.isdir(path):
        table = pq.read_table(path, columns=columns)
    else:
        table = read_parquet(path, columns=columns)
    df = table.to_pandas()
    df.attrs["units"] = units_of(table.schema)
    return df


def read_folder(folder, columns=None) -> pd.DataFrame:
    """The Parquet files directly in ``folder`` (a campaign's ``trajectories/``), each through the one
    reader, as one DataFrame in file-name order (``df.attrs["units"]`` of the first)."""
    names = sorted(n for n in os.listdir(folder) if n.endswith(".parquet") and not n.startswith("."))
    tables = [read_parquet(os.path.join(folder, n), columns=columns) for n in names]
    if not tables:
        return pd.DataFrame()
    table = pa.concat_tables(tables, promote_options="default")
    df = table.to_pandas()
    df.attrs["units"] = units_of(tables[0].schema)
    return df
