"""Which blocks become which FMUs: model name -> (block class path, slave script)."""
import importlib
from pathlib import Path

SLAVES = Path(__file__).parent / "slaves"

CATALOG = {
    "FlexibleSpacecraft": ("plant.flexible:FlexibleSpacecraft", "ftcsim_plant_flexible.py"),
    "PDController": ("controller.pd:PDController", "ftcsim_controller_pd.py"),
    "FAFEO": ("estimator.fafeo:FAFEO", "ftcsim_estimator_fafeo.py"),
    "FASMC": ("controller.fasmc:FASMC", "ftcsim_controller_fasmc.py"),
    "AISMC": ("controller.aismc:AISMC", "ftcsim_controller_aismc.py"),
    # paper 001 (Zhang, Gao, Qian, Bai 2019): generic blocks with 001's defaults
    "RigidSpacecraftWheels": ("papers.p001_zhang2019.blocks:plant", "ftcsim_plant_rigid_wheels.py"),
    "ASMFEO": ("papers.p001_zhang2019.blocks:observer", "ftcsim_estimator_asmfeo.py"),
    "FONTSM": ("papers.p001_zhang2019.blocks:controller", "ftcsim_controller_fontsm.py"),
    # scenario sources as an FMU, for SSP packages (orchestrator/ssp.py)
    "PiecewiseConstantSource": ("plant.signals:PiecewiseConstantSource", "ftcsim_signal_pwc.py"),
}


def block_class(model_name: str):
    """The block class behind an FMU model name (``KeyError`` if not ours)."""
    path, _ = CATALOG[model_name]
    module, cls = path.split(":")
    return getattr(importlib.import_module(module), cls)


def slave_script(model_name: str) -> Path:
    return SLAVES / CATALOG[model_name][1]
