"""Paper 002: Zhang, Qiao, Li, Guo, "Robust fault-tolerant control for flexible spacecraft against
partial actuator failures", Nonlinear Dyn. (2014)."""
