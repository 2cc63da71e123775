"""ftcsim: spacecraft attitude fault estimation and fault-tolerant control as FMI co-simulation
components. The Python API (see :mod:`orchestrator.api`)::

    import ftcsim
    r = ftcsim.run("li2023_fasmc", stop=60, mode="inprocess")
    r.df, r.metrics, r.units, r.plot()
    r = ftcsim.open("results/li2023_fasmc")                          # a run folder read back
    df = ftcsim.campaign("campaigns/li2023_methods.toml", "results/li2023_methods")  # summary table
    ftcsim.fdir_calibrate("zhang2019_fdir_calibration", detector="det", rate_per_hour=1.0,
                          draws="results/fdir_draws", out="results/fdir_calibration.json")   # docs/fdir.md
"""
from orchestrator.api import Result, campaign, fdir_calibrate, load, open, run, scenarios  # noqa: A004 (ftcsim.open)

__all__ = ["Result", "campaign", "fdir_calibrate", "load", "open", "run", "scenarios"]
