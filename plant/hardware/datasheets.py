"""Parameter sets of real hardware, under the blocks' parameter names (SI), with their sources.

Each set is a dict ``parameter base name -> value`` for one block of ``plant/hardware``; the arena
registers them as parameter sets (``parameter_set = "wheels_hr12_12"`` on an instance). Values
marked "ours" are not on the cited sheet: they are stated choices, kept selectable.

Reaction wheels (``ReactionWheels``): Honeywell *Constellation Series Reaction Wheels* data sheet
(HR12 / HR16: 0.2 N.m motor torque, 6000 rpm, momentum 12/25/50 and 50/75/100 N.m.s by size),
with the Coulomb friction 0.5 mN.m that Basilisk (AVSLab/basilisk ``src/utilities/simIncludeRW.py``,
``Honeywell_HR12`` / ``Honeywell_HR16``) uses for these wheels; Blue Canyon Technologies
*Reaction Wheels* data sheet (RWp015: 0.015 N.m.s, 4 mN.m, 6000 rpm, as in the same Basilisk file,
``BCT_RWP015``, friction 0.05 mN.m there). I_w = h_max / Omega_max. Not on the sheets (ours): the
torque-loop time constant 0.05 s (a 3.2 Hz drive bandwidth), no viscous friction, the Coulomb law
smoothed below 0.1 rad/s.

Gyros (``RateGyro``; ``arw``/``rrw`` in the block's units: sigma_v, sigma_u numerically):

* ``gyro_textbook``: sigma_v = sqrt(10) 1e-7 rad/s^0.5, sigma_u = sqrt(10) 1e-10 rad/s^1.5, the
  gyro of the attitude-estimation examples of Crassidis & Junkins, *Optimal Estimation of Dynamic
  Systems* (2nd ed., 2012) and Markley & Crassidis (2014); no separate bias instability; 10 Hz (ours).
* ``gyro_stim300``: Safran Sensonor STIM300 data sheet (tactical-grade MEMS): angle random walk
  0.15 deg/sqrt(h), bias instability 0.5 deg/h; the instability as a Gauss-Markov process with
  correlation time 300 s (ours), initial bias 0; 100 Hz (ours; the sheet allows up to 2 kHz).
* ``gyro_navigation``: navigation-grade class values (Honeywell HG9900 class: angle random walk
  0.002 deg/sqrt(h), bias instability 0.003 deg/h), correlation time 3600 s (ours); 100 Hz (ours).

Star trackers (``StarTracker``): ``st_small``: a small-satellite star tracker, 6 arcsec (1 sigma)
across the boresight and 40 arcsec about it at 5 Hz (the order of the small trackers' sheets,
e.g. the Blue Canyon nano star tracker; our set, not one sheet); ``st_precise``: 1 arcsec across,
10 arcsec about, 10 Hz (the order of large trackers such as Sodern Hydra; our set). Markley &
Crassidis (2014) for the error model.

Angle sensor of the pitch-axis plants (``AngleSensor``): ``angle_small``: the cross-boresight
noise of ``st_small`` about the pitch axis at 5 Hz.

Controller sample rate (``ZeroOrderHold``): ``zoh_10hz`` (0.1 s), ``zoh_50hz`` (0.02 s) (ours).
"""
from __future__ import annotations

import math

ARCSEC = math.pi / (180.0 * 3600.0)  # rad
DEG_PER_HOUR = math.pi / (180.0 * 3600.0)  # rad/s
DEG_PER_SQRT_HOUR = math.pi / 180.0 / 60.0  # rad/s^0.5 (1 deg/sqrt(h) = pi/180 / sqrt(3600 s))
RPM = 2.0 * math.pi / 60.0  # rad/s


def wheel(tau_max: float, h_max: float, rpm_max: float, coulomb: float, time_constant: float = 0.05) -> dict:
    """A ``ReactionWheels`` set from data-sheet figures (I_w = h_max / Omega_max)."""
    return {"tau_max": tau_max, "h_max": h_max, "I_w": h_max / (rpm_max * RPM), "coulomb": coulomb,
            "viscous": 0.0, "time_constant": time_constant, "omega_eps": 0.1}


WHEELS = {
    "wheels_hr12_12": wheel(0.2, 12.0, 6000.0, 0.0005),
    "wheels_hr12_50": wheel(0.2, 50.0, 6000.0, 0.0005),
    "wheels_hr16_100": wheel(0.2, 100.0, 6000.0, 0.0005),
    "wheels_rwp015": wheel(0.004, 0.015, 6000.0, 0.00005),
}

GYROS = {
    "gyro_textbook": {"arw": math.sqrt(10.0) * 1e-7, "rrw": math.sqrt(10.0) * 1e-10, "bi_sigma": 0.0,
                      "bi_tau": 3600.0, "sample_period": 0.1},
    "gyro_stim300": {"arw": 0.15 * DEG_PER_SQRT_HOUR, "rrw": 0.0, "bi_sigma": 0.5 * DEG_PER_HOUR,
                     "bi_tau": 300.0, "sample_period": 0.01},
    "gyro_navigation": {"arw": 0.002 * DEG_PER_SQRT_HOUR, "rrw": 0.0, "bi_sigma": 0.003 * DEG_PER_HOUR,
                        "bi_tau": 3600.0, "sample_period": 0.01},
}

STAR_TRACKERS = {
    "st_small": {"sigma_cross": 6.0 * ARCSEC, "sigma_roll": 40.0 * ARCSEC, "sample_period": 0.2},
    "st_precise": {"sigma_cross": 1.0 * ARCSEC, "sigma_roll": 10.0 * ARCSEC, "sample_period": 0.1},
}

ANGLE_SENSORS = {"angle_small": {"sigma": 6.0 * ARCSEC, "sample_period": 0.2}}

HOLDS = {"zoh_10hz": {"sample_period": 0.1}, "zoh_50hz": {"sample_period": 0.02}}

ALL = {**WHEELS, **GYROS, **STAR_TRACKERS, **ANGLE_SENSORS, **HOLDS}
