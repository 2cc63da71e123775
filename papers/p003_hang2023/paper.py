"""Paper 003's descriptor for the registry (papers/registry.py)."""
from papers.paper import DesignSpec, FMUSpec, OptionSpec, Paper

PAPER = Paper(
    id="003",
    key="hang2023",
    title="Hang, Su, Deng, Adaptive sliding mode fault-tolerant attitude control for flexible satellites based on "
          "T-S fuzzy disturbance modeling, Math. Biosci. Eng. 20(7) (2023)",
    package="papers.p003_hang2023",
    fmus=(
        FMUSpec("Hang2023Plant", "papers.p003_hang2023.blocks:plant",
                "pitch-axis flexible satellite, 003 (2.1)-(2.5), (4.2), effectiveness switch at 20 s"),
        FMUSpec("Hang2023TSFDO", "papers.p003_hang2023.blocks:observer",
                "T-S fuzzy disturbance observer, 003 (3.1), published L1, Gaussian memberships"),
        FMUSpec("Hang2023ASMFTC", "papers.p003_hang2023.blocks:controller",
                "adaptive terminal sliding-mode FTC, 003 (3.9)-(3.21)"),
    ),
    parameter_sets={"hang2023": "papers.p003_hang2023.parameters:PARAMETER_SET"},
    designs=(
        DesignSpec("hang2023-tsfdo", "papers.p003_hang2023.design_cli", "003 Theorem 1, (3.4)", options=(
            OptionSpec("alpha", "fixed decay rate instead of the search", check="positive"),
        )),
    ),
    metrics="papers.p003_hang2023.metrics:metrics",
    report="papers.p003_hang2023.report:make_report",
    demo=("hang2023_asmftc_f04",),
    benchmarks=(("hang2023_asmftc_f04", None, 1),),
)
