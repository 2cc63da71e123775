"""ftcsim: spacecraft attitude fault estimation and fault-tolerant control as FMI co-simulation
components. The Python API (see :mod:`orchestrator.api`)::

    import ftcsim
    r = ftcsim.run("li2023_fasmc", stop=60, mode="inprocess")
    r.df, r.metrics, r.units, r.plot()
    r = ftcsim.open("results/li2023_fasmc")                          # a run folder read back
    df = ftcsim.campaign("campaigns/li2023_methods.toml", "results/li2023_methods")  # summary table
    df = ftcsim.read_table("results/li2023_methods/summary.parquet")  # any ftcsim Parquet file or folder
    df.attrs["units"]                                                  # {column: unit}
    ftcsim.fdir_calibrate("zhang2019_fdir_calibration", detector="det", rate_per_hour=1.0,
                          draws="results/fdir_draws", out="results/fdir_calibration.json")   # docs/fdir.md

Bad input (a scenario, a parameter, a file) raises :class:`ftcsim.InputError` (``.source``, ``.key``,
``.problem``), the error the command line prints as one line with exit status 2.
"""
from orchestrator.api import Result, campaign, fdir_calibrate, load, open, run, scenarios  # noqa: A004 (ftcsim.open)
from orchestrator.common.errors import InputError
from orchestrator.common.parquet import read_table

__all__ = ["InputError", "Result", "campaign", "fdir_calibrate", "load", "open", "read_table", "run", "scenarios"]
