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
    # paper 004 (Xu, Song, Wang 2024): factories in papers/p004_xu2024/blocks.py
    "Xu2024FlexiblePlant": ("papers.p004_xu2024.blocks:flexible_plant", "ftcsim_xu2024_plant_flexible.py"),
    "Xu2024TSPlant": ("papers.p004_xu2024.blocks:ts_plant", "ftcsim_xu2024_plant_ts.py"),
    "Xu2024MarkovFaults": ("papers.p004_xu2024.blocks:mode_source", "ftcsim_xu2024_markov_faults.py"),
    "Xu2024FaultActuator": ("papers.p004_xu2024.blocks:fault_actuator", "ftcsim_xu2024_fault_actuator.py"),
    "Xu2024Disturbance": ("papers.p004_xu2024.blocks:disturbance", "ftcsim_xu2024_disturbance.py"),
    "Xu2024SampledFTC": ("papers.p004_xu2024.blocks:controller", "ftcsim_xu2024_controller_sdftc.py"),
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
