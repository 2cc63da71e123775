"""ftcsim: spacecraft attitude fault estimation and fault-tolerant control as FMI co-simulation
components. The Python API (see :mod:`orchestrator.api`)::

    import ftcsim
    r = ftcsim.run("li2023_fasmc", stop=60, mode="inprocess")
    r.df, r.metrics
"""
from orchestrator.api import Result, load, run, scenarios

__all__ = ["Result", "load", "run", "scenarios"]
