"""Paper 001's descriptor for the registry (papers/registry.py)."""
from papers.paper import declare

PAPER = declare(
    "001", "zhang2019",
    "Zhang, Gao, Qian, Bai: Integrated fault estimation and fault-tolerant control for rigid "
    "spacecraft attitude system with multiple actuator faults (2019)",
    fmus=(
        ("RigidSpacecraftWheels", "plant", "rigid spacecraft, 2-3-1 Euler angles, 4 wheels with faults, 001 (1)-(3), (5)"),
        ("ASMFEO", "observer", "adaptive sliding-mode fault-estimation observer, 001 (12), (14), (15)"),
        ("FONTSM", "controller", "backstepping + fractional-order NTSM FE/FTC, 001 (23)-(36)"),
    ),
    parameters="ZHANG2019",
    designs=(),  # 001 has no LMI: Theorem 3.1's condition is checked in analysis.py
    demo=("zhang2019_fontsm", "zhang2019_fontsm_paired", "zhang2019_fontsm_smooth", "zhang2019_fontsm_fast_observer",
          "zhang2019_fontsm_accurate"),
    benchmarks=(("zhang2019_fontsm", None, 1),),
)
