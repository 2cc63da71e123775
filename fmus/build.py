"""Build the FMUs with pythonfmu and fix their modelDescription.

pythonfmu 0.7 writes outputs without ``dependencies``, no ``InitialUnknowns`` and no
units. The fix-up rewrites ``modelDescription.xml`` from the block's own declaration:
units (with ``UnitDefinitions``), exact output dependencies from the block's
``feedthrough``, a complete ``InitialUnknowns`` list, and the co-simulation
capabilities (no execution tool, get/set and serialise state).
"""
from __future__ import annotations

import shutil
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from .catalog import CATALOG, block_class, slave_script
from .runtime import generation_tool, write_runtime_files

ROOT = Path(__file__).resolve().parent.parent
EMBEDDED_PACKAGES = ("plant", "estimator", "controller", "papers")

# SI base-unit exponents (and factor) of every unit string the blocks use.
UNITS = {
    "1": {},
    "s": {"s": 1},
    "rad": {"rad": 1},
    "deg": {"rad": 1, "factor": 0.017453292519943295},
    "rad/s": {"rad": 1, "s": -1},
    "rad/s2": {"rad": 1, "s": -2},
    "1/s": {"s": -1},
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "N.m.s": {"kg": 1, "m": 2, "s": -1},
    "kg.m2": {"kg": 1, "m": 2},
}

CAPABILITIES = dict(
    needsExecutionTool="false",
    canHandleVariableCommunicationStepSize="true",
    canGetAndSetFMUstate="true",
    canSerializeFMUstate="true",
)


def _stage_project_files(tmp: Path, fmus_files=("__init__.py", "block_runtime.py", "adapter.py")) -> list[Path]:
    """Copy the packages an FMU needs (without caches) into ``tmp``; of ``fmus/`` only
    ``fmus_files`` (the adapter of the FMI version being built)."""
    files = []
    for name in EMBEDDED_PACKAGES:
        dst = tmp / name
        shutil.copytree(ROOT / name, dst, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        files.append(dst)
    fm = tmp / "fmus"
    fm.mkdir()
    for f in fmus_files:
        shutil.copy2(ROOT / "fmus" / f, fm / f)
    files.append(fm)
    return files


def fix_model_description(xml_text: bytes, block) -> bytes:
    """Return the corrected modelDescription for ``block``'s FMU."""
    root = ET.fromstring(xml_text)
    root.set("description", block.description)
    root.set("generationTool", generation_tool(root.get("generationTool")))  # records the Python version
    cosim = root.find("CoSimulation")
    for k, v in CAPABILITIES.items():
        cosim.set(k, v)

    variables = block.inputs + block.outputs + block.parameters
    unit_of = {v.name: v.unit for v in variables}
    used = sorted({v.unit for v in variables})
    unknown = [u for u in used if u not in UNITS]
    if unknown:
        raise ValueError(f"{block.model_name}: units without a definition: {unknown}")
    units = ET.Element("UnitDefinitions")
    for u in used:
        spec = dict(UNITS[u])
        unit = ET.SubElement(units, "Unit", name=u)
        ET.SubElement(unit, "BaseUnit", {k: repr(float(x)) if k == "factor" else str(x) for k, x in spec.items()})
    for old in root.findall("UnitDefinitions"):
        root.remove(old)
    root.insert(list(root).index(cosim) + 1, units)

    index = {}
    for i, sv in enumerate(root.find("ModelVariables").findall("ScalarVariable"), start=1):
        name = sv.get("name")
        index[name] = i
        real = sv.find("Real")
        if real is not None and unit_of.get(name, "1") != "1":
            real.set("unit", unit_of[name])

    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    outputs = ET.SubElement(structure, "Outputs")
    initial = ET.SubElement(structure, "InitialUnknowns")
    param_idx = [index[p.name] for p in block.parameters]
    for v in block.outputs:
        deps = sorted(index[i] for i in block.feedthrough.get(v.name, ()))
        ET.SubElement(outputs, "Unknown", index=str(index[v.name]), dependencies=" ".join(map(str, deps)))
        init_deps = sorted(set(deps) | set(param_idx))
        ET.SubElement(initial, "Unknown", index=str(index[v.name]), dependencies=" ".join(map(str, init_deps)))
    ET.indent(root)
    return ET.tostring(root, encoding="utf-8", xml_declaration=True)


def _rewrite_member(fmu: Path, member: str, data: bytes) -> None:
    tmp = fmu.with_suffix(".tmp")
    with zipfile.ZipFile(fmu) as zin, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            zout.writestr(item, data if item.filename == member else zin.read(item.filename))
    tmp.replace(fmu)


def build_fmu(model_name: str, out_dir: Path) -> Path:
    """Build one FMU into ``out_dir`` and fix its modelDescription; returns its path."""
    from pythonfmu import FmuBuilder

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    block = block_class(model_name)()
    with tempfile.TemporaryDirectory(prefix="ftcsim_build_") as tmp:
        files = _stage_project_files(Path(tmp))
        # resources/requirements.txt (pythonfmu's convention) and resources/ftcsim_build.json
        block_module = CATALOG[model_name][0].split(":")[0]
        files += write_runtime_files(Path(tmp), model_name, block_module, "2.0", "pythonfmu")
        staging = Path(tmp) / "out"
        fmu = FmuBuilder.build_FMU(
            slave_script(model_name), dest=staging, project_files=files, **CAPABILITIES
        )
        with zipfile.ZipFile(fmu) as z:
            xml = z.read("modelDescription.xml")
        _rewrite_member(fmu, "modelDescription.xml", fix_model_description(xml, block))
        final = out_dir / f"{model_name}.fmu"
        shutil.move(str(fmu), final)
    return final


def build_all(out_dir: Path, names=None) -> list[Path]:
    names = list(CATALOG) if not names else names
    return [build_fmu(n, out_dir) for n in names]


def validate(fmu: Path) -> list[str]:
    """Problems reported by ``fmpy.validate_fmu`` (empty list: valid)."""
    from fmpy.validation import validate_fmu

    return list(validate_fmu(str(fmu)))


if __name__ == "__main__":  # pragma: no cover
    for p in build_all(Path(sys.argv[1] if len(sys.argv) > 1 else "build/fmus")):
        print(p, validate(p))
