"""orchestrator/common/parquet.py: declared schemas, units in field metadata, atomic writes
(a failed write under a file-size limit keeps the previous file byte-identical)."""
import subprocess
import sys
import textwrap

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from orchestrator.common.parquet import read_table, write_table

SCHEMA = pa.schema([pa.field("run_id", pa.int64()), pa.field("energy", pa.float64()),
                    pa.field("error", pa.string())])


def test_declared_schema_gives_typed_nulls_and_units_round_trip(tmp_path):
    p = tmp_path / "a.parquet"
    write_table(p, pd.DataFrame({"run_id": [3, 4], "error": [None, None]}), SCHEMA, units={"energy": "N m s"})
    s = pq.read_schema(p)
    assert s.field("energy").type == pa.float64() and s.field("error").type == pa.string()
    assert s.field("run_id").type == pa.int64()
    df = read_table(p)
    assert df.attrs["units"] == {"energy": "N m s"}
    assert df["run_id"].tolist() == [3, 4] and df["energy"].isna().all()


def test_a_column_outside_the_declared_schema_or_of_the_wrong_type_is_refused_and_nothing_written(tmp_path):
    p = tmp_path / "a.parquet"
    with pytest.raises(ValueError, match="not in the declared schema"):
        write_table(p, {"run_id": [1], "other": [1.0]}, SCHEMA)
    with pytest.raises((pa.ArrowInvalid, pa.ArrowTypeError, ValueError)):
        write_table(p, {"run_id": [1.5]}, SCHEMA)  # 1.5 is no run id
    assert list(tmp_path.iterdir()) == []


def test_a_write_over_the_file_size_limit_keeps_the_previous_file_byte_identical(tmp_path):
    p = tmp_path / "t.parquet"
    write_table(p, {"x": np.arange(10.0)}, units={"x": "s"})
    before = p.read_bytes()
    # a second write of ~8 MB under a 64 kB limit (RLIMIT_FSIZE; SIGXFSZ ignored so write() fails with EFBIG)
    code = textwrap.dedent(f"""
        import resource, signal, sys
        import numpy as np
        from orchestrator.common.parquet import write_table
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (65536, 65536))
        try:
            write_table({str(p)!r}, {{"x": np.random.default_rng(0).random(1_000_000)}})
        except OSError as e:
            print("failed:", e)
            sys.exit(3)
        sys.exit(0)
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 3, r.stdout + r.stderr
    assert p.read_bytes() == before
    assert sorted(x.name for x in tmp_path.iterdir()) == ["t.parquet"]  # no temporary file left
    assert read_table(p)["x"].tolist() == list(np.arange(10.0))


@pytest.mark.parametrize("data", [
    {"run_id": [7], "energy": [2], "error": [None]},  # an int where float64 is declared
    {"run_id": [np.int64(7)], "energy": [np.float64(0.5)]},  # numpy scalars, a missing column
    {"run_id": np.arange(3), "energy": np.linspace(0, 1, 3), "error": ["a", None, "c"]},
    {"run_id": [7], "energy": [True]},  # a bool is no energy: the general path decides
    {"run_id": [7.0], "energy": [1.0]},  # a float run id: the general path casts it (7.0 is exact)
])
def test_typed_values_go_straight_in_with_the_general_paths_result(data):
    from orchestrator.common.parquet import to_table

    general = to_table(pa.table({k: list(v) for k, v in data.items()}), SCHEMA)
    assert to_table(data, SCHEMA).equals(general)
    assert to_table(data, SCHEMA).schema == SCHEMA
