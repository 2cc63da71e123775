"""orchestrator/common/watchdog.py alone (fast, no FMU): the time limit stops a stepping loop at a
communication point, and a call that never returns is interrupted GRACE s after the limit, in the
main thread and in another thread (a Dask worker's)."""
import threading
import time

import pytest
from mock_block import Integrator

from orchestrator.common.watchdog import GRACE, Hung, guarded, run_deadline, start_clock
from orchestrator.cosim.block import BlockComponent
from orchestrator.cosim.master import Master


def _spin_forever():
    while True:  # pure Python: reaches the eval loop, where the watchdog's exception arrives
        pass


def test_a_call_that_never_returns_is_interrupted_after_the_limit_in_the_main_thread():
    t0 = time.monotonic()
    with pytest.raises(Hung, match="time limit of 0.2 s"):
        with guarded(0.2):
            start_clock()
            time.sleep(3600)  # a blocking call: SIGALRM breaks it
    assert 0.2 + GRACE - 0.05 < time.monotonic() - t0 < 0.2 + GRACE + 3.0
    assert run_deadline() is None  # the frame is gone: no limit outside a run


def test_a_call_that_never_returns_is_interrupted_in_a_worker_thread():
    got = {}

    def worker():
        t0 = time.monotonic()
        try:
            with guarded(0.2):
                start_clock()
                _spin_forever()
        except Hung as e:
            got["error"], got["took"] = str(e), time.monotonic() - t0

    th = threading.Thread(target=worker, daemon=True)
    th.start()
    th.join(10)
    assert not th.is_alive() and "time limit of 0.2 s" in got["error"] and got["took"] < 0.2 + GRACE + 3.0


def test_without_a_stop_nothing_is_raised_and_set_up_is_not_counted():
    with guarded(0.2) as run:
        time.sleep(0.4)  # set-up: before start_clock, not limited
        assert run_deadline() is None
        start_clock()
        assert run_deadline() is not None
    time.sleep(0.2 + GRACE + 0.2)  # the timer was cancelled with the frame
    assert run.fired is None


class SlowIntegrator(Integrator):
    """An integrator whose step takes 20 ms of wall time."""

    def advance(self, t, h, u):
        time.sleep(0.02)
        super().advance(t, h, u)


def test_the_time_limit_stops_the_stepping_loop_at_a_communication_point():
    comps = {"i": BlockComponent("i", SlowIntegrator())}
    for c in comps.values():
        c.setup(0.0, 100.0, {}, {})
    m = Master(comps, [], [], [("i", "y[1]")])
    with guarded(0.3):
        start_clock()
        r = m.run(0.0, 100.0, 0.01)
    assert not r.complete and r.info.get("timed_out") and r.interrupted == 0
    assert "time limit of 0.3 s (wall time) exceeded at t = " in r.error
    assert 5 <= r.steps <= 30 and len(r.time) == r.steps + 1  # ~15 steps of 20 ms, every row kept
