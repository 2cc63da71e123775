"""``make demo``: every paper's demo scenarios (``Paper.demo``), then each paper's report, on every
available core, with one line per paper and a closing table.

    python -m orchestrator.tools.demo [--out results] [--paper 000] [--jobs N] [-v]

Runs go to ``OUT/<scenario>`` (results and metrics; the runs' own plots are left out, a seventh of
the demo's time: the reports draw the figures, and ``ftcsim run NAME`` draws a run's), reports to
``OUT/report_<paper key>`` (``report.md`` and ``report.html``, the same report as one page), and
``OUT/index.html`` links them all (its path is printed last). The runs and reports are independent
jobs (a paper's report waits for its runs) on ``--jobs`` worker processes (default: the cores
this process may use): the paper with the least work first, so that its report exists early, then
the longest runs first; a report goes ahead of the runs still waiting.

What it prints: one line per paper (on a terminal a live line with its runs done and the time; in a
log one line once its report exists, with its path), then a table of every paper's items reproduced
under the literal readings and under the best documented reading (``papers.reproduction.headline``
of the report's ``report.json``) and the report's path, then the index's path. ``-v`` adds what each
run and report printed (solver logs, the reports' Markdown), job by job.

Folders of an earlier demo are replaced (they carry ftcsim's marker); anything else in the way
stops the demo before anything runs, with a clear message, and is left untouched.
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import multiprocessing
import os
import signal
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from orchestrator.common.errors import InputError
from orchestrator.common.outputs import is_result_folder
from orchestrator.common.process_exit import finish
from orchestrator.common.progress import is_terminal
from orchestrator.results.report import reproduction_headline, write_index
from orchestrator.scenario.shipped import papers, scenario_files
from orchestrator.scenario.toml import read_document


@dataclass
class PaperPlan:
    """What the demo does for one paper: its runs (scenario, folder, estimated cost) and its report."""

    id: str
    key: str
    title: str
    runs: list  # [(scenario, folder, cost)]
    report: Path | None
    done: int = 0
    started: float | None = None
    finished: float | None = None
    failed: str | None = None
    outputs: list = field(default_factory=list)  # (what, captured text) in completion order

    @property
    def cost(self) -> float:
        return sum(c for _, _, c in self.runs)

    @property
    def label(self) -> str:
        return f"{self.id} {self.key}"


def run_cost(name: str) -> float:
    """Work of a shipped scenario, for ordering: communication steps x (instances + 1)."""
    doc = read_document(scenario_files()[name])
    t = doc.get("timing", {})
    steps = (float(t.get("stop", 1.0)) - float(t.get("start", 0.0))) / float(t.get("step", 0.01))
    return steps * (len(doc.get("instances", {})) + 1)


def plan(out: Path, only=None) -> list[PaperPlan]:
    """Every selected paper with demo runs; each target folder checked before anything runs."""
    plans = []
    for p in papers():
        if only and p.id not in only and p.key not in only:
            continue
        if not p.demo:
            continue
        runs = [(name, out / name, run_cost(name)) for name in p.demo]
        plans.append(PaperPlan(p.id, p.key, p.title, runs, out / f"report_{p.key}" if p.report else None))
    if only:
        known = {x for p in papers() for x in (p.id, p.key)}
        unknown = [x for x in only if x not in known]
        if unknown:
            raise InputError("command line", "--paper", f"unknown paper {unknown[0]!r} (known: "
                             f"{', '.join(p.id + ' ' + p.key for p in papers())})")
    for pp in plans:
        targets = [(f, "run") for _, f, _ in pp.runs] + ([(pp.report, "report")] if pp.report else [])
        for folder, kind in targets:
            if (folder.exists() or folder.is_symlink()) and (folder.is_symlink() or not is_result_folder(folder, kind)):
                raise InputError("command line", "--out", f"{folder} exists and is not a {kind} folder of an earlier "
                                 "demo: nothing was run; move it away or choose another --out")
    return plans


def order(plans: list[PaperPlan]) -> list[tuple[PaperPlan, str, Path]]:
    """The runs in the order they start: the cheapest paper's runs first (its report comes early),
    then every other run, the longest first (the shortest total time on a few cores)."""
    if not plans:
        return []
    first = min(plans, key=lambda pp: pp.cost)
    head = [(first, n, f, c) for n, f, c in first.runs]
    rest = sorted(((pp, n, f, c) for pp in plans if pp is not first for n, f, c in pp.runs), key=lambda x: -x[3])
    return [(pp, n, f) for pp, n, f, _ in head + rest]


# -- the worker side ---------------------------------------------------------------------------

def _worker_init() -> None:
    """A worker leaves Ctrl-C to the demo (which stops it), and draws no window."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.environ.setdefault("MPLBACKEND", "Agg")


def _job(argv: list[str]) -> tuple[int, float, str]:
    """``ftcsim ARGV`` in this worker with its stdout and stderr (solver logs of compiled libraries
    too: file descriptors 1 and 2) captured: (exit status, seconds, what it printed)."""
    from orchestrator.cli.main import main as ftcsim

    t0 = time.monotonic()
    with tempfile.TemporaryFile(mode="w+b") as cap:
        sys.stdout.flush()
        sys.stderr.flush()
        saved = os.dup(1), os.dup(2)
        os.dup2(cap.fileno(), 1)
        os.dup2(cap.fileno(), 2)
        try:
            rc = ftcsim(argv)
        except SystemExit as e:  # argparse
            rc = e.code if isinstance(e.code, int) else 2
        except BaseException as e:  # noqa: BLE001 - reported as the job's failure
            print(f"ftcsim: internal error: {type(e).__name__}: {e}", file=sys.stderr)
            rc = 1
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
        cap.seek(0)
        text = cap.read().decode("utf-8", "replace")
    return rc, time.monotonic() - t0, text


# -- the display --------------------------------------------------------------------------------

class Display:
    """One line per paper: redrawn in place on a terminal, else printed once the paper is done."""

    def __init__(self, plans: list[PaperPlan], t0: float, stream=None):
        self.plans, self.t0 = plans, t0
        self.stream = stream or sys.stdout
        self.live = is_terminal(self.stream) and os.environ.get("TERM") != "dumb"
        self.drawn = 0
        self.announced: set = set()
        self.width = max((len(pp.label) for pp in plans), default=0)

    def text(self, pp: PaperPlan) -> str:
        n = len(pp.runs)
        if pp.started is None:
            state = "waiting"
            took = ""
        else:
            end = pp.finished or time.monotonic()
            took = f"{end - pp.started:5.0f} s"
            if pp.failed:
                state = f"FAILED: {pp.failed}"
            elif pp.finished is not None:
                state = f"report: {_shown(pp.report / 'report.html')}" if pp.report else "no report"
            elif pp.done == n and pp.report:
                state = "writing the report"
            else:
                state = "running"
        runs = f"{pp.done}/{n} runs"
        return f"{pp.label:{self.width}s}  {runs:>10s}  {took:>7s}  {state}"

    def update(self, changed: PaperPlan | None = None) -> None:
        """Redraw (terminal); else print ``changed``'s line once, when it has finished."""
        if self.live:
            out = self.stream
            if self.drawn:
                out.write(f"\x1b[{self.drawn}F")  # back to the first paper line
            for pp in self.plans:
                out.write("\x1b[2K" + self.text(pp) + "\n")
            self.drawn = len(self.plans)
            out.flush()
        elif changed is not None and changed.finished is not None and changed.label not in self.announced:
            self.announced.add(changed.label)
            print(self.text(changed), file=self.stream, flush=True)

    def say(self, text: str) -> None:
        """A message above the live lines (or a plain line)."""
        if self.live and self.drawn:
            self.stream.write(f"\x1b[{self.drawn}F\x1b[J")
            self.drawn = 0
        print(text, file=self.stream, flush=True)
        if self.live:
            self.update()


def _shown(path: Path) -> str:
    """``path`` relative to the working folder when it lies below it, else absolute."""
    p = Path(path).absolute()
    try:
        return str(p.relative_to(Path.cwd()))
    except ValueError:
        return str(p)


def closing_table(plans: list[PaperPlan]) -> list[str]:
    """paper | items reproduced (literal readings / best documented reading) | report."""
    rows = []
    for pp in plans:
        counts = reproduction_headline(pp.report) if pp.report and pp.finished and not pp.failed else None
        rows.append((pp.label, counts or ("failed" if pp.failed else "no reproduction table"),
                     _shown(pp.report / "report.html") if pp.report and pp.finished and not pp.failed else "-"))
    head = ("paper", "items reproduced", "report")
    w = [max(len(r[i]) for r in [head, *rows]) for i in range(3)]
    lines = ["  ".join(c.ljust(w[i]) for i, c in enumerate(head)).rstrip(),
             "  ".join("-" * w[i] for i in range(3))]
    lines += ["  ".join(c.ljust(w[i]) for i, c in enumerate(r)).rstrip() for r in rows]
    return lines


# -- the demo ------------------------------------------------------------------------------------

def available_cores() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m orchestrator.tools.demo", description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results", help="results folder (default results)")
    ap.add_argument("--paper", action="append", help="only these papers (id or key; repeatable); default all")
    ap.add_argument("--jobs", type=int, default=None, help="runs and reports at once (default: the available cores)")
    ap.add_argument("-v", "--verbose", action="store_true", help="also print what every run and report printed "
                    "(solver logs, the reports' Markdown)")
    args = ap.parse_args(argv)
    if args.jobs is not None and args.jobs < 1:
        print(f"ftcsim: error: command line: --jobs: must be >= 1, got {args.jobs}", file=sys.stderr)
        return 2
    out = Path(args.out)
    try:
        plans = plan(out, args.paper)
    except InputError as e:
        print(f"ftcsim: error: {e}", file=sys.stderr)
        return 2
    jobs = args.jobs or available_cores()
    n_runs = sum(len(pp.runs) for pp in plans)
    print(f"ftcsim demo: {len(plans)} papers, {n_runs} runs and {sum(bool(pp.report) for pp in plans)} reports, "
          f"{jobs} at a time, into {_shown(out)}/", flush=True)
    t0 = time.monotonic()
    rc = execute(plans, jobs, out, args.verbose, t0)
    if rc not in (0, None):
        return rc
    for line in closing_table(plans):
        print(line)
    try:
        index = write_index(out)
    except InputError as e:
        print(f"ftcsim: error: {e}", file=sys.stderr)
        return 2
    print(f"{n_runs} runs and {sum(1 for pp in plans if pp.report)} reports in {time.monotonic() - t0:.0f} s; "
          f"every run and report: {index.resolve()}")
    return 0


def execute(plans: list[PaperPlan], jobs: int, out: Path, verbose: bool, t0: float) -> int:
    """Every run, and each paper's report once its runs are done, on ``jobs`` worker processes."""
    queue = order(plans)
    display = Display(plans, t0)
    display.update()
    first_report = None
    ready: list[PaperPlan] = []  # papers whose runs are done, report not started
    running: dict = {}
    status = 0
    ctx = multiprocessing.get_context("spawn")  # no FMU library inherited by a fork
    pool = cf.ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_worker_init)
    try:
        while queue or ready or running:
            while len(running) < jobs and (ready or queue) and not status:
                if ready:
                    pp = ready.pop(0)
                    argv = ["report", *(str(f) for _, f, _ in pp.runs), "--out", str(pp.report), "--overwrite"]
                    running[pool.submit(_job, argv)] = (pp, "report", pp.report)
                else:
                    pp, name, folder = queue.pop(0)
                    pp.started = pp.started or time.monotonic()
                    argv = ["run", name, "--out", str(folder), "--overwrite", "--quiet", "--no-plots"]
                    running[pool.submit(_job, argv)] = (pp, name, folder)
            if not running:
                break
            done, _ = cf.wait(running, return_when=cf.FIRST_COMPLETED)
            for fut in done:
                pp, what, folder = running.pop(fut)
                try:
                    rc, secs, text = fut.result()
                except Exception as e:  # noqa: BLE001 - a worker that died (a crashing FMU): that job failed
                    rc, secs, text = 1, 0.0, f"the worker running it stopped: {type(e).__name__}: {e}"
                pp.outputs.append((what, text))
                if verbose:
                    display.say(f"--- {what} ({secs:.1f} s, exit {rc}) ---\n{text.rstrip()}")
                    if what == "report" and rc == 0 and (folder / "report.md").is_file():
                        display.say((folder / "report.md").read_text(encoding="utf-8").rstrip())
                if rc != 0:
                    pp.failed = f"{what} exit {rc}"
                    pp.finished = time.monotonic()
                    status = status or rc
                    display.say(f"ftcsim demo: {what} failed (exit {rc}); what it printed:\n{text.rstrip()}")
                elif what == "report":
                    pp.finished = time.monotonic()
                    if first_report is None:
                        first_report = pp.finished
                else:
                    pp.done += 1
                    if pp.done == len(pp.runs):
                        if pp.report:
                            ready.append(pp)
                        else:
                            pp.finished = time.monotonic()
                display.update(pp)
        pool.shutdown(wait=True)
    except KeyboardInterrupt:  # the runs in flight stop on their own SIGINT (kept, marked incomplete)
        pool.shutdown(wait=True, cancel_futures=True)
        print("ftcsim demo: interrupted", file=sys.stderr)
        return 130
    if status:
        return status
    if first_report is not None:
        print(f"first report after {first_report - t0:.0f} s")
    return 0


if __name__ == "__main__":  # pragma: no cover
    finish(main())
