"""000's Appendix A numbers against Theorems 1 and 2: what the reproduction table reads (LMI solves of
seconds each, stored in ``appendix_study.json`` with this command; the tests solve the designs again):

    python -m papers.p000_li2023.appendix_study --out papers/p000_li2023/appendix_study.json

* ``gamma_1_design`` / ``gamma_2_design``: the smallest gamma our Theorem 1 (23)-(24) / Theorem 2
  (41)-(44) designs certify with 000's printed settings (disk O(-10, 10); mu, varsigma, disk O(-20, 20)),
  next to the printed 1.6563 / 1.7919. 000 does not say that it minimised gamma: the minimum is our
  objective (a documented reading).
* ``A1_lmi_23``, ``A2_lmi_41``: the printed gains with the printed gamma in (23) / (41) with one common
  Lyapunov matrix: the infeasibility certificate's bound (every point with entries in [-100, 100]
  violates an LMI by at least this much; 0 or below: a feasible point exists).
"""
from __future__ import annotations

import sys
from datetime import date
from pathlib import Path

from papers import stored_study

STUDY = Path(__file__).with_name("appendix_study.json")
COMMAND = "python -m papers.p000_li2023.appendix_study --out papers/p000_li2023/appendix_study.json"


def certificate_bound(cert: dict) -> float:
    """The violation bound of an LMI feasibility answer: > 0 certified infeasible, <= 0 feasible."""
    if cert.get("feasible"):
        return 0.0
    b = cert.get("bound")
    return float(b) if b is not None else float("inf")


def study() -> dict:
    from . import design_controller as dc
    from . import design_observer as de

    obs, ctl = de.design(), dc.design()
    pub_o, pub_c = de.published_gains(), dc.published_gains()
    c23 = de.lmi_certificate(**pub_o, which=("23",))
    c41 = dc.lmi_certificate(pub_c["K_c"], pub_c["gamma_2"], which=("41",))
    return {"source": "000 Theorems 1-2 and Appendix A; papers/p000_li2023/design_observer.py, design_controller.py",
            "date": date.today().isoformat(), "command": COMMAND,
            "gamma_1_design": float(obs["performance"]["gamma_1"]),
            "gamma_2_design": float(ctl["performance"]["gamma_2"]),
            "A1_lmi_23": {"gamma_1": pub_o["gamma_1"], "bound": certificate_bound(c23), "message": c23["message"]},
            "A2_lmi_41": {"gamma_2": pub_c["gamma_2"], "bound": certificate_bound(c41), "message": c41["message"]}}


def load() -> dict | None:
    """The stored study (None if the file is missing)."""
    return stored_study.load(STUDY)


def main(argv=None) -> int:
    return stored_study.main("python -m papers.p000_li2023.appendix_study", __doc__, study, STUDY, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
