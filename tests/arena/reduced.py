"""A reduced arena for tests: 002's H-infinity law (re-designed gains) on 003's pitch axis, 000's FAFEO
+ FASMC (re-designed gains) and PD (published gains) on 001's four-wheel craft, ideal and realistic hardware, two fault classes,
two draws, six seconds of mission, in-process. The H-infinity cell is labelled "own" here (it is not
a paper's own pair): the reduced arena needs a reference pair that settles within seconds to exercise
the accuracy-with-realistic-hardware verdict."""
import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "arena" / "scenarios"
FILES = ("arena_hinf_on_hang2023.toml", "arena_fasmc_on_zhang2019.toml", "arena_pd_on_zhang2019.toml")

ARENA = '''
[arena]
name = "reduced"
description = "a reduced arena (tests)"
draws = 2
seed = 7
mode = "inprocess"
hardware = ["ideal", "realistic"]
faults = ["none", "bias"]
stop = 6.0
trajectory_step = 0.02
accuracy_tolerance = 2.0

[statistics]
bootstrap = 200

[detection]
false_alarms_per_hour = 10.0
persistence = 0.2

[dispersions]
onset = [1.0, 3.0]
loss = [0.3, 0.7]
magnitude = [0.5, 1.5]

[plants.hang2023]
mission = 60.0
band = 0.02
fault_torque = 0.05
wheels = "wheels_hr12_12"
gyro = "gyro_stim300"
attitude_sensor = "angle_small"
hold = "zoh_10hz"

[plants.zhang2019]
mission = 60.0
band = 0.2
fault_torque = 0.1
wheels = "wheels_hr12_50"
gyro = "gyro_stim300"
attitude_sensor = "st_small"
hold = "zoh_10hz"

[methods.hinf]
label = "002 robust H-infinity"
paper = "002"
claims = ["loe_step"]

[methods.fasmc]
label = "000 FAFEO + FASMC"
paper = "000"
claims = ["bias", "time_varying"]

[methods.pd]
label = "000 PD"
paper = "000"
claims = ["bias", "time_varying"]

[[cells]]
method = "hinf"
plant = "hang2023"
scenario = "scenarios/arena_hinf_on_hang2023.toml"
gains = "own"

[[cells]]
method = "fasmc"
plant = "zhang2019"
scenario = "scenarios/arena_fasmc_on_zhang2019.toml"
gains = "redesigned"
estimate = "est.f_hat"
truth = "truth.fault_torque"
estimate_from = 0.5

[[cells]]
method = "pd"
plant = "zhang2019"
scenario = "scenarios/arena_pd_on_zhang2019.toml"
gains = "published"
'''


def write(folder: Path, text: str = ARENA, name: str = "reduced.toml") -> Path:
    """The arena file and copies of its cells' scenarios in ``folder``."""
    (folder / "scenarios").mkdir(parents=True, exist_ok=True)
    for f in FILES:
        shutil.copy(SCENARIOS / f, folder / "scenarios" / f)
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path
