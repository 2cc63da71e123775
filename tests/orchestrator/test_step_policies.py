"""Step policies (orchestrator/cosim/policies.py): multirate against a hand-built sampled-data loop,
announced instants landed on exactly, adaptive step doubling with rollback (FMU = in-process bit
for bit, error falling with rtol against a fine fixed-step reference), step statistics and
variable-step metrics. Short windows, in-process where the FMI layer adds nothing."""
import dataclasses

import numpy as np
import pytest
from scenario_text import variant, write
from step_policy_blocks import HeldIntegrator, IrregularSampler, irregular_instants

from orchestrator.cli.main import main
from orchestrator.cosim.block import BlockComponent
from orchestrator.cosim.master import Master
from orchestrator.cosim.policies import AdaptiveStep, MultirateStep, time_grid
from orchestrator.cosim.runner import run_scenario
from orchestrator.results.files import metrics_and_info, read_results
from orchestrator.scenario.toml import load
from papers.registry import scenario_files

FASMC = scenario_files()["li2023_fasmc"].read_text()


def _scenario(tmp_path, text, name="case.toml", in_process=True, **replace):
    return load(write(tmp_path, variant(replace, text), name), in_process=in_process)


# -- multirate ---------------------------------------------------------------------------------
def test_multirate_with_every_step_equal_is_the_fixed_step(tmp_path):
    fixed = _scenario(tmp_path, FASMC, **{"stop = 200.0": "stop = 0.3", "step = 0.01": "step = 0.001"})
    multi = _scenario(tmp_path, FASMC, "m.toml", **{"stop = 200.0": "stop = 0.3", "step = 0.01": "step = 0.001",
                                                   'exchange = "ordered"': 'exchange = "ordered"\nstep_policy = "multirate"'})
    a, b = run_scenario(fixed), run_scenario(multi)
    assert a.info["policy"] == "fixed" and b.info["policy"] == "multirate"
    assert np.array_equal(a.time, b.time) and np.array_equal(a.data, b.data)


def _hand_built_pd_loop(sc, n, m):
    """Plant at the base step, PD controller every m base steps with its output held in between:
    written out with the blocks' own calls, no exchange plan."""
    from papers.registry import block_factory

    blocks = {}
    for name, inst in sc.instances.items():
        b = block_factory(inst.model_name)()
        b.set_parameters(inst.parameters)
        b.initialize(sc.start)
        blocks[name] = b
    plant, ctrl = blocks["plant"], blocks["ctrl"]
    up, uc = plant.default_inputs(), ctrl.default_inputs()
    pi, ci = plant.input_index, ctrl.input_index
    po, co = plant.output_index, ctrl.output_index
    q_d = sc.sources[0].values[0]
    t = time_grid(sc.start, sc.step, n).tolist()
    rows = []
    for k in range(n + 1):
        yp = plant.outputs_at(t[k], up)
        if k % m == 0:  # the controller samples, computes, and its command holds for m plant steps
            for i in range(4):
                uc[ci[f"q[{i}]"]] = yp[po[f"q[{i}]"]]
                uc[ci[f"q_d[{i}]"]] = q_d[i]
            for i in (1, 2, 3):
                uc[ci[f"omega[{i}]"]] = yp[po[f"omega[{i}]"]]
            yc = ctrl.outputs_at(t[k], uc)
            for i in (1, 2, 3):
                up[pi[f"u[{i}]"]] = yc[co[f"u[{i}]"]]
        rows.append([yp[po[f"q[{i}]"]] for i in range(4)] + [yp[po[f"omega[{i}]"]] for i in (1, 2, 3)]
                    + [up[pi[f"u[{i}]"]] for i in (1, 2, 3)])
        if k == n:
            break
        if k % m == 0:
            ctrl.advance(t[k], t[k + m] - t[k], uc)
        plant.advance(t[k], t[k + 1] - t[k], up)
    return np.array(t), np.array(rows)


def test_multirate_equals_a_hand_built_sampled_data_loop(tmp_path):
    """A 10 ms PD controller around a 1 ms plant (li2023_pd set-up) is, bit for bit, the loop that
    holds the controller's command for 10 plant steps."""
    sc = _scenario(tmp_path, variant({}), **{
        "stop = 200.0": "stop = 0.6", "step = 0.01": "step = 0.001",
        'fmu = "PDController"': 'fmu = "PDController"\nstep = 0.01'})
    sc = dataclasses.replace(sc, record=[("plant", f"q[{i}]") for i in range(4)] + [("plant", f"omega[{i}]") for i in (1, 2, 3)]
                             + [("ctrl", f"u[{i}]") for i in (1, 2, 3)])
    r = run_scenario(sc)
    assert r.complete and r.info["policy"] == "multirate"
    stats = r.info["step_statistics"]
    assert stats["do_steps"] == {"plant": 600, "ctrl": 60}
    t, rows = _hand_built_pd_loop(sc, 600, 10)
    assert np.array_equal(r.time, t)
    assert np.array_equal(r.data, rows)
    u = r.vector("ctrl.u")
    assert np.all(u[1:10] == u[0]) and np.any(u[10] != u[0])  # held, then a new sample
    # and it is a different loop from the 1 ms controller: sampling at 10 ms is visible
    sc1 = _scenario(tmp_path, variant({}), "one.toml", **{"stop = 200.0": "stop = 0.6", "step = 0.01": "step = 0.001"})
    sc1 = dataclasses.replace(sc1, record=sc.record)
    one = run_scenario(sc1)
    assert np.abs(one.data[:, 7:] - r.data[:, 7:]).max() > 1e-3


# -- announced instants ------------------------------------------------------------------------
T_END, BASE, SEED = 0.4, 0.01, 11


def _announcing_run(policy, exchange="ordered"):
    comps = {"s": BlockComponent("s", IrregularSampler(seed=SEED, t1=T_END)), "i": BlockComponent("i", HeldIntegrator())}
    for c in comps.values():
        c.setup(0.0, T_END, {}, {})
    record = [("s", "y"), ("s", "t_next"), ("i", "x"), ("i", "z")]
    m = Master(comps, [("s", "y", "i", "x")], record=record, exchange=exchange, watch=policy.watch)
    return m.run(0.0, T_END, policy=policy), comps["s"].block, comps["i"].block


@pytest.mark.parametrize("exchange", ["ordered", "jacobi"])
@pytest.mark.parametrize("record_announced", [False, True])
def test_announced_instants_are_landed_on_exactly(exchange, record_announced):
    policy = MultirateStep(BASE, announced=[("s", "t_next")], record_announced=record_announced)
    r, sampler, integ = _announcing_run(policy, exchange)
    assert r.complete, r.error
    grid = time_grid(0.0, BASE, int(round(T_END / BASE))).tolist()
    instants = [x for x in irregular_instants(SEED, 0.0, T_END, sampler.mean) if x < T_END]
    assert len(instants) > 2 * len(grid)  # several instants per base step, none on the grid
    assert not set(instants) & set(grid)
    # the announcer is stepped from exactly every announced double (and from the grid points)
    starts = [t for t, _ in sampler.log]
    assert set(starts) == set(grid[:-1]) | set(instants)
    assert all(t + h == nxt for (t, h), nxt in zip(sampler.log, starts[1:]))
    # the other component sees the new output exactly there: its held input changes only at instants
    xs = [(t, x) for t, _, x in integ.log]
    changes = [t for (t, x), (_, x0) in zip(xs[1:], xs[:-1]) if x != x0]
    assert set(changes) <= set(instants) and len(changes) >= len(instants) - 1
    # ... so its integral is the exact integral of the sample-and-hold signal
    knots = [0.0] + instants + [T_END]
    exact = sum(sampler.values[j] * (knots[j + 1] - knots[j]) for j in range(len(knots) - 1))
    assert abs(integ.z - exact) < 1e-14 * len(knots)
    # rows: the regular grid, plus every instant on request
    want = sorted(grid + instants) if record_announced else grid
    assert r.time.tolist() == want
    stats = r.info["step_statistics"]
    assert stats["announced_instants"] == len(instants)
    assert stats["smallest_step"] < BASE / 20 and stats["largest_step"] <= BASE
    if record_announced:  # the recorded input changes only at rows that are announced instants
        x = r.column("i.x")
        assert set(r.time[1:][np.diff(x) != 0].tolist()) <= set(instants)


def test_announced_instants_under_the_adaptive_policy():
    policy = AdaptiveStep(BASE, BASE, rtol=1e-6, atol=1e-9, min_step=1e-6, max_step=BASE,
                          error_variables=[("i", "z")], announced=[("s", "t_next")])
    r, sampler, integ = _announcing_run(policy)
    assert r.complete, r.error
    instants = [x for x in irregular_instants(SEED, 0.0, T_END, sampler.mean) if x < T_END]
    assert set(instants) <= {t for t, _ in sampler.log}
    knots = [0.0] + instants + [T_END]
    exact = sum(sampler.values[j] * (knots[j + 1] - knots[j]) for j in range(len(knots) - 1))
    assert abs(integ.z - exact) < 1e-12
    assert r.time.tolist() == time_grid(0.0, BASE, 40).tolist()
    assert r.info["step_statistics"]["announced_instants"] == len(instants)


def test_sampled_data_controller_of_paper_004_needs_the_announced_instants(tmp_path):
    """004's controller samples aperiodically on a 1 ms quantum: with a 2.5 ms step the fixed-step
    run stops at the first sample instant inside a step; with the controller announcing
    t_next_sample (and the Markov source t_next_jump) the master lands on every instant, and each
    sample the controller takes (its t_k) is a recorded row."""
    text = variant({"stop = 30.0": "stop = 0.6", "step = 0.001": "step = 0.0025"}, scenario_files()["xu2024_ts"].read_text())
    fixed = run_scenario(load(write(tmp_path, text, "fixed.toml"), in_process=True))
    assert not fixed.complete and "inside the communication step" in fixed.error
    ann = variant({"[instances.ctrl]\n": '[instances.ctrl]\nannounces = ["t_next_sample"]\n',
                   "[instances.faults]\n": '[instances.faults]\nannounces = ["t_next_jump"]\n',
                   'exchange = "ordered"': 'exchange = "ordered"\nrecord_announced = true'}, text)
    r = run_scenario(load(write(tmp_path, ann, "ann.toml"), in_process=True))
    assert r.complete, r.error
    assert r.info["policy"] == "multirate"
    samples = sorted(set(r.column("ctrl.t_k").tolist()))
    assert len(samples) >= 6  # 50-100 ms intervals over 0.6 s
    off_grid = [t for t in samples if abs(t / 0.0025 - round(t / 0.0025)) > 1e-6]
    assert off_grid  # the test has teeth: some samples fall between the 2.5 ms points
    assert set(samples) <= set(r.time.tolist())  # a row at every one: the master landed there
    assert r.info["step_statistics"]["announced_instants"] >= len(off_grid)


# -- adaptive ----------------------------------------------------------------------------------
ADAPTIVE = {
    "stop = 200.0": "stop = 0.6", "step = 0.01": "step = 0.005",
    'exchange = "ordered"': 'exchange = "ordered"\nstep_policy = "adaptive"\nrtol = 1e-6\natol = 1e-7\noutput_step = 0.01',
    "fault_onset = 40.0\nu_max": "fault_onset = 0.3\nu_max",
}


@pytest.mark.fmu
def test_adaptive_run_through_fmus_equals_the_in_process_run(tmp_path, fmu_dir):
    """Rollback through fmi2GetFMUstate / fmi2SetFMUstate is exact: the adaptive run on FMUs takes
    the same steps, rejections included, and gives the same rows as the in-process blocks."""
    fmu = run_scenario(_scenario(tmp_path, FASMC, "f.toml", in_process=False, **ADAPTIVE))
    ip = run_scenario(_scenario(tmp_path, FASMC, "i.toml", **ADAPTIVE))
    assert fmu.complete and ip.complete, (fmu.error, ip.error)
    s_f, s_i = fmu.info["step_statistics"], ip.info["step_statistics"]
    assert s_f == {**s_i, "wall_time_s": s_f["wall_time_s"]}
    assert s_i["rejected_steps"] >= 1 and s_i["rollbacks"] == s_i["accepted_steps"] + 2 * s_i["rejected_steps"]
    assert s_i["smallest_step"] < 0.1 * s_i["largest_step"]  # really variable (the fault at 0.3 s)
    assert np.array_equal(fmu.time, ip.time) and np.array_equal(fmu.data, ip.data)
    assert np.array_equal(ip.time, time_grid(0.0, 0.01, 60))  # rows on the output grid


@pytest.mark.slow
def test_adaptive_error_falls_with_rtol(tmp_path):
    """li2023_fasmc over 0.4 s with the fault step at 0.2 s: against a 0.1 ms fixed-step reference the
    error falls with rtol as a first-order coupling predicts (local error ~ h^2 ~ tol, so the global
    error ~ sqrt(tol): a factor ~3 per decade; asserted > 2), and the doSteps grow."""
    common = {"stop = 200.0": "stop = 0.4", "fault_onset = 40.0": "fault_onset = 0.2"}
    ref = run_scenario(_scenario(tmp_path, FASMC, "ref.toml", **common, **{"step = 0.01": "step = 0.0001"}))
    errs, work = [], []
    for rtol in (1e-5, 1e-6, 1e-7):
        r = run_scenario(_scenario(tmp_path, FASMC, f"a{rtol}.toml", **common, **{'exchange = "ordered"':
                         f'exchange = "ordered"\nstep_policy = "adaptive"\nrtol = {rtol}\natol = {rtol}'}))
        assert r.complete, r.error
        idx = np.searchsorted(ref.time, r.time - 1e-12)
        assert np.allclose(ref.time[idx], r.time, rtol=0, atol=1e-12)
        cols = [k for k, c in enumerate(r.columns) if c.startswith(("plant.q[", "plant.omega["))]
        errs.append(np.abs(r.data[:, cols] - ref.data[idx][:, cols]).max())
        work.append(r.info["step_statistics"]["do_steps_total"])
    assert errs[0] > 2 * errs[1] > 4 * errs[2], errs
    assert work[0] < work[1] < work[2], work


def test_adaptive_statistics_and_variable_step_metrics_in_metrics_json(tmp_path):
    text = variant({"stop = 200.0": "stop = 0.3", 'exchange = "ordered"':
                    'exchange = "ordered"\nstep_policy = "adaptive"\nrtol = 1e-5\nmax_step = 0.01'})
    out = tmp_path / "run"
    assert main(["run", str(write(tmp_path, text)), "--out", str(out), "--quiet", "--no-plots", "--mode", "inprocess"]) == 0
    m = metrics_and_info(out)
    st = m["step_statistics"]
    assert m["step_policy"] == st["policy"] == "adaptive"
    assert st["accepted_steps"] >= 30 and st["do_steps_total"] == 2 * 3 * (st["accepted_steps"] + st["rejected_steps"])
    assert 0 < st["smallest_step"] <= st["largest_step"] <= 0.01
    header, data = read_results(out)
    t = data[:, 0]
    u = data[:, [header.index(f"ctrl.u[{i}]") for i in (1, 2, 3)]]
    assert np.isclose(m["control_energy"], np.sum(np.sum(u[:-1] ** 2, axis=1) * np.diff(t)), rtol=1e-14)


def test_control_energy_uses_the_row_intervals():
    """Rows at irregular times (announced instants recorded): E = sum ||u_k||^2 (t_k+1 - t_k)."""
    from orchestrator.cosim.master import RunResult
    from orchestrator.results.metrics import compute_metrics

    t = np.array([0.0, 0.01, 0.013, 0.02, 0.05])
    u = np.array([[1.0, 0, 0], [2.0, 0, 0], [0, 3.0, 0], [0, 0, 1.0], [9.0, 9.0, 9.0]])
    r = RunResult([f"c.u[{i}]" for i in (1, 2, 3)], t, u, True, steps=4)

    class Sc:
        name, paper, step, metrics = "x", "", 0.01, {"control": "c.u"}

    m = compute_metrics(r, Sc)
    assert m["control_energy"] == pytest.approx(1 * 0.01 + 4 * 0.003 + 9 * 0.007 + 1 * 0.03, rel=1e-14)
    assert m["real_time_factor"] is None  # no wall time
