"""Shared fixtures: the built FMUs (FMI 2.0 and 3.0, rebuilt if any source is newer) and the
shipped scenarios by name. Safe under pytest-xdist: one worker builds, under a file lock."""
import fcntl
import os
from contextlib import contextmanager
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FMU_DIR = ROOT / "build" / "fmus"
FMI3_DIR = FMU_DIR / "fmi3"
SOURCE_DIRS = ("plant", "estimator", "controller", "diagnosis", "fmus", "papers", "arena", "orchestrator/interop/basilisk")


def _stale(folder: Path, names) -> bool:
    sources = [p for d in SOURCE_DIRS for p in (ROOT / d).rglob("*.py")]
    sources += [p for p in (ROOT / "fmus" / "native").rglob("*") if p.is_file()]  # the export library's C sources
    newest = max(p.stat().st_mtime for p in sources)
    return any(not (folder / f"{n}.fmu").is_file() or (folder / f"{n}.fmu").stat().st_mtime < newest for n in names)


@contextmanager
def _build_lock():
    FMU_DIR.mkdir(parents=True, exist_ok=True)
    with open(FMU_DIR / ".test-build-lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        yield


def built(fmi: str) -> Path:
    """The folder of every catalog FMU for FMI version ``fmi``, built now if missing or stale."""
    from fmus.build import build_all
    from papers.registry import fmu_specs

    folder = FMU_DIR if fmi == "2" else FMI3_DIR
    specs = {m: s for m, s in fmu_specs().items() if s.available()}  # the Basilisk plant needs ftcsim[basilisk]
    with _build_lock():
        if _stale(folder, specs):
            build_all(folder, specs.values(), fmi=fmi)
    return folder


@pytest.fixture(scope="session")
def fmu_dir() -> Path:
    """build/fmus with every FMU of the catalog (FMI 2.0)."""
    folder = built("2")
    os.environ["FTCSIM_FMU_DIR"] = str(folder)
    return folder


@pytest.fixture(scope="session")
def fmi3_dir() -> Path:
    """build/fmus/fmi3 with every FMU of the catalog as FMI 3.0."""
    return built("3")


@pytest.fixture(scope="session", params=["2", "3"], ids=["fmi2", "fmi3"])
def any_fmu_dir(request) -> tuple[str, Path]:
    """(FMI version, folder): tests that must hold for both FMI versions."""
    built("2")
    return request.param, built(request.param)


class ScenarioFiles:
    """``scenarios / "li2023_pd.toml"`` -> the shipped scenario of that name (any paper's folder)."""

    def __truediv__(self, name) -> Path:
        from papers.registry import scenario_files

        return scenario_files()[Path(name).stem]


@pytest.fixture(scope="session")
def scenarios() -> ScenarioFiles:
    return ScenarioFiles()


@pytest.fixture(scope="session")
def c_fmu(tmp_path_factory) -> Path:
    """CAttitudePD.fmu: a C FMU (FMI 2.0 co-simulation, not made by pythonfmu) compiled with gcc from
    tests/fmus/third_party/ into a temporary folder (tests/third_party_fmu.py)."""
    from third_party_fmu import build_c_fmu

    return build_c_fmu(tmp_path_factory.mktemp("c_fmu"))


# Integration tests that take minutes on 2 cores: `make test-long` runs them, `make test` (the
# 6-minute suite) leaves them out. Each is an acceptance test of an issue; the list says which.
LONG = (
    # issue 36: every page's blocks in one folder after make demo, outputs compared (about 15 min); the
    # blocks of seconds stay in make test (test_fast_blocks_as_documented)
    "tests/docs/test_docs_run.py::test_docs_in_full",
    "tests/orchestrator/test_demo.py::test_one_paper_quietly_then_verbosely",  # issue 36: paper 002's demo twice (about 1 min)
    "tests/orchestrator/test_campaign_cluster.py",  # issue 25: scheduler file, killed worker, shipped FMUs
    "tests/orchestrator/test_bad_input_cluster.py::test_a_scheduler_without_workers",  # Dask processes
    "tests/orchestrator/test_bad_input_cluster.py::test_a_run_that_kills_its_worker",  # Dask processes
    "tests/plant/test_kernel_cache_damage.py",  # recompiles the kernels
    "tests/arena/test_arena.py",  # issues 26, 33: a reduced arena end to end, leaderboard in Chromium, FMUs = blocks
    # issue 33: 003's own pair over its 60 s mission at 0.5 ms (25 s); the other plants' missions stay
    "tests/arena/test_missions.py::test_the_papers_own_method_settles_within_its_plants_mission[hang2023]",
    "tests/fmus/test_host_exit.py",  # issue 24: 20 plain exits per FMI version (about 60 s)
    "tests/fmus/test_external_hosts.py",  # issue 24: Ecos in-process and CLI
    # issue 37: the hostile host on every FMU (about 1 min per FMI version), its table under valgrind (about 40 s
    # per FMU: 8 FMUs of every kind per version); make test runs three FMUs and the C host
    "tests/fmus/test_hostile_host.py::test_hostile_host_on_every_fmu",
    "tests/fmus/test_hostile_host.py::test_hostile_host_under_valgrind",
    "tests/fmus/test_hostile_host.py::test_fmpy_simulates_every_fmu_with_tmpdir_named_like_a_uri_trap",  # 30 s each
    "tests/fmus/test_divergence_in_other_hosts.py",  # issue 37: the diverging package in libcosim and Ecos (1-2 min)
    "tests/fmus/test_engines_fmi3.py",  # issue 37: li2023_pd's FMI 3 package in Ecos and the container (minutes)
    "tests/fmus/test_other_python_hosts.py",  # issue 37: fmuloader and PathSim (3 s per host and FMI version)
    "tests/orchestrator/test_engines.py",  # other FMI engines (libcosim, Ecos, the toolbox container)
    "tests/orchestrator/test_campaign_dask.py::test_sigint_stops_cleanly",  # a LocalCluster stopped by SIGINT
    "tests/orchestrator/test_paper_reports.py::test_report_of_every_papers_demo_runs[zhang2014]",  # li2023, xu2024 stay
    "tests/orchestrator/test_paper_reports.py::test_report_of_every_papers_demo_runs[zhang2019]",
    "tests/orchestrator/test_paper_reports.py::test_report_of_every_papers_demo_runs[hang2023]",
    "tests/papers/p003_hang2023/test_hang2023_delivered.py",  # issue 21: three 25 s runs at 0.5 ms
    "tests/controller/test_fontsm_host_steps.py::test_zhang2019_fontsm_runs_to_25_s",  # issue 24: 25,000 t += h steps
    "tests/orchestrator/test_time_and_failures.py",  # issue 20: hung and crashing FMUs in run, campaign, compare
    # the numpy path of li2023_fasmc over 120 s through FMUs, by checksum (15 s): li2023_pd keeps the checksum
    # in make test, and li2023_fasmc's kernel path is compared with the same stored rows to 1e-10
    "tests/papers/p000_li2023/test_results_unchanged.py::test_reference_path_unchanged[li2023_fasmc]",
    # numba compiling the flexible craft's kernels into an empty cache from inside an FMU (15 s); every FMU
    # run of make test uses the kernels from the shared cache
    "tests/fmus/test_kernels_fmu.py::test_fmu_with_numba_runs_the_kernels_and_caches_outside",
    # 004's Theorem 2 design solved again (11 s) to match the stored study that make test's verdicts read
    "tests/papers/p004_xu2024/test_xu2024_c2.py::test_printed_averaging_with_small_alpha_gives_the_printed_c2",
    "tests/orchestrator/test_paper_reports.py::test_report_of_every_papers_demo_runs[xu2024]",  # li2023's stays
    "tests/orchestrator/test_safety.py::test_signal_part_way_keeps_an_incomplete_readable_run[15-143]",  # SIGINT stays
    # issue 31: README's and each paper README's reproduction counts from every paper's demo runs (the demo's minutes);
    # make test checks 000's line from the full runs tests/papers/p000_li2023/test_reproduction_li2023.py makes anyway
    "tests/papers/test_readme_counts.py",
    # issue 34: the FDIR study for the other three wheels (9 runs of 60 s), the chain through FMI 2.0 and 3.0 FMUs,
    # and the shipped threshold on 40 fresh fault-free draws of 60 s (about 2 min); the shipped wheel stays
    "tests/diagnosis/test_fdir_wheel_loss.py::test_every_wheel_is_isolated_and_fdir_helps",
    "tests/diagnosis/test_fdir_wheel_loss.py::test_the_fdir_chain_through_fmus_matches_in_process",
    "tests/diagnosis/test_fdir_wheel_loss.py::test_the_shipped_threshold_keeps_its_rate_on_fresh_fault_free_draws",
    # issue 35: the hostile pages opened in Chromium (a browser start, 5-8 s); their links and images are checked
    # without it in make test (test_pages_hold_no_link_or_image_from_data)
    "tests/orchestrator/test_hostile_matrix.py::test_hostile_pages_in_headless_chromium",
)


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.nodeid.startswith(LONG):
            item.add_marker(pytest.mark.long)
