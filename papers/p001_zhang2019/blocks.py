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


def observer() -> ASMFEO:
    """Adaptive sliding-mode fault-estimation observer 001 (12), (14), (15), printed gains."""
    b = ASMFEO(N_WHEELS)
    b.set_defaults(
        {
            "J": ZHANG2019["J"],
            "M": ZHANG2019["M"],
            "Lambda": G.LAMBDA,
            "lambda_1": G.LAMBDA_1,
            "lambda_2": G.LAMBDA_2,
            "lambda_3": G.LAMBDA_3,
            "epsilon": G.EPSILON,
            "mu": G.MU,
            "K_init": G.K_INIT,
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
            "a": G.A,
            "b": G.B,
            "alpha_1": G.ALPHA_1,
            "alpha_2": G.ALPHA_2,
            "beta_1": G.BETA_1,
            "beta_2": G.BETA_2,
            "r": G.R,
            "eps_1": G.EPS_1,
            "eps_2": G.EPS_2,
            "rho": G.RHO,
            "c": G.C,
            "fo_step": STEP,
            "fo_memory": G.FO_MEMORY_FULL,
        }
    )
    return b
