"""Parquet tables with units: :func:`write_table` (atomic, units as each field's ``b"unit"``
metadata) and :func:`read_table` (a DataFrame with ``df.attrs["units"]``).

float64 columns are written with zstd compression and the BYTE_STREAM_SPLIT encoding (the
bytes of each float grouped by position, which compresses slowly varying signals several
times better than plain float64); nothing is rounded.
"""
from __future__ import annotations

import os
import tempfile

UNIT = b"unit"


def _table(df, schema=None, units=None):
    import pyarrow as pa

    table = pa.Table.from_pandas(df, schema=schema, preserve_index=False)
    units = units or {}
    fields = []
    for f in table.schema:
        meta = dict(f.metadata or {})
        if f.name in units and units[f.name] is not None:
            meta[UNIT] = str(units[f.name]).encode("utf-8")
        fields.append(f.with_metadata(meta) if meta else f)
    return table.cast(pa.schema(fields, metadata=table.schema.metadata))


def write_table(path, df, schema=None, units=None) -> None:
    """Write ``df`` (its columns; the index is not written) to ``path`` through a temporary file
    in the same folder, flushed to disk, then renamed. ``units``: column -> unit string,
    stored as the field's ``b"unit"`` metadata."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = _table(df, schema, units)
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=".parquet", dir=folder)
    umask = os.umask(0)
    os.umask(umask)
    try:
        os.chmod(tmp, 0o666 & ~umask)
        floats = [f.name for f in table.schema if pa.types.is_floating(f.type)]
        with os.fdopen(fd, "wb") as fh:
            pq.write_table(table, fh, compression="zstd", use_dictionary=False,
                           column_encoding={c: "BYTE_STREAM_SPLIT" for c in floats} or None)
            fh.flush()
            os.fsync(fh.fileno())
        meta = pq.read_metadata(tmp)  # the footer is complete: the file is whole
        if meta.num_rows != table.num_rows:
            raise OSError(f"{path}: {meta.num_rows} rows on disk, {table.num_rows} written")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def read_table(path):
    """The table at ``path`` as a DataFrame, with ``df.attrs["units"]`` (column -> unit) from the
    fields' metadata."""
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    units = {f.name: f.metadata[UNIT].decode("utf-8") for f in table.schema
             if f.metadata and UNIT in f.metadata}
    df = table.to_pandas()
    df.attrs["units"] = units
    return df
