"""The FTC arena (issue 26): every method of the five papers on every plant it can fly.

This package is to the cross-paper comparison what ``papers/pNNN_*`` is to one paper: it
configures the paper-agnostic models of ``plant/``, ``estimator/`` and ``controller/`` and holds
no algorithm of its own:

* ``blocks.py``     factories of the arena's FMUs (adapters, fault catalog, hardware), numpy only;
* ``catalog.py``    those FMUs and the parameter sets (models + re-designed gains) for the registry;
* ``parameters.py`` the parameter sets: a method's model and gains for another paper's plant;
* ``gains.py``      gains re-designed by ``design.py`` (generated data, with provenance);
* ``design.py``     the re-designs (cvxpy, through the papers' own design code);
* ``metrics.py``    the one metric set, pure functions over a trajectory (numpy);
* ``scenarios/``    cross-paper pairs as scenario files.

The application (``ftcsim arena``, issues 26 and 33): ``arenafile.py`` (the arena file and the command
line's overrides), ``cells.py`` (a cell's scenario and campaigns), ``plan.py`` (every cell in one plan,
each cell's digest), ``app.py`` (the folder, the runs, resume), ``measure.py`` (one run: metrics,
outcome, feasibility), ``detector.py`` (the calibrated detector), ``stats.py`` (scipy statistics),
``verdicts.py`` (every table and count), ``leaderboard.py`` (figures and the page).

Layers: ``blocks``, ``catalog``, ``parameters``, ``gains`` and ``metrics`` sit with the papers'
declarations (numpy only, importable by the orchestrator); ``design`` sits with the papers'
designs (it imports cvxpy and the papers' design modules).
"""
