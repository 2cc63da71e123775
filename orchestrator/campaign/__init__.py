"""Many runs (floor 4.4): ``spec`` (campaign files, their variants and base scenarios), ``expand``
(draws, grid points, run keys), ``worker`` (one run), ``store`` (the campaign folder), ``cluster``
(Dask), ``run`` (run or resume a campaign, replay one run), ``compare`` (a user's controller as one
more variant) and ``report`` (statistics, requirements, worst runs, plots)."""
