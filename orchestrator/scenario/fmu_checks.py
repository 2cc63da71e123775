"""Checks an FMU must pass before anything loads it (and what ``ftcsim validate`` reports).

``fmpy.validate_fmu`` checks the modelDescription against the schema; it does not check that
the FMU can load on this machine. :func:`load_problems` adds what loading needs: zip entries
that stay inside the archive, a plain ``modelIdentifier`` (it becomes a file name), the binary
for this platform, and for pythonfmu FMUs the slave script the binary will import.
"""
from __future__ import annotations

import re
import zipfile

from fmus.validation import validate_fmu
from orchestrator.common.archives import check_members
from orchestrator.common.errors import InputError

PLAIN_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,127}$")


def _platform_dir(fmi_version: str) -> str:
    import fmpy

    return fmpy.platform_tuple if fmi_version.startswith("3") else fmpy.platform


def load_problems(path, md=None) -> list[str]:
    """Why the FMU at ``path`` cannot be loaded here (empty list: it can be tried)."""
    from fmpy import read_model_description, sharedLibraryExtension

    try:
        infos = check_members(path)
    except InputError as e:
        return [e.problem]
    names = {i.filename for i in infos}
    if "modelDescription.xml" not in names:
        return ["no modelDescription.xml in the archive"]
    if md is None:
        try:
            md = read_model_description(str(path), validate=False)
        except Exception as e:
            return [f"unreadable modelDescription.xml: {' '.join(str(e).split())[:200]}"]
    if md.coSimulation is None:
        return ["not a co-simulation FMU"]
    problems = []
    mid = md.coSimulation.modelIdentifier or ""
    if not PLAIN_IDENTIFIER.match(mid):
        return [f"modelIdentifier {mid!r} is not a plain name (letters, digits, '_'); refused"]
    binary = f"binaries/{_platform_dir(md.fmiVersion)}/{mid}{sharedLibraryExtension}"
    if binary not in names:
        problems.append(f"no binary for this platform: {binary} is missing")
    if "resources/slavemodule.txt" in names:  # a pythonfmu(3) FMU: the binary imports this script
        with zipfile.ZipFile(path) as z:
            module = z.read("resources/slavemodule.txt").decode("utf-8", "replace").strip()
        if not PLAIN_IDENTIFIER.match(module):
            problems.append(f"resources/slavemodule.txt names {module!r}, not a plain module name")
        elif f"resources/{module}.py" not in names:
            problems.append(f"its Python slave script resources/{module}.py is missing")
    return problems


def check_fmu(path) -> list[str]:
    """Everything ``ftcsim validate`` reports for one FMU: load problems, then fmpy's validation."""
    problems = load_problems(path)
    if problems:
        return problems
    try:
        return validate_fmu(path)
    except Exception as e:
        return [f"fmpy.validate_fmu failed: {' '.join(str(e).split())[:200]}"]


def toolbox_problems(path) -> list[str] | None:
    """What the fmu-manipulation-toolbox checker (``fmutool -input X.fmu -check``: the FMI XSD
    schema and the rules it cannot express) reports as errors; None if the toolbox is not
    installed (it is a test extra, not a dependency)."""
    import logging

    try:
        from fmu_manipulation_toolbox.checker import get_checkers
        from fmu_manipulation_toolbox.operations import FMU
    except ImportError:
        return None

    class Collect(logging.Handler):
        def __init__(self):
            super().__init__(logging.ERROR)
            self.messages = []

        def emit(self, record):
            self.messages.append(record.getMessage())

    logger = logging.getLogger("fmu_manipulation_toolbox")
    handler = Collect()
    logger.addHandler(handler)
    try:
        with FMU(str(path)) as fmu:
            for checker in get_checkers():
                fmu.apply_operation(checker())
    except Exception as e:
        handler.messages.append(f"the toolbox could not read the FMU: {' '.join(str(e).split())[:200]}")
    finally:
        logger.removeHandler(handler)
    return handler.messages
