"""A reduced arena for tests: two methods on 002's pitch axis (002's own H-infinity pair and 003's
TSFDO + ASMFTC flown there) and 000's FAFEO + FASMC on 001's four-wheel craft, ideal and realistic
hardware, three fault classes, two draws, a few seconds of mission, in-process."""
import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "arena" / "scenarios"
FILES = ("arena_hinf_on_zhang2014.toml", "arena_asmftc_on_zhang2014.toml", "arena_fasmc_on_zhang2019.toml")

ARENA = '''
[arena]
name = "reduced"
description = "a reduced arena (tests)"
draws = 2
seed = 7
mode = "inprocess"
hardware = ["ideal", "realistic"]
faults = ["none", "loe_step", "bias"]
stop = 6.0
trajectory_step = 0.02
accuracy_tolerance = 2.0
bootstrap = 200

[dispersions]
onset = [1.0, 3.0]
loss = [0.3, 0.7]
magnitude = [0.5, 1.5]

[plants.zhang2014]
band = 0.03
fault_torque = 0.1
wheels = "wheels_hr12_12"
gyro = "gyro_stim300"
attitude_sensor = "angle_small"
hold = "zoh_10hz"

[plants.zhang2019]
band = 0.2
fault_torque = 0.1
wheels = "wheels_hr12_50"
gyro = "gyro_stim300"
attitude_sensor = "st_small"
hold = "zoh_10hz"

[methods.hinf]
label = "002 robust H-infinity"
paper = "002"

[methods.asmftc]
label = "003 TSFDO + ASMFTC"
paper = "003"

[methods.fasmc]
label = "000 FAFEO + FASMC"
paper = "000"

[[cells]]
method = "hinf"
plant = "zhang2014"
scenario = "scenarios/arena_hinf_on_zhang2014.toml"
gains = "own"

[[cells]]
method = "asmftc"
plant = "zhang2014"
scenario = "scenarios/arena_asmftc_on_zhang2014.toml"
gains = "redesigned"
estimate = "est.d0_hat"
threshold = 0.05
estimate_from = 0.5

[[cells]]
method = "fasmc"
plant = "zhang2019"
scenario = "scenarios/arena_fasmc_on_zhang2019.toml"
gains = "redesigned"
'''


def write(folder: Path, text: str = ARENA, name: str = "reduced.toml") -> Path:
    """The arena file and copies of its cells' scenarios in ``folder``."""
    (folder / "scenarios").mkdir(parents=True, exist_ok=True)
    for f in FILES:
        shutil.copy(SCENARIOS / f, folder / "scenarios" / f)
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path
