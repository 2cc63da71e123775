"""Paper 004: Xu, Song, Wang, "Finite-Time Fuzzy Fault-Tolerant Control for Nonlinear Flexible
Spacecraft System with Stochastic Actuator Faults", Mathematics 12(4) 503 (2024)."""
