"""The TSFDO keeps the memberships of its outputs for the step that follows (estimator/tsfdo.py): a run
of 003's own pair equals, bit for bit, the run with every membership recomputed."""
import numpy as np

import ftcsim
from estimator.tsfdo import TSFDO


def test_kept_memberships_give_the_recomputed_run(monkeypatch, tmp_path):
    from tests.arena.reduced import ROOT

    scen = ROOT / "arena" / "scenarios" / "arena_asmftc_on_hang2023.toml"
    par = {"faults.fault_class": 1.0, "faults.onset": 0.3, "faults.loss": 0.5}
    kept = ftcsim.run(str(scen), stop=0.6, mode="inprocess", parameters=par)
    original = TSFDO.outputs_at

    def forgetting(self, t, u):
        y = original(self, t, u)
        self._last = None  # advance recomputes w_hat and the memberships
        return y

    monkeypatch.setattr(TSFDO, "outputs_at", forgetting)
    recomputed = ftcsim.run(str(scen), stop=0.6, mode="inprocess", parameters=par)
    assert list(kept.df.columns) == list(recomputed.df.columns)
    assert np.array_equal(kept.df.to_numpy(), recomputed.df.to_numpy(), equal_nan=True)
