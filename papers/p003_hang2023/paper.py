"""Paper 003's descriptor for the registry (papers/registry.py)."""
from papers.paper import DesignSpec, OptionSpec, declare

PAPER = declare(
    "003", "hang2023",
    "Hang, Su, Deng, Adaptive sliding mode fault-tolerant attitude control for flexible satellites based on "
    "T-S fuzzy disturbance modeling, Math. Biosci. Eng. 20(7) (2023)",
    fmus=(
        ("Hang2023Plant", "plant", "pitch-axis flexible satellite, 003 (2.1)-(2.5), (4.2), effectiveness switch at 20 s"),
        ("Hang2023TSFDO", "observer", "T-S fuzzy disturbance observer, 003 (3.1), published L1, Gaussian memberships"),
        ("Hang2023ASMFTC", "controller", "adaptive terminal sliding-mode FTC, 003 (3.9)-(3.21)"),
    ),
    parameters="PARAMETER_SET",
    designs=(
        DesignSpec("hang2023-tsfdo", ".design_cli", "003 Theorem 1, (3.4)", options=(
            OptionSpec("alpha", "fixed decay rate instead of the search", check="positive"),
        )),
    ),
    demo=("hang2023_asmftc_f04", "hang2023_asmftc_f08", "hang2023_asmftc_f10", "hang2023_asmftc_delivered_f04",
          "hang2023_asmftc_delivered_f08", "hang2023_asmftc_delivered_f10", "hang2023_asmftc_sign_f04",
          "hang2023_asmftc_noobs_f04", "hang2023_asmftc_noobs_g01_f04"),
    benchmarks=(("hang2023_asmftc_f04", None, 1),),
)
