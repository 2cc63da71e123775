"""Paper 004's descriptor (Xu, Song, Wang 2024)."""
from papers.paper import DesignSpec, OptionSpec, declare

PAPER = declare(
    "004", "xu2024",
    "Xu, Song, Wang, \"Finite-Time Fuzzy Fault-Tolerant Control for Nonlinear Flexible Spacecraft "
    "System with Stochastic Actuator Faults\", Mathematics 12(4) 503 (2024)",
    fmus=(
        ("Xu2024FlexiblePlant", "flexible_plant", "000's flexible spacecraft with 004's parameter set, no saturation"),
        ("Xu2024TSPlant", "ts_plant", "004's 3-rule T-S attitude model (6) as a plant"),
        ("Xu2024MarkovFaults", "mode_source", "nonhomogeneous Markov fault modes (52)-(53), exact thinning, seeded"),
        ("Xu2024FaultActuator", "fault_actuator", "mode-dependent actuator faults F_r u + G_r v (9) plus d(t)"),
        ("Xu2024Disturbance", "disturbance", "004's disturbance torque d(t)"),
        ("Xu2024SampledFTC", "controller", "sampled-data fuzzy FTC over a sensor network (14), our Theorem-2 gains"),
    ),
    parameters="XU2024",
    designs=(
        DesignSpec("xu2024-ftc", ".design_cli", "004 Theorem 2, (45)-(50), nonhomogeneous case",
                   (OptionSpec("alpha", "exponential rate alpha of Theorem 2 (ours: 0.1)", check="positive"),
                    OptionSpec("T", "finite-time horizon T, s (ours: 10)", check="positive"),
                    OptionSpec("rho_mm", "bound on |h_j(x(t_k)) - h_j(x(t))| (ours: 0.1; the paper's 1)",
                               check="unit_interval"),
                    OptionSpec("eps2", "free parameter eps2 (printed -0.1 is infeasible; ours +0.1)", check="positive"))),
    ),
    demo=("xu2024_ts", "xu2024_flexible", "xu2024_ts_published", "xu2024_network_printed"),
    benchmarks=(("xu2024_ts", None, 1),),
)
