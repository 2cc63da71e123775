"""Paper 002 (Zhang, Qiao, Li, Guo 2014) as the registry sees it."""
from papers.paper import DesignSpec, OptionSpec, Paper

PAPER = Paper(
    id="002",
    key="zhang2014",
    title="Zhang, Qiao, Li, Guo, Robust fault-tolerant control for flexible spacecraft against partial actuator "
          "failures, Nonlinear Dyn. (2014)",
    package="papers.p002_zhang2014",
    designs=(
        DesignSpec("zhang2014-hinf", "papers.p002_zhang2014.design_cli", "002 Theorem 2, (22)", (
            OptionSpec("omega_hat", "effectiveness cases", nargs="+", check="unit_interval"),
            OptionSpec("j", "relative effectiveness half-width", check="fraction"),
            OptionSpec("kappa", "kappa values to search", nargs="+", check="positive"),
        )),
    ),
)
