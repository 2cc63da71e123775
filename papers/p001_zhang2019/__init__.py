"""Paper 001: Zhang, Gao, Qian, Bai, "Integrated fault estimation and fault-tolerant control for
rigid spacecraft attitude system with multiple actuator faults", IJICIC (2019)."""
