"""Strict JSON written atomically (orchestrator/common/jsonio.py, what design files and metrics.json
go through) and the one place that forms structured parameter names (plant/block.py)."""
import json

import numpy as np
import pytest

from orchestrator.common.jsonio import write_json_atomic
from plant.block import structured_values


def test_atomic_json_write(tmp_path):
    f = tmp_path / "g.json"
    write_json_atomic(f, {"K": np.eye(2), "x": np.float64(1.5), "z": 1 + 2j})
    data = json.loads(f.read_text())
    assert data["K"] == [[1.0, 0.0], [0.0, 1.0]] and data["z"] == {"re": 1.0, "im": 2.0}
    with pytest.raises(TypeError):
        write_json_atomic(f, {"bad": object()})
    assert json.loads(f.read_text())["x"] == 1.5  # old file intact
    assert [p.name for p in tmp_path.iterdir()] == ["g.json"]  # no temp file left


def test_structured_names_are_one_based():
    s = structured_values("K", np.arange(8).reshape(2, 2, 2))
    assert s["K[1,1,1]"] == 0 and s["K[2,2,2]"] == 7 and len(s) == 8
