"""A configured copy of one of our FMUs: the same FMU with other start values.

FMI makes the start values of the modelDescription the FMU's initial values, and our FMUs honour
that (fmus/block_runtime.py: ``model_description_starts``). ``ftcsim export-ssp`` packs, for every
instance, a copy whose start values are the scenario's: a host that applies no SSP parameter set
(Ecos's plain ``init()`` and ``ecos simulate`` without ``--parameterSet``; Ecos applies SSV values
only under a set name) runs the scenario, not the FMU's defaults. The SSV files still carry the
same values for the tools that apply them. FMUs that do not say they honour their start values
(``resources/ftcsim_build.json``: ``start_values``, every FMU built since) are never configured:
rewriting their modelDescription would describe values their code does not use.
"""
from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

START_VALUES = "modelDescription"  # ftcsim_build.json: the FMU starts from its modelDescription's start values


def honours_start_values(fmu) -> bool:
    """True if ``fmu`` (a path) is one of ours that starts from its modelDescription's start values."""
    try:
        with zipfile.ZipFile(fmu) as z:
            info = json.loads(z.read("resources/ftcsim_build.json"))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return False
    return isinstance(info, dict) and info.get("start_values") == START_VALUES


def _set_starts(xml: bytes, values: dict) -> bytes:
    root = ET.fromstring(xml)
    found = {}
    for v in root.find("ModelVariables"):
        name = v.get("name")
        if name not in values:
            continue
        holder = v.find("Real") if v.tag == "ScalarVariable" else v if v.tag == "Float64" else None
        if holder is None or holder.get("start") is None:
            raise ValueError(f"variable {name!r} has no Real start value to configure")
        holder.set("start", repr(float(values[name])))
        found[name] = True
    missing = sorted(set(values) - set(found))
    if missing:
        raise ValueError(f"no variables {missing} in the modelDescription")
    return ET.tostring(root, encoding="utf-8", xml_declaration=True)


def configured_fmu(fmu, values: dict) -> bytes:
    """The bytes of a copy of ``fmu`` whose modelDescription start values of the variables in
    ``values`` (name -> float) are those values; every other member unchanged."""
    out = io.BytesIO()
    with zipfile.ZipFile(Path(fmu)) as zin, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                data = _set_starts(data, values)
            zout.writestr(item, data)
    return out.getvalue()
