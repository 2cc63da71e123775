"""Paper 003 (Hang, Su, Deng 2023) as the registry sees it."""
from papers.paper import DesignSpec, OptionSpec, Paper

PAPER = Paper(
    id="003",
    key="hang2023",
    title="Hang, Su, Deng, Adaptive sliding mode fault-tolerant attitude control for flexible satellites based on "
          "T-S fuzzy disturbance modeling, MBE 20(7) (2023)",
    package="papers.p003_hang2023",
    designs=(
        DesignSpec("hang2023-tsfdo", "papers.p003_hang2023.design_cli", "003 Theorem 1, (3.4)", (
            OptionSpec("alpha", "fixed decay rate instead of the search (1/s)", check="positive"),
        )),
    ),
)
