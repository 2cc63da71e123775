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


def fmi_problem(path) -> str | None:
    """Why the FMU at ``path`` is not one ftcsim runs, read from its modelDescription's root element
    before fmpy parses the rest (whose errors on an FMI 1.0 or a versionless file are cryptic): no
    fmiVersion, a version other than 2.0 or 3.0, no co-simulation interface. None when it is one."""
    from lxml import etree

    try:
        with zipfile.ZipFile(path) as z, z.open("modelDescription.xml") as f:
            parser = etree.XMLPullParser(events=("start",), resolve_entities=False, no_network=True)
            root = None
            while root is None:
                chunk = f.read(4096)
                if not chunk:
                    break
                parser.feed(chunk)
                for _, el in parser.read_events():
                    root = el
                    break
            cs = None
            if root is not None:  # the rest of the file, for the CoSimulation element
                for chunk in iter(lambda: f.read(1 << 16), b""):
                    parser.feed(chunk)
                parser.close()
                cs = root.find("CoSimulation")
    except (OSError, KeyError, zipfile.BadZipFile, etree.XMLSyntaxError, ValueError) as e:
        return f"unreadable modelDescription.xml ({' '.join(str(e).split())[:160]})"
    if root is None or root.tag != "fmiModelDescription":
        return "modelDescription.xml has no fmiModelDescription element: not an FMU"
    version = root.get("fmiVersion")
    if not version:
        return "modelDescription.xml declares no fmiVersion: not an FMI 2.0 or 3.0 FMU"
    if version.startswith("1."):
        return (f"an FMI {version} FMU: ftcsim runs FMI 2.0 and 3.0 co-simulation FMUs (export it again as FMI 2.0, "
                "or convert it, e.g. with FMPy's tools)")
    if version not in ("2.0", "3.0"):
        return f"fmiVersion {version!r}: ftcsim runs FMI 2.0 and 3.0 co-simulation FMUs"
    if cs is None:
        return (f"an FMI {version} FMU without a co-simulation interface (Model Exchange only): ftcsim runs "
                "co-simulation FMUs")
    return None


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
    version = fmi_problem(path)
    if version:
        return [version]
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
