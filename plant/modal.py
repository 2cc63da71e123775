"""Declarations the flexible models share: the modal state of n flexible modes.

eta[1..n] modal coordinates (1) and eta_dot[1..n] modal rates (1/s), as outputs of the plants
(``plant/flexible.py`` 000 (2), ``plant/pitch_axis.py`` 002 (1) / 003 (2.1)) and, with
``_init``, as their initial-value parameters.
"""
from __future__ import annotations

from .block import vector

__all__ = ["modal_state"]


def modal_state(n: int, coordinate: str = "modal displacement", initial: bool = False) -> list:
    """Variables eta[1..n] (1) and eta_dot[1..n] (1/s); ``initial``: eta_init, eta_dot_init.
    ``coordinate`` describes eta (000: modal displacement, 002 / 003: modal coordinate)."""
    suffix, pre = ("_init", "initial ") if initial else ("", "")
    return vector("eta" + suffix, n, "1", pre + coordinate) + vector("eta_dot" + suffix, n, "1/s", pre + "modal rate")
