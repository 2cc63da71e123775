"""Paper 001's descriptor for the registry (papers/registry.py)."""
from papers.paper import FMUSpec, Paper

PAPER = Paper(
    id="001",
    key="zhang2019",
    title="Zhang, Gao, Qian, Bai: Integrated fault estimation and fault-tolerant control for rigid "
    "spacecraft attitude system with multiple actuator faults (2019)",
    package="papers.p001_zhang2019",
    fmus=(
        FMUSpec("RigidSpacecraftWheels", "papers.p001_zhang2019.blocks:plant",
                "rigid spacecraft, 2-3-1 Euler angles, 4 wheels with faults, 001 (1)-(3), (5)"),
        FMUSpec("ASMFEO", "papers.p001_zhang2019.blocks:observer",
                "adaptive sliding-mode fault-estimation observer, 001 (12), (14), (15)"),
        FMUSpec("FONTSM", "papers.p001_zhang2019.blocks:controller",
                "backstepping + fractional-order NTSM FE/FTC, 001 (23)-(36)"),
    ),
    parameter_sets={"zhang2019": "papers.p001_zhang2019.parameters:ZHANG2019"},
    designs=(),  # 001 has no LMI: Theorem 3.1's condition is checked in analysis.py
    metrics="papers.p001_zhang2019.metrics:metrics",
    report="papers.p001_zhang2019.report:make_report",
    demo=("zhang2019_fontsm",),
    benchmarks=(("zhang2019_fontsm", None, 1),),
)
