"""Paper 000 (Li, Xu, Chang 2023) as the registry sees it."""
from papers.paper import DesignSpec, OptionSpec, declare

_DISK = (OptionSpec("phi", "pole-disk centre (1/s)"), OptionSpec("eps", "pole-disk radius (1/s)", check="positive"))

PAPER = declare(
    "000", "li2023",
    "Li, Xu, Chang, Fuzzy model based fault estimation and fault tolerant control for flexible "
    "spacecraft with unmeasurable vibration modes, IET Control Theory Appl. 17 (2023)",
    fmus=(
        ("FlexibleSpacecraft", "flexible_spacecraft", "flexible spacecraft 000 (2)-(7) with faults, saturation, misalignment"),
        ("PDController", "pd_controller", "PD with feed-forward 000 (69)"),
        ("FAFEO", "fafeo", "fuzzy adaptive fault-estimation observer 000 (16)-(17)"),
        ("FASMC", "fasmc", "fuzzy adaptive sliding-mode FTC 000 (40), (64)"),
        ("AISMC", "aismc", "adaptive integral sliding-mode baseline 000 (70)-(71)"),
    ),
    parameters="LI2023",
    designs=(
        DesignSpec("li2023-observer", ".design_observer", "000 Theorem 1, (23)-(24)", _DISK),
        DesignSpec("li2023-controller", ".design_controller", "000 Theorem 2, (41)-(44)",
                   _DISK + (OptionSpec("mu", "bound on ||s(0)||", check="positive"),
                            OptionSpec("varsigma", "bound on ||v||", check="positive"))),
    ),
    demo=("li2023_pd", "li2023_fasmc", "li2023_aismc", "li2023_pd_fe", "li2023_fasmc_weak", "li2023_fasmc_peraxis"),
    benchmarks=(("li2023_pd", None, 3), ("li2023_fasmc", None, 3), ("li2023_fasmc", 0.001, 1)),
)
