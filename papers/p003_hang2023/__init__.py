"""Paper 003: Hang, Su, Deng, "Adaptive sliding mode fault-tolerant attitude control for flexible
satellites based on T-S fuzzy disturbance modeling", MBE 20(7) (2023)."""
