"""The mapped conventions (orchestrator/interop/basilisk/conventions.py): numpy only, checked against
ftcsim's own attitude functions and, where bsk is installed, against Basilisk's RigidBodyKinematics."""
import numpy as np
import pytest

from orchestrator.interop.basilisk import conventions as cv
from plant import euler231
from plant.so3 import rotation_matrix

RNG = np.random.default_rng(32)
QUATERNIONS = [q / np.linalg.norm(q) for q in RNG.normal(size=(20, 4))]
ANGLES = [np.array([RNG.uniform(-1.4, 1.4), RNG.uniform(-3.0, 3.0), RNG.uniform(-3.0, 3.0)]) for _ in range(20)]


def test_attitude_sets_round_trip_and_agree_with_ftcsim():
    for q in QUATERNIONS:
        s = cv.mrp_from_quaternion(q)
        assert np.linalg.norm(s) <= 1.0 + 1e-15  # the short set
        assert np.allclose(cv.mrp_to_dcm(s), rotation_matrix(q), atol=1e-14)
        assert np.allclose(cv.quaternion_from_mrp(s), q if q[0] >= 0 else -q, atol=1e-14)
        assert np.allclose(cv.quaternion_from_mrp(-s / (s @ s)), q if q[0] >= 0 else -q, atol=1e-13)  # the shadow set
    for a in ANGLES:
        s = cv.mrp_from_euler231(a)
        assert np.allclose(cv.mrp_to_dcm(s), euler231.dcm(a), atol=1e-14)
        assert np.allclose(cv.euler231_from_mrp(s), a, atol=1e-12)


def test_wheel_and_inertia_mappings():
    G = np.array([[1.0, 0, 0, 3**-0.5], [0, 1.0, 0, 3**-0.5], [0, 0, 1.0, 3**-0.5]])
    J = np.diag([30.0, 27.0, 19.0])
    assert np.allclose(cv.craft_inertia(cv.hub_inertia(J, G, 0.08), G, 0.08), J)
    assert np.allclose(cv.hub_inertia(J, G, 0.08) - J, 0.08 * G @ G.T)
    w, speed = np.array([0.1, -0.2, 0.3]), np.array([100.0, -50.0, 20.0, 5.0])
    assert np.allclose(cv.relative_speed(cv.inertial_momentum(speed, w, G, 0.08), w, G, 0.08), speed)
    assert np.array_equal(cv.motor_torque([0.1, -0.2]), [-0.1, 0.2]) and np.array_equal(cv.body_torque([0.1]), [-0.1])
    with pytest.raises(ValueError, match="unit vectors"):
        cv.hub_inertia(J, 2 * G, 0.08)
    panels = cv.panels_from_modes([[3.0, 4.0, 0.0]], [2.0], [0.01])
    assert np.allclose(panels[0]["axis"], [0.6, 0.8, 0.0]) and panels[0]["inertia"] == 25.0
    assert panels[0]["k"] == 100.0 and np.isclose(panels[0]["c"], 1.0) and panels[0]["scale"] == 5.0
    with pytest.raises(ValueError, match="row 1 is zero"):
        cv.panels_from_modes([[0.0, 0.0, 0.0]], [1.0], [0.0])
    H = cv.hinge_dcm([0.0, 0.6, 0.8])
    assert np.allclose(H @ H.T, np.eye(3)) and np.isclose(np.linalg.det(H), 1.0) and np.allclose(H[1], [0, 0.6, 0.8])


def test_the_conventions_are_basilisks():
    rbk = pytest.importorskip("Basilisk.utilities.RigidBodyKinematics",
                              reason="bsk (the optional extra ftcsim[basilisk]) is not installed")
    for q in QUATERNIONS:
        s = cv.mrp_from_quaternion(q)
        assert np.allclose(np.asarray(rbk.MRP2C(list(s))), cv.mrp_to_dcm(s), atol=1e-14)
        assert np.allclose(np.asarray(rbk.EP2C(list(q))), rotation_matrix(q), atol=1e-14)
        assert np.allclose(np.asarray(rbk.MRP2EP(list(s))), cv.quaternion_from_mrp(s), atol=1e-14)
    for a in ANGLES:  # 001's [nu, psi, gamma] is Basilisk's euler2312C([psi, nu, gamma])
        assert np.allclose(np.asarray(rbk.euler2312C([a[1], a[0], a[2]])), euler231.dcm(a), atol=1e-14)
        assert not np.allclose(np.asarray(rbk.euler2312C(list(a))), euler231.dcm(a), atol=1e-3)  # the order matters


def test_ftcsim_build_skips_an_fmu_whose_optional_extra_is_missing(tmp_path, monkeypatch, capsys):
    """Without bsk, `ftcsim build` builds the rest and says which FMU it skipped; naming it is refused in
    one line (an FMU spec with a missing module stands for BasiliskSpacecraft4 without ftcsim[basilisk])."""
    from orchestrator.cli import main as cli
    from papers.paper import FMUSpec

    spec = FMUSpec("NeedsExtra", "plant.signals:PiecewiseConstantSource", requires="no_such_module_for_ftcsim")
    assert not spec.available()
    monkeypatch.setattr(cli, "catalog", lambda: {"NeedsExtra": spec})
    assert cli.main(["build", "--out", str(tmp_path / "fmus")]) == 0
    assert "skipped NeedsExtra: needs the optional module no_such_module_for_ftcsim" in capsys.readouterr().out
    assert not list((tmp_path / "fmus").glob("*.fmu"))
    assert cli.main(["build", "NeedsExtra", "--out", str(tmp_path / "fmus")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "NeedsExtra needs the optional module no_such_module_for_ftcsim" in err[0]
