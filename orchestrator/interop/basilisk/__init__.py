"""Basilisk (AVS Lab, PyPI ``bsk``) and ftcsim in both directions; ``bsk`` is an optional extra
(``pip install 'ftcsim[basilisk]'``), imported by nothing below this package (the import rule in
pyproject.toml checks it).

* :mod:`.conventions`  the mapped conventions (attitude sets, wheel-command sign, hub inertia, wheel
                       speed, flexible modes as hinged panels): numpy only, importable without bsk;
* :mod:`.module`       :class:`~.module.FMUModule`, a Basilisk ``SysModel`` running any co-simulation FMU
                       (ftcsim's, or any FMI 2.0 / 3.0 one) through fmpy inside a Basilisk simulation;
* :mod:`.spacecraft`   :class:`~.spacecraft.BasiliskSpacecraft`, a block (plant/block.py) backed by a
                       Basilisk spacecraft (hub, reaction wheels, optional hinged panels, gravity
                       gradient), usable in scenarios and built as an FMU;
* :mod:`.mission`      a Basilisk spacecraft with Honeywell wheels (``simIncludeRW``) flown by ftcsim FMUs:
                       the shipped examples of ``python -m orchestrator.tools.basilisk_example``.

This file imports nothing, so that an FMU embedding the spacecraft block carries no more than it.
"""
