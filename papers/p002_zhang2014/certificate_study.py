"""What Table 1's published V1, W certify in 002 (22), per omega_hat (LMI solves of about 10 s each),
stored in ``certificate_study.json`` with this command so the report reads it (the tests solve the
omega_hat = 1 case again and compare):

    python -m papers.p002_zhang2014.certificate_study --out papers/p002_zhang2014/certificate_study.json

Each entry is :func:`papers.p002_zhang2014.reproduction.published_certificate`.
"""
from __future__ import annotations

import sys
from datetime import date

from papers import stored_study

from .reproduction import STUDY

COMMAND = "python -m papers.p002_zhang2014.certificate_study --out papers/p002_zhang2014/certificate_study.json"


def study() -> dict:
    from .gains import CASES
    from .reproduction import published_certificate

    return {"source": "002 (22) with Table 1's V1, W; papers/p002_zhang2014/reproduction.py:published_certificate",
            "date": date.today().isoformat(), "command": COMMAND,
            "certificates": {f"{w:g}": published_certificate(w) for w in CASES}}


def main(argv=None) -> int:
    return stored_study.main("python -m papers.p002_zhang2014.certificate_study", __doc__, study, STUDY, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
