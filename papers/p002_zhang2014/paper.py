"""Paper 002's descriptor for the registry (papers/registry.py)."""
from papers.paper import DesignSpec, OptionSpec, declare

PAPER = declare(
    "002", "zhang2014",
    "Zhang, Qiao, Li, Guo, Robust fault-tolerant control for flexible spacecraft against partial actuator "
    "failures, Nonlinear Dyn. (2014)",
    fmus=(
        ("Zhang2014Plant", "plant", "pitch-axis flexible spacecraft, 002 (1)-(3), section 4 parameters"),
        ("Zhang2014Hinf", "controller",
         "robust H-infinity passive FTC u = K x, 002 (9), Table 2 gains (omega_hat selects the case)"),
    ),
    parameters="PARAMETER_SET",
    designs=(
        DesignSpec("zhang2014-hinf", ".design_cli", "002 Theorem 2, (22)-(23)", options=(
            OptionSpec("omega_hat", "effectiveness cases (at most 3)", nargs="+", check="unit_interval"),
            OptionSpec("j", "relative effectiveness half-width |L| <= j (default 0.75)", check="fraction"),
            OptionSpec("kappa", "kappa values to search", nargs="+", check="positive"),
        )),
    ),
    demo=("zhang2014_hinf_w1", "zhang2014_hinf_w05", "zhang2014_hinf_w02"),
    benchmarks=(("zhang2014_hinf_w1", None, 3),),
)
