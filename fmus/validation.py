"""``fmpy.validate_fmu`` with its variable-name check made fast for plain names.

fmpy checks every variable name of a "structured" FMU with a Lark Earley parser of the FMI
naming grammar (fmpy/validation.py ``_validate_variable_names``): about 9 ms per name, so
0.6 s per FMU and half of ``ftcsim build``. The names our blocks declare (``omega[2]``,
``theta_hat``, ``wheel.tau[1]``) lie in a regular subset of that grammar, matched here by
:data:`PLAIN_STRUCTURED_NAME`; an FMU all of whose names match it gets fmpy's validation with
the name check off, any other FMU (quoted names, ``der(...)``, anything unusual) gets fmpy's
full ``validate_fmu``. The regex accepts only names the grammar accepts, so the verdict is
fmpy's in every case (tests/fmus/test_validation.py compares both on accepted and refused names).
"""
from __future__ import annotations

import re
import zipfile
from pathlib import Path

# FMI 2.0 / 3.0 structured naming, without q-names and der(): identifier = bname [arrayindices] {"." bname [arrayindices]}
_BNAME = r"[A-Za-z_][A-Za-z0-9_]*"
_INDICES = r"(?:\[[0-9]+(?:,[0-9]+)*\])?"
PLAIN_STRUCTURED_NAME = re.compile(rf"{_BNAME}{_INDICES}(?:\.{_BNAME}{_INDICES})*")


def validate_fmu(path) -> list[str]:
    """The problems ``fmpy.validation.validate_fmu`` reports for the FMU at ``path`` (empty: valid)."""
    from fmpy import read_model_description
    from fmpy.model_description import ValidationError
    from fmpy.validation import validate_fmu as fmpy_validate_fmu

    path = str(path)
    try:
        names = [v.name for v in read_model_description(path, validate=False).modelVariables]
    except Exception:  # noqa: BLE001 - unreadable: fmpy's own validation says how
        return list(fmpy_validate_fmu(path))
    if not all(PLAIN_STRUCTURED_NAME.fullmatch(n) for n in names):
        return list(fmpy_validate_fmu(path))
    problems = []
    if Path(path).is_file():  # as fmpy: archive paths with a backslash
        with zipfile.ZipFile(path) as z:
            problems += [f'The file path "{i.orig_filename}" contains a backslash.' for i in z.filelist
                         if "\\" in i.orig_filename]
    try:
        read_model_description(path, validate=True, validate_variable_names=False, validate_model_structure=True)
    except ValidationError as e:
        problems = list(e.problems)
    except Exception as e:  # noqa: BLE001 - as fmpy: the message is the problem
        problems = [str(e)]
    return problems
