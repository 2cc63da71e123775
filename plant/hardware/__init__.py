"""Realistic hardware as blocks (issue 26 item 4), selectable per scenario; the papers' ideal
hardware (no such block in the loop) stays the default of their own scenarios.

* ``wheels.py``      reaction wheels: torque and momentum limits, speed saturation, friction,
                     torque-command bandwidth;
* ``sensors.py``     rate gyro (angle random walk, rate random walk, bias instability), star tracker,
                     single-axis angle sensor; sampled at their own rates, seeded, rollback-safe;
* ``sample_hold.py`` zero-order hold at a controller sample rate;
* ``sampling.py``    the sample clock and the seeded noise stream they share;
* ``datasheets.py``  parameter sets from data sheets and textbooks, with their sources.
"""
