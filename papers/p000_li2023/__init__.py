"""Paper 000: Li, Xu, Chang, "Fuzzy model based fault estimation and fault tolerant control for
flexible spacecraft with unmeasurable vibration modes", IET Control Theory Appl. 17 (2023).
See README.md for every reading chosen."""
