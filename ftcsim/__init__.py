"""ftcsim: spacecraft attitude fault estimation and fault-tolerant control as FMI co-simulation
components. The Python API (see :mod:`orchestrator.api`)::

    import ftcsim
    r = ftcsim.run("li2023_fasmc", stop=60, mode="inprocess")
    r.df, r.metrics
    df = ftcsim.campaign("campaigns/li2023_methods.toml", "results/li2023_methods")  # summary table
"""
from orchestrator.api import Result, campaign, load, run, scenarios

__all__ = ["Result", "campaign", "load", "run", "scenarios"]
