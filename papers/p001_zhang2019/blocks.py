"""Paper 001's blocks: the generic plant, observer and controller with 001's numbers as defaults
(numpy only: the FMUs embed this module)."""
from controller.fontsm import FONTSM
from estimator.asmfeo import ASMFEO
from plant.rigid_wheels import RigidSpacecraftWheels

from . import gains as G
from .parameters import N_WHEELS, OMEGA0, PLANT_DEFAULTS, STEP, ZHANG2019


def plant() -> RigidSpacecraftWheels:
    """Rigid spacecraft with four wheels, 001 (1)-(3), (5), section 5 set-up and fault profile."""
    b = RigidSpacecraftWheels(N_WHEELS)
    b.set_defaults(PLANT_DEFAULTS)
    return b


def _printed(*names) -> dict:
    """The printed gains of gains.py under the block's parameter names (gains.py spells them in capitals)."""
    return {name: getattr(G, name.upper()) for name in names}


def observer() -> ASMFEO:
    """Adaptive sliding-mode fault-estimation observer 001 (12), (14), (15), printed gains."""
    b = ASMFEO(N_WHEELS)
    b.set_defaults(
        {
            "J": ZHANG2019["J"],
            "M": ZHANG2019["M"],
            **_printed("Lambda", "lambda_1", "lambda_2", "lambda_3", "epsilon", "mu", "K_init"),
            "omega_hat_init": OMEGA0,  # reading: omega_hat(0) = omega(0), the first measurement
            "h_max": STEP,
        }
    )
    return b


def controller() -> FONTSM:
    """Backstepping + FONTSM FE/FTC 001 (23)-(36), printed gains, readings of README.md."""
    b = FONTSM(N_WHEELS)
    b.set_defaults(
        {
            "J": ZHANG2019["J"],
            "M": ZHANG2019["M"],
            **_printed("a", "b", "alpha_1", "alpha_2", "beta_1", "beta_2", "r", "eps_1", "eps_2", "rho", "c"),
            "fo_step": STEP,
            "fo_memory": G.FO_MEMORY_FULL,
        }
    )
    return b
