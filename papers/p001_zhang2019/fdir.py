"""The shipped FDIR calibration on 001's craft (issue 34): the parameter set
``zhang2019_fdir_wheel_loss`` (``papers/registry.py: FDIR_SETS``) that the detector of the scenarios
zhang2019_fdir_wheel_loss(_open) applies, read from the calibration file
``fdir_wheel_loss_calibration.json`` that this command wrote (docs/fdir.md)::

    ftcsim fdir calibrate campaigns/zhang2019_fdir_calibration.toml --detector det --rate 1 \\
        --draws results/fdir_calibration_draws --out papers/p001_zhang2019/fdir_wheel_loss_calibration.json

Its thresholds are never edited by hand: tests/diagnosis/test_shipped_calibration.py checks the file
against the campaign and the scenario it came from."""
from pathlib import Path

from diagnosis.calibration import parameter_set

CALIBRATION = Path(__file__).resolve().parent / "fdir_wheel_loss_calibration.json"
ZHANG2019_FDIR_WHEEL_LOSS = parameter_set(CALIBRATION)
