"""fmus.runtime.embedding keeps each catalog block's import probe in the user's cache folder: a
second build (the FMI 3.0 one) reads it instead of starting a Python; a damaged entry is probed again."""
import subprocess

import pytest

from fmus import runtime


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("FTCSIM_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache" / "embedding"


def test_the_second_probe_is_read_from_the_cache(cache, monkeypatch):
    first = runtime.embedding("controller.attitude", "fmus.block_runtime")
    (entry,) = list(cache.glob("*.json"))

    def no_python(*a, **k):
        raise AssertionError("probed again")

    monkeypatch.setattr(subprocess, "run", no_python)
    again = runtime.embedding("controller.attitude", "fmus.block_runtime")
    assert again == first
    monkeypatch.undo()
    monkeypatch.setenv("FTCSIM_CACHE_DIR", str(cache.parent))
    for damaged in ("{not json", '{"by_module": {"plant": 3}, "optional": []}', '{"by_module": {}, "optional": [1]}'):
        entry.write_text(damaged, encoding="utf-8")  # probed again, and rewritten
        assert runtime.embedding("controller.attitude", "fmus.block_runtime") == first
        assert '"by_module"' in entry.read_text(encoding="utf-8") and entry.read_text(encoding="utf-8") != damaged


def test_the_key_covers_the_modules_and_the_sources(cache, monkeypatch):
    a = runtime._probe_cache_file(("controller.attitude",))
    assert a != runtime._probe_cache_file(("estimator.asmfeo",))
    monkeypatch.setattr(runtime, "ROOT", cache.parent)  # another project folder (no sources): another key
    assert runtime._probe_cache_file(("controller.attitude",)) != a


def test_an_edited_source_changes_the_key_in_the_same_process(cache, tmp_path, monkeypatch):
    """A block edited after a build in a long-lived process (a notebook) is probed again."""
    (tmp_path / "plant").mkdir()
    src = tmp_path / "plant" / "block.py"
    src.write_text("x = 1\n", encoding="utf-8")
    monkeypatch.setattr(runtime, "ROOT", tmp_path)
    before = runtime._probe_cache_file(("plant.block",))
    assert runtime._probe_cache_file(("plant.block",)) == before
    src.write_text("import json\nx = 2\n", encoding="utf-8")
    assert runtime._probe_cache_file(("plant.block",)) != before
