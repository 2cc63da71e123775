"""make demo (orchestrator/tools/demo.py, issue 36): every target checked before anything runs, the
cheapest paper's runs first then the longest, a closing table from each report's counts
(papers.reproduction.headline), at most 40 lines without -v and the solvers' logs with it."""
import json
import subprocess
import sys
from pathlib import Path

from orchestrator.tools import demo
from papers.reproduction import PRINTED, READING, Row, close, headline, summarize, to_json

ROOT = Path(__file__).resolve().parents[2]


def test_a_foreign_folder_in_the_way_stops_the_demo_before_anything_runs(tmp_path, capsys):
    out = tmp_path / "results"
    (out / "zhang2014_hinf_w05").mkdir(parents=True)
    (out / "zhang2014_hinf_w05" / "notes.txt").write_text("mine")
    assert demo.main(["--out", str(out), "--paper", "002"]) == 2
    err = capsys.readouterr().err
    assert "zhang2014_hinf_w05 exists and is not a run folder" in err and "nothing was run" in err
    assert sorted(p.name for p in out.iterdir()) == ["zhang2014_hinf_w05"]
    assert (out / "zhang2014_hinf_w05" / "notes.txt").read_text() == "mine"


def test_an_unknown_paper_is_refused(tmp_path, capsys):
    assert demo.main(["--out", str(tmp_path / "r"), "--paper", "li2032"]) == 2
    assert "unknown paper 'li2032'" in capsys.readouterr().err and not (tmp_path / "r").exists()


def test_the_cheapest_paper_goes_first_then_the_longest_runs(tmp_path):
    plans = demo.plan(tmp_path)
    queue = demo.order(plans)
    first = min(plans, key=lambda pp: pp.cost)
    head = queue[:len(first.runs)]
    assert {pp.id for pp, _, _ in head} == {first.id}
    costs = [demo.run_cost(name) for _, name, _ in queue[len(first.runs):]]
    assert costs == sorted(costs, reverse=True) and len(queue) == sum(len(pp.runs) for pp in plans)


def test_the_closing_table_prints_each_reports_headline(tmp_path):
    rows = [Row("Fig. 1 settling time [s]", 10.0, 13.5, close(), reading="as printed", kind=PRINTED),
            Row("Fig. 1 settling time [s]", 10.0, 10.2, close(), reading="our reading", kind=READING),
            Row("Table 2 overshoot", 0.2, 0.9, close(), reading="as printed", kind=PRINTED)]
    report = tmp_path / "report_x"
    report.mkdir()
    (report / "report.json").write_text(json.dumps({"reproduction": to_json(rows)}))
    pp = demo.PaperPlan("009", "x2030", "X", [], report, finished=1.0)
    table = demo.closing_table([pp])
    assert table[2].startswith("009 x2030") and headline(summarize(rows)) in table[2]
    assert "literal 0/2, best reading 1/2" in table[2]  # the item reproduced under our reading only
    assert str(report / "report.html") in table[2] or "report_x/report.html" in table[2]


def _demo(tmp_path, *extra):
    return subprocess.run([sys.executable, "-m", "orchestrator.tools.demo", "--out", str(tmp_path / "results"),
                           "--paper", "002", *extra], capture_output=True, text=True, cwd=tmp_path, timeout=1800,
                          env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg",
                               "HOME": str(Path.home())})


def test_one_paper_quietly_then_verbosely(tmp_path):
    """Paper 002 (3 runs and its report): a header, one line for the paper, the first report's
    time, the table and the index, no solver output; -v adds what the runs and the report printed
    (the LMI solver's log)."""
    p = _demo(tmp_path)
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    assert len(lines) <= 40 and "CLARABEL" not in p.stdout + p.stderr, p.stdout
    assert any(ln.startswith("002 zhang2014") and "report_zhang2014/report.html" in ln for ln in lines)
    table = lines.index(next(ln for ln in lines if ln.startswith("paper ")))
    assert lines[table + 2].startswith("002 zhang2014") and "literal " in lines[table + 2]
    assert lines[-1].endswith("results/index.html") and (tmp_path / "results" / "index.html").is_file()
    v = _demo(tmp_path, "-v")  # the folders of the first demo are replaced
    assert v.returncode == 0, v.stderr
    assert "CLARABEL" in v.stdout and "# " in v.stdout  # the solver's log, the report's Markdown
