"""Paper 000's blocks with 000's numbers: the factories behind its FMUs (numpy only).

Each factory returns a fresh block of a paper-agnostic algorithm module, with 000's parameter
set (section 5) and published gains (Appendix A.1/A.2, section 5.3) as its defaults, which
become the FMU's start values.
"""
from controller.aismc import AISMC
from controller.fasmc import FASMC
from controller.pd import PDController
from estimator.fafeo import FAFEO
from plant.flexible import FlexibleSpacecraft

from . import gains as G
from .parameters import LI2023, OMEGA_BOX, U_MAX


def _configured(block, values):
    block.set_defaults(values)
    return block


def flexible_spacecraft() -> FlexibleSpacecraft:
    """000 (2)-(7) with 000's J, delta and modes."""
    return _configured(FlexibleSpacecraft(n_modes=4), {**LI2023, "u_max": U_MAX})


def fafeo() -> FAFEO:
    """FAFEO 000 (16)-(17) with the A.1 gains and 000 (68)."""
    return _configured(FAFEO(n_modes=4), {
        "K": G.K, "F1": G.F1, "G1": G.G1, "F2": G.F2, "G2": G.G2, "theta_1": G.THETA_1,
        "theta_2": G.THETA_2, "f_min": G.F_MIN, "f_max": G.F_MAX, "d_max": G.D_MAX,
        **LI2023, "omega_box": OMEGA_BOX,
    })


def _controller(block, law: dict):
    return _configured(block, {**LI2023, "omega_box": OMEGA_BOX, "u_max": U_MAX, **law})


def pd_controller() -> PDController:
    """PD with feed-forward 000 (69); k_p = 20, k_d = 60 (000 section 5.3), beta from A.2."""
    return _controller(PDController(n_modes=4), {"k_p": 20.0, "k_d": 60.0, "beta": G.BETA})


def fasmc() -> FASMC:
    """FASMC 000 (40)/(64) with the A.2 gains."""
    return _controller(FASMC(n_modes=4), {
        "K_c": G.K_C, "beta": G.BETA, "sigma_1": G.SIGMA_1, "sigma_2": G.SIGMA_2,
        "sigma_2p": G.SIGMA_2_PRIME, "varsigma": G.VARSIGMA,
    })


def aismc() -> AISMC:
    """AISMC baseline 000 (70)-(71) with the A.2 K_c (standing in for ref. [21])."""
    return _controller(AISMC(n_modes=4), {
        "K_c": G.K_C, "beta": G.AISMC_BETA, "sigma": G.AISMC_SIGMA, "sigma_p": G.AISMC_SIGMA_PRIME,
    })
