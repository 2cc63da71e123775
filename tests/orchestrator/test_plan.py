"""The master's parts on mock blocks whose answers are known in closed form: ordered and Jacobi
exchange, algebraic loops, one output evaluation per exchange, the growing recorder, stop
requests, recording after the transfer."""
import numpy as np
import pytest
from mock_block import Clock, Gain, Integrator

from orchestrator.common.interrupt import REQUEST
from orchestrator.cosim.block import BlockComponent
from orchestrator.cosim.master import Master
from orchestrator.cosim.plan import AlgebraicLoopError


def _chain(k=2.0):
    """clock -> gain (y = k t) -> integrator (x' = k t)."""
    blocks = {"clock": Clock(), "gain": Gain(k=k), "int": Integrator()}
    comps = {n: BlockComponent(n, b) for n, b in blocks.items()}
    for c in comps.values():
        c.setup(0.0, 1.0, {}, {})
    conns = [("clock", "y[1]", "gain", "u[1]"), ("gain", "y[1]", "int", "u[1]")]
    record = [("clock", "y[1]"), ("gain", "y[1]"), ("int", "y[1]")]
    return blocks, comps, conns, record


@pytest.mark.parametrize("exchange", ["ordered", "jacobi"])
def test_chain_against_closed_form(exchange):
    h, n = 0.01, 500
    blocks, comps, conns, record = _chain()
    r = Master(comps, conns, (), record, exchange=exchange).run(0.0, n * h, h)
    assert r.complete and r.steps == n and len(r.time) == n + 1
    t = r.time
    k = np.arange(n + 1)
    if exchange == "ordered":
        # the integrator sees u = 2 t_k over [t_k, t_k+1]: x(t_m) = 2 h^2 sum_{k<m} k = h^2 m (m - 1)
        expected = h * h * k * (k - 1)
        assert np.array_equal(r.column("gain.y[1]"), 2.0 * t)
    else:
        # Jacobi: the gain's output read at t_k was computed from the clock of t_{k-1}, so the
        # integrator's input over [t_k, t_k+1] is 2 t_{k-1} (0 for k = 0, the start time exchanged
        # consistently): x(t_m) = 2 h^2 sum_{j<m-1} j = h^2 (m - 1)(m - 2)
        expected = h * h * np.maximum(k - 1, 0) * np.maximum(k - 2, 0)
        assert np.allclose(r.column("gain.y[1]")[1:], 2.0 * t[:-1], rtol=0, atol=1e-15)
    assert np.allclose(r.column("int.y[1]"), expected, rtol=1e-12, atol=1e-15)


def test_each_output_is_evaluated_once_per_exchange():
    h, n = 0.01, 100
    blocks, comps, conns, record = _chain()
    Master(comps, conns, (), record).run(0.0, n * h, h)
    assert {name: b.evaluations for name, b in blocks.items()} == {"clock": n + 1, "gain": n + 1, "int": n + 1}


def test_algebraic_loop_is_refused_with_the_cycle_named():
    comps = {n: BlockComponent(n, Gain()) for n in ("a", "b")}
    conns = [("a", "y[1]", "b", "u[1]"), ("b", "y[1]", "a", "u[1]")]
    # each output, then the input it depends on, then the output feeding that input, ...
    with pytest.raises(AlgebraicLoopError, match=r"a\.y\[1\] -> a\.u\[1\] -> b\.y\[1\] -> b\.u\[1\] -> a\.y\[1\]"):
        Master(comps, conns, (), [("a", "y[1]")])


def test_recorder_grows_past_its_first_chunk():
    from orchestrator.cosim.recorder import Recorder

    rec = Recorder(["x"], chunk_rows=16)
    for k in range(1000):
        rec.row(0.5 * k)[0] = k
    t, d = rec.result()
    assert t.shape == (1000,) and np.array_equal(d[:, 0], np.arange(1000.0)) and t[-1] == 499.5


def test_stop_request_ends_the_run_with_what_was_recorded():
    blocks, comps, conns, record = _chain()
    REQUEST.signum = 15
    try:
        r = Master(comps, conns, (), record).run(0.0, 1.0, 0.01)
    finally:
        REQUEST.signum = 0
    assert not r.complete and r.interrupted == 15 and len(r.time) == 1 and "SIGTERM" in r.error


def test_recording_after_the_transfer():
    """Jacobi, sample="after": a feedthrough output is recorded with the inputs just set."""
    h, n = 0.01, 50
    blocks, comps, conns, record = _chain()
    r = Master(comps, conns, (), record, exchange="jacobi", sample="after").run(0.0, n * h, h)
    assert np.allclose(r.column("gain.y[1]"), 2.0 * r.time, rtol=0, atol=1e-15)
