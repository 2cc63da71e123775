"""SSP export/import: the package validates (fmpy's SSP reader), carries units, step and
parameters, and re-imported by ``ftcsim run`` gives the TOML run's results exactly."""
import zipfile

import numpy as np
import pytest
from lxml import etree
from scenario_text import variant, write

from orchestrator.cli.main import main
from orchestrator.common.errors import InputError
from orchestrator.cosim.runner import run_scenario
from orchestrator.cosim.sources import PiecewiseConstant
from orchestrator.results.files import read_results
from orchestrator.scenario.ssp import NS, export_ssp, load_ssp
from orchestrator.scenario.toml import load
from plant.signals import PiecewiseConstantSource

pytestmark = pytest.mark.fmu

STOP = "stop = 85.0"  # past the attitude command switch at 80 s and the fault onset at 40 s


@pytest.fixture(scope="module")
def pd_package(tmp_path_factory, fmu_dir):
    tmp = tmp_path_factory.mktemp("ssp")
    toml = write(tmp, variant({"stop = 200.0": STOP}), "pd.toml")
    scenario = load(toml)
    return toml, scenario, export_ssp(scenario, tmp / "pd.ssp")


def test_exported_package_is_valid_ssp(pd_package):
    from fmpy.ssp.ssd import read_ssd

    toml, scenario, ssp = pd_package
    ssd = read_ssd(str(ssp), validate=True)  # schema-validates the SSD and every SSV
    comps = {c.name: c for c in ssd.system.elements}
    assert set(comps) == {"plant", "ctrl", "attitude_command"}
    assert comps["plant"].source == "resources/FlexibleSpacecraft.fmu"
    n_conn = len(scenario.connections) + 4  # + the source FMU's y[1..4] -> ctrl.q_d
    assert len(ssd.system.connections) == n_conn
    assert {u.name for u in ssd.units} >= {"N.m", "rad/s"}
    # parameter sets bound to the components, values exact
    binding = comps["plant"].parameterBindings[0]
    assert binding.source == "resources/plant.ssv"
    values = {p.name: float(p.value) for p in binding.parameterValues[0].parameters}
    assert values == scenario.instances["plant"].parameters
    with zipfile.ZipFile(ssp) as z:
        root = etree.fromstring(z.read("SystemStructure.ssd"))
        names = z.namelist()
    assert {"resources/FlexibleSpacecraft.fmu", "resources/PDController.fmu",
            "resources/PiecewiseConstantSource.fmu"} <= set(names)
    # connectors carry the units of the FMU variables
    u1 = root.find("ssd:System/ssd:Elements/ssd:Component[@name='plant']/ssd:Connectors/ssd:Connector[@name='u[1]']/ssc:Real", NS)
    assert u1.get("unit") == "N.m"
    # the step, where libcosim reads it
    fixed = root.find("ssd:DefaultExperiment/ssd:Annotations/ssc:Annotation[@type='com.opensimulationplatform']"
                      "/osp:Algorithm/osp:FixedStepAlgorithm", NS)
    assert float(fixed.get("baseStepSize")) == scenario.step
    exp = root.find("ssd:DefaultExperiment", NS)
    assert (float(exp.get("startTime")), float(exp.get("stopTime"))) == (scenario.start, scenario.stop)


@pytest.mark.parametrize("exchange", ["ordered", "jacobi"])
def test_reimported_package_gives_identical_results(pd_package, exchange):
    toml, scenario, ssp = pd_package
    ref = run_scenario(load(toml), exchange=exchange)
    back = load_ssp(ssp)
    assert (back.start, back.stop, back.step) == (scenario.start, scenario.stop, scenario.step)
    assert back.record == scenario.record and back.metrics == scenario.metrics
    got = run_scenario(back, exchange=exchange)
    assert ref.complete and got.complete
    assert got.columns == ref.columns
    assert np.array_equal(got.time, ref.time)
    assert np.array_equal(got.data, ref.data)  # bit for bit, the source switch at 80 s included
    u = ref.vector("ctrl.u")
    assert np.abs(u[np.searchsorted(ref.time, 80.0) + 2]).max() > 0.1  # the switch really acts


def test_cli_export_and_run(tmp_path, fmu_dir):
    toml = write(tmp_path, variant({"stop = 200.0": "stop = 2.0"}))
    ssp = tmp_path / "out" / "pd.ssp"
    assert main(["export-ssp", str(toml), "--out", str(ssp), "--quiet"]) == 0
    assert ssp.is_file()
    out = tmp_path / "res"
    assert main(["run", str(ssp), "--out", str(out), "--quiet", "--no-plots"]) == 0
    header, data = read_results(out)
    assert header[0] == "time" and "ctrl.u[1]" in header and "plant.q[0]" in header
    assert len(data) == 201


def test_package_without_step_is_refused(tmp_path, pd_package):
    _, _, ssp = pd_package
    bad = tmp_path / "nostep.ssp"
    with zipfile.ZipFile(ssp) as zin, zipfile.ZipFile(bad, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "SystemStructure.ssd":
                root = etree.fromstring(data)
                exp = root.find("ssd:DefaultExperiment", NS)
                exp.remove(exp.find("ssd:Annotations", NS))
                system = root.find("ssd:System", NS)
                system.remove(system.find("ssd:Annotations", NS))
                data = etree.tostring(root)
            zout.writestr(item, data)
    with pytest.raises(InputError, match="no step size"):
        load_ssp(bad)


def test_schema_violation_is_reported(tmp_path, pd_package):
    _, _, ssp = pd_package
    bad = tmp_path / "bad.ssp"
    with zipfile.ZipFile(ssp) as zin, zipfile.ZipFile(bad, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "SystemStructure.ssd":
                data = data.replace(b'kind="input"', b'kind="sideways"', 1)
            zout.writestr(item, data)
    with pytest.raises(InputError, match="SystemStructure.ssd"):
        load_ssp(bad)


def test_export_refuses_too_many_segments(tmp_path, fmu_dir):
    times = ", ".join(str(float(k)) for k in range(17))
    values = ", ".join("[1.0, 0.0, 0.0, 0.0]" for _ in range(17))
    text = variant({"times = [0.0, 80.0]": f"times = [{times}]"})
    text = text.replace("values = [[0.8426149773176358, 0.3, 0.2, -0.4], [0.9695359714832658, 0.2, -0.1, -0.1]]",
                        f"values = [{values}]")
    with pytest.raises(InputError, match="at most 16"):
        export_ssp(load(write(tmp_path, text)), tmp_path / "x.ssp")
    assert not (tmp_path / "x.ssp").exists()


def test_source_block_matches_master_source():
    times = [0.0, 0.3, 80.0]
    values = np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]])
    src = PiecewiseConstant("s", times, values, [("a", "x"), ("a", "y")])
    blk = PiecewiseConstantSource()
    blk.set_parameter("n_segments", 3)
    for k, t in enumerate(times):
        blk.set_parameter(f"times[{k + 1}]", t)
        for i in range(2):
            blk.set_parameter(f"values[{k + 1},{i + 1}]", values[k, i])
    blk.initialize(0.0)
    # 0.1 * 3 != 0.3 in floating point: both use the same tolerance at switch times
    for t in [0.0, 0.1 * 3, 0.29999999, 0.3, 79.99, 80.0, 0.01 * 8000, 1e3, -1.0]:
        assert np.array_equal(blk.outputs_at(t, np.zeros(0))[:2], src.value(t)), t


def test_package_loads_as_it_is_in_omsimulator_and_ecos(pd_package):
    """What OMSimulator's command line and Ecos need, on the XML: the org.openmodelica fixed-step
    master with our step inside ssd:System (before our own annotation, nothing at the SSD root),
    one ParameterSet name for every SSV, a package readable by others (not mode 0600)."""
    import os
    import stat

    toml, scenario, ssp = pd_package
    with zipfile.ZipFile(ssp) as z:
        root = etree.fromstring(z.read("SystemStructure.ssd"))
        ssvs = [etree.fromstring(z.read(n)) for n in z.namelist() if n.endswith(".ssv")]
    assert root.find("ssd:Annotations", NS) is None
    anns = root.findall("ssd:System/ssd:Annotations/ssc:Annotation", NS)
    assert [a.get("type") for a in anns] == ["org.openmodelica", "org.ftcsim.scenario"]
    master = anns[0].find("oms:Annotations/oms:SimulationInformation/oms:FixedStepMaster", NS)
    assert master is not None and float(master.get("stepSize")) == scenario.step
    assert list(root.find("ssd:System", NS))[-1].tag.endswith("Annotations")  # last child, as the schema wants
    assert ssvs and {s.get("name") for s in ssvs} == {"default"}
    mode = stat.S_IMODE(os.stat(ssp).st_mode)
    umask = os.umask(0)
    os.umask(umask)
    assert mode == 0o666 & ~umask and mode & stat.S_IRGRP


def test_packages_of_the_old_layout_still_load(tmp_path, pd_package):
    """Our annotation at the SSD root (packages written before it moved into ssd:System)."""
    _, scenario, ssp = pd_package
    old = tmp_path / "old.ssp"
    with zipfile.ZipFile(ssp) as zin, zipfile.ZipFile(old, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "SystemStructure.ssd":
                root = etree.fromstring(data)
                system = root.find("ssd:System", NS)
                ann = system.find("ssd:Annotations", NS)
                system.remove(ann)
                ours = [a for a in ann if a.get("type") == "org.ftcsim.scenario"][0]
                top = etree.Element(f"{{{NS['ssd']}}}Annotations")
                top.append(ours)
                root.append(top)
                data = etree.tostring(root)
            zout.writestr(item, data)
    s = load_ssp(old)
    assert s.name == scenario.name and s.record == scenario.record and s.step == scenario.step


def test_step_policy_travels_with_the_package(tmp_path, fmu_dir):
    """The adaptive settings and announced outputs go into the ftcsim annotation, instance steps into
    libcosim's osp:StepSizeHint; re-imported, the package has the TOML file's step policy."""
    text = variant({"stop = 200.0": STOP, 'exchange = "ordered"':
                    'exchange = "ordered"\nstep_policy = "adaptive"\nrtol = 1e-5\natol = 1e-7\nmin_step = 1e-4\n'
                    'error_variables = ["plant.q", "plant.omega"]\nrecord_announced = true',
                    'fmu = "PDController"': 'fmu = "PDController"\nannounces = ["u[1]"]'})
    sc = load(write(tmp_path, text, "a.toml"))
    back = load_ssp(export_ssp(sc, tmp_path / "a.ssp"))
    assert back.step_policy == "adaptive" and back.timing.record_announced
    for k in ("rtol", "atol", "min_step", "max_step", "output_step", "safety", "error_variables"):
        assert getattr(back.timing, k) == getattr(sc.timing, k), k
    assert back.instances["ctrl"].announces == ["u[1]"]
    # multirate: the hint, where libcosim reads it
    text = variant({"stop = 200.0": STOP, 'fmu = "PDController"': 'fmu = "PDController"\nstep = 0.05'})
    ssp = export_ssp(load(write(tmp_path, text, "m.toml")), tmp_path / "m.ssp")
    with zipfile.ZipFile(ssp) as z:
        root = etree.fromstring(z.read("SystemStructure.ssd"))
    hint = root.find("ssd:System/ssd:Elements/ssd:Component[@name='ctrl']/ssd:Annotations/ssc:Annotation"
                     "[@type='com.opensimulationplatform']/osp:StepSizeHint", NS)
    assert float(hint.get("value")) == 0.05
    assert root.find("ssd:System/ssd:Elements/ssd:Component[@name='plant']/ssd:Annotations", NS) is None
    m = load_ssp(ssp)
    assert m.step_policy == "multirate" and m.instances["ctrl"].step == 0.05
