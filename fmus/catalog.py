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
    # papers 002 and 003 (factories: generic blocks with the paper's numbers as defaults)
    "Zhang2014Plant": ("papers.p002_zhang2014.blocks:plant", "ftcsim_plant_zhang2014.py"),
    "Zhang2014Hinf": ("papers.p002_zhang2014.blocks:controller", "ftcsim_controller_zhang2014.py"),
    "Hang2023Plant": ("papers.p003_hang2023.blocks:plant", "ftcsim_plant_hang2023.py"),
    "Hang2023TSFDO": ("papers.p003_hang2023.blocks:observer", "ftcsim_estimator_tsfdo_hang2023.py"),
    "Hang2023ASMFTC": ("papers.p003_hang2023.blocks:controller", "ftcsim_controller_asmftc_hang2023.py"),
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
