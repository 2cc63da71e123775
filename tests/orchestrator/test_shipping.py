"""The inputs a campaign ships to its workers (orchestrator/campaign/shipping.py), without Dask: a
worker whose disk lost the FMUs runs on the shipped copies (SHA-256 checked), a damaged copy is
refused, the kernel cache travels and never overwrites a worker's own, teardown removes what was written."""
import shutil
import tarfile
from pathlib import Path

import pytest

from orchestrator.campaign import worker
from orchestrator.campaign.expand import expand
from orchestrator.campaign.shipping import CampaignInputs, current_cache_folders, kernel_cache_archive, unpack_kernel_cache
from orchestrator.campaign.spec import load, recipe
from orchestrator.campaign.worker import execute, recipe_key

CAMPAIGN = """
[campaign]
scenario = "li2023_pd"
runs = 2
seed = 1
stop = 0.2
fmu_dir = "{fmus}"

[dispersions."plant.fault_scale"]
distribution = "uniform"
low = 0.2
high = 1.5
"""


def _plan(tmp_path, fmu_dir):
    fmus = tmp_path / "fmus"
    fmus.mkdir()
    for model in ("FlexibleSpacecraft", "PDController"):
        shutil.copy2(fmu_dir / f"{model}.fmu", fmus / f"{model}.fmu")
    p = tmp_path / "c.toml"
    p.write_text(CAMPAIGN.format(fmus=fmus), encoding="utf-8")
    c = load(p)
    return c, expand(c), fmus


@pytest.mark.fmu
def test_runs_use_the_shipped_fmus_when_the_planned_files_are_gone(tmp_path, fmu_dir):
    c, plan, fmus = _plan(tmp_path, fmu_dir)
    bases = {recipe_key(recipe(c, v)): sc for v, sc in zip(c.variants, c.bases)}
    plugin = CampaignInputs(bases, kernels=False, warm=True)
    shutil.rmtree(fmus)  # this "worker" has no FMU at the planned paths
    assert execute(plan[0])["row"]["status"] == "failed"  # without the plugin: named as missing
    local = tmp_path / "worker"
    plugin._setup(str(local))
    try:
        copies = sorted(p.name for p in local.rglob("*.fmu"))
        assert copies == ["FlexibleSpacecraft.fmu", "PDController.fmu"]
        rows = [execute(s)["row"] for s in plan]
        assert [r["status"] for r in rows] == ["ok", "ok"], [r["error"] for r in rows]
        for r in rows:  # each draw read back from the shipped FMU after set-up
            assert r["plant.fault_scale"] == r["requested:plant.fault_scale"]
        assert rows[0]["plant.fault_scale"] != rows[1]["plant.fault_scale"]
    finally:
        plugin.teardown(None)
    assert not any(local.iterdir()) and not worker._SHIPPED and not worker._LOCAL_FMUS


@pytest.mark.fmu
def test_a_damaged_shipped_copy_is_refused(tmp_path, fmu_dir):
    c, plan, fmus = _plan(tmp_path, fmu_dir)
    plugin = CampaignInputs({recipe_key(recipe(c, c.variants[0])): c.bases[0]}, kernels=False, warm=False)
    shutil.rmtree(fmus)
    path, (digest, data) = next(iter(plugin.fmus.items()))
    plugin.fmus[path] = (digest, data[:-10] + b"0123456789")
    with pytest.raises(OSError, match="damaged"):
        plugin._setup(str(tmp_path / "worker"))


def test_the_kernel_cache_travels_and_never_overwrites_a_workers_own(tmp_path):
    from plant import kernels

    if not kernels.enabled() or not current_cache_folders():
        pytest.skip("no compiled kernels in this user's cache (make warm)")
    data = kernel_cache_archive()
    with tarfile.open(fileobj=__import__("io").BytesIO(data)) as tar:
        names = {Path(n).parts[0] for n in tar.getnames()}
    assert names == {p.name for p in current_cache_folders()}
    root = tmp_path / "numba"
    own = root / sorted(names)[0]
    own.mkdir(parents=True)
    (own / "mine.nbi").write_bytes(b"the worker's own")
    added = unpack_kernel_cache(data, str(root))
    assert added == len(names) - 1
    assert sorted(p.name for p in own.iterdir()) == ["mine.nbi"]  # left as it was
    assert {p.name for p in root.iterdir()} == names
