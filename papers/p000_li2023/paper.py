"""Paper 000 (Li, Xu, Chang 2023) as the registry sees it."""
from papers.paper import DesignSpec, FMUSpec, OptionSpec, Paper

_DISK = (OptionSpec("phi", "pole-disk centre (1/s)"), OptionSpec("eps", "pole-disk radius (1/s)", check="positive"))

PAPER = Paper(
    id="000",
    key="li2023",
    title="Li, Xu, Chang, Fuzzy model based fault estimation and fault tolerant control for flexible "
          "spacecraft with unmeasurable vibration modes, IET Control Theory Appl. 17 (2023)",
    package="papers.p000_li2023",
    fmus=(
        FMUSpec("FlexibleSpacecraft", "papers.p000_li2023.blocks:flexible_spacecraft",
                "flexible spacecraft 000 (2)-(7) with faults, saturation, misalignment"),
        FMUSpec("PDController", "papers.p000_li2023.blocks:pd_controller", "PD with feed-forward 000 (69)"),
        FMUSpec("FAFEO", "papers.p000_li2023.blocks:fafeo", "fuzzy adaptive fault-estimation observer 000 (16)-(17)"),
        FMUSpec("FASMC", "papers.p000_li2023.blocks:fasmc", "fuzzy adaptive sliding-mode FTC 000 (40), (64)"),
        FMUSpec("AISMC", "papers.p000_li2023.blocks:aismc", "adaptive integral sliding-mode baseline 000 (70)-(71)"),
    ),
    parameter_sets={"li2023": "papers.p000_li2023.parameters:LI2023"},
    designs=(
        DesignSpec("li2023-observer", "papers.p000_li2023.design_observer", "000 Theorem 1, (23)-(24)", _DISK),
        DesignSpec("li2023-controller", "papers.p000_li2023.design_controller", "000 Theorem 2, (41)-(44)",
                   _DISK + (OptionSpec("mu", "bound on ||s(0)||", check="positive"),
                            OptionSpec("varsigma", "bound on ||v||", check="positive"))),
    ),
    metrics="papers.p000_li2023.metrics:metrics",
    report="papers.p000_li2023.report:make_report",
    demo=("li2023_pd", "li2023_fasmc", "li2023_aismc", "li2023_pd_fe", "li2023_fasmc_weak"),
    benchmarks=(("li2023_pd", None, 3), ("li2023_fasmc", None, 3), ("li2023_fasmc", 0.001, 1)),
)
