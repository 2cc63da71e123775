"""Published TSFDO gain of 003 section 4 (numpy only).

Printed "L1=[01.54x10^3 02.35x10^4]": L1 = [[0, -1.54e3], [0, -2.35e4]]; the negative signs
are the only ones that make W_j + L1 B0 V_j Hurwitz with V_j as read (design.py)."""
import numpy as np

L1_PUBLISHED = np.array([[0.0, -1.54e3], [0.0, -2.35e4]])
