"""Which blocks become which FMUs: the papers' registry (``papers/registry.py``) plus the
generic FMUs, as ``model name -> FMUSpec(model, factory, description)``."""
from __future__ import annotations


def catalog() -> dict:
    """Model name -> :class:`papers.paper.FMUSpec`, in registry order."""
    from papers.registry import fmu_specs

    return fmu_specs()


def block_factory(model_name: str):
    """The callable returning a fresh, configured block for an FMU model (``KeyError`` if not ours)."""
    from papers.paper import resolve

    return resolve(catalog()[model_name].factory)


def module_name(model_name: str, fmi_version: str = "2") -> str:
    """The stem of the FMU's slave module name, per model and FMI version (``ftcsim_fafeo``,
    ``ftcsim3_fafeo``); the build appends the digest of the FMU's code (``ftcsim_fafeo_<10 hex>``),
    so that FMUs of every model, version and build can be loaded in one process."""
    stem = "".join(c if c.isalnum() else "_" for c in model_name.lower())
    return ("ftcsim_" if str(fmi_version).startswith("2") else "ftcsim3_") + stem
