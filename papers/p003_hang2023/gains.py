"""Published TSFDO gain of 003 section 4 (numpy only).

Printed "L1=[01.54x10^3 02.35x10^4]": L1 = [[0, -1.54e3], [0, -2.35e4]]; the negative signs
are the only ones that make W_j + L1 B0 V_j Hurwitz with V_j as read (design.py)."""
import numpy as np

L1_PUBLISHED = np.array([[0.0, -1.54e3], [0.0, -2.35e4]])

# Ours, not the paper's: the gain of papers/p003_hang2023/design.py (max alpha*beta, Clarabel 0.11.1,
# cvxpy 1.9.3), recorded so that scenarios can select it without a solver. Error eigenvalues
# -10.35, -2.01 (rule 1) and -4.26 +- 5.50j (rule 2). Any gain passing design.verify() may replace it.
L1_DESIGNED = np.array([[0.0, -10.4118620176], [0.0, -4.9613919771]])
