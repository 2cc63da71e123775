"""Paper 004 (Xu, Song, Wang 2024) as the registry sees it."""
from papers.paper import Paper

PAPER = Paper(
    id="004",
    key="xu2024",
    title="Xu, Song, Wang, Finite-Time Fuzzy Fault-Tolerant Control for Nonlinear Flexible Spacecraft System with "
          "Stochastic Actuator Faults, Mathematics 12(4) 503 (2024)",
    package="papers.p004_xu2024",
    parameter_sets={"xu2024": "papers.p004_xu2024.parameters:XU2024"},
)
