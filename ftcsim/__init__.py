"""ftcsim: spacecraft attitude fault estimation and fault-tolerant control as FMI co-simulation
components. The Python API (see :mod:`orchestrator.api`)::

    import ftcsim
    r = ftcsim.run("li2023_fasmc", stop=60, mode="inprocess")
    r.df, r.metrics, r.units, r.plot()
    r = ftcsim.open("results/li2023_fasmc")                          # a run folder read back
    df = ftcsim.campaign("campaigns/li2023_methods.toml", "results/li2023_methods")  # summary table
"""
from orchestrator.api import Result, campaign, load, open, run, scenarios  # noqa: A004 (ftcsim.open)

__all__ = ["Result", "campaign", "load", "open", "run", "scenarios"]
