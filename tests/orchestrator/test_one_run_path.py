"""`ftcsim run` (the command line) and `ftcsim.run` (the API) go through one code path: the
command line loads with `orchestrator.api.load` and runs with `orchestrator.api.run`, which hands
the validated scenario to the engine (`orchestrator.cosim.runner.run_scenario`) once."""
import numpy as np

import ftcsim
from orchestrator import api
from orchestrator.cli.main import main
from orchestrator.results.files import read_results

SHORT = "li2023_pd"


def test_command_line_and_api_share_the_run_path(tmp_path, monkeypatch, capsys):
    seen = []
    engine = api.run_scenario

    def spy(scenario, **kw):
        seen.append((scenario, kw))
        return engine(scenario, **kw)

    monkeypatch.setattr(api, "run_scenario", spy)
    r = ftcsim.run(SHORT, mode="inprocess", stop=2.0)
    assert main(["run", SHORT, "--mode", "inprocess", "--out", str(tmp_path / "cli"), "--no-plots",
                 "--quiet"]) == 0
    assert len(seen) == 2  # the API's run and the command line's
    (api_sc, _), (cli_sc, cli_kw) = seen
    assert api_sc.name == cli_sc.name == SHORT and api_sc.mode == cli_sc.mode == "inprocess"
    assert cli_kw["progress"] is False
    # the same scenario up to the stop override: the same rows where they overlap, bit for bit
    header, data = read_results(tmp_path / "cli")
    assert header[1:] == list(r.df.columns)
    n = len(r.df)
    assert np.array_equal(data[:n, 0], r.df.index.to_numpy()) and np.array_equal(data[:n, 1:], r.df.to_numpy())


def test_api_run_writes_what_the_command_line_writes(tmp_path):
    r = ftcsim.run(SHORT, mode="inprocess", stop=1.0, out=tmp_path / "api")
    assert main(["run", SHORT, "--mode", "inprocess", "--out", str(tmp_path / "cli"), "--no-plots", "--quiet"]) == 0
    ha, a = read_results(tmp_path / "api")
    hc, c = read_results(tmp_path / "cli")
    assert ha == hc and np.array_equal(a, c[:len(a)])  # the API's run stops at 1 s
    assert r.complete and r.errors == []
