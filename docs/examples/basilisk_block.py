"""A Basilisk spacecraft of one's own as an ftcsim plant (docs/basilisk.md): four wheels, two hinged
solar panels, the gravity gradient on the default orbit (circular, 7000 km). ``ftcsim build --block
basilisk_block:craft_with_panels --path docs/examples`` makes it an FMU; the values set here are its
start values."""
import numpy as np

from orchestrator.interop.basilisk.spacecraft import BasiliskSpacecraft


def craft_with_panels() -> BasiliskSpacecraft:
    b = BasiliskSpacecraft(n_wheels=4, n_panels=2)
    b.model_name = "CraftWithPanels"
    b.set_defaults({
        "J": np.diag([120.0, 100.0, 80.0]),  # kg.m2, the hub without wheels and panels
        "panel_mass": [20.0, 20.0], "panel_d": [1.5, 1.5],  # kg; m from the hinge to the panel's centre
        "panel_I": [[10.0, 15.0, 5.0], [10.0, 15.0, 5.0]],  # kg.m2 about the panel's centre (s1, s2 = hinge, s3)
        "panel_r": [[0.5, 0.0, 1.0], [-0.5, 0.0, 1.0]], "panel_axis": [[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]],
        "panel_k": [80.0, 80.0], "panel_c": [2.0, 2.0],  # N.m/rad, N.m.s/rad
        "coulomb": 0.0005,  # N.m: the Honeywell wheels' friction of simIncludeRW
        "gravity_gradient": 1.0,
        "omega_init": [0.001, -0.002, 0.0005],
    })
    return b
