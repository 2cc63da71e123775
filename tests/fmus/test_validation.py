"""fmus.validation.validate_fmu gives fmpy.validate_fmu's verdict: on every catalog FMU, on
modelDescriptions with names inside and outside the fast regex, and on names drawn at random."""
import shutil
import zipfile

import pytest
from fmpy.validation import validate_fmu as fmpy_validate_fmu
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fmus.validation import PLAIN_STRUCTURED_NAME, validate_fmu

XML = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="m" guid="{{00000000-0000-0000-0000-000000000000}}"
  variableNamingConvention="structured" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="m"/>
  <ModelVariables>
{variables}
  </ModelVariables>
  <ModelStructure>
    <Outputs>
{outputs}
    </Outputs>
  </ModelStructure>
</fmiModelDescription>
"""


def _xml(folder, names):
    """An extracted FMU folder whose outputs are ``names``."""
    from xml.sax.saxutils import quoteattr

    variables = "\n".join(f'    <ScalarVariable name={quoteattr(n)} valueReference="{i}" causality="output" '
                          f'variability="continuous" initial="exact"><Real start="0"/></ScalarVariable>'
                          for i, n in enumerate(names))
    outputs = "\n".join(f'      <Unknown index="{i + 1}"/>' for i in range(len(names)))
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    (folder / "modelDescription.xml").write_text(XML.format(variables=variables, outputs=outputs), encoding="utf-8")
    return folder


def test_every_catalog_fmu_is_valid_by_both(any_fmu_dir):
    _, folder = any_fmu_dir
    fmus = sorted(folder.glob("*.fmu"))
    assert len(fmus) > 20
    for f in fmus:
        assert validate_fmu(f) == [], f.name
    for f in fmus[:3]:  # fmpy's own (0.6 s each): the same verdict
        assert fmpy_validate_fmu(str(f)) == [], f.name


@pytest.mark.parametrize(("names", "valid"), [
    (["omega[1]", "theta_hat", "wheel.tau[2]", "a.b.c"], True),  # the fast path
    (["1omega"], False),  # not a name: refused by fmpy's grammar (full check)
    (["der(x)"], True),  # valid, outside the regex: the full check
    (["'quoted name'"], True),  # valid q-name: the full check
    (["a..b"], False),  # invalid
    (["x[]"], False),  # invalid
    (["x", "x"], False),  # duplicate: refused by the model description checks on the fast path too
])
def test_same_verdict_as_fmpy(tmp_path, names, valid):
    folder = _xml(tmp_path / "fmu", names)
    problems = validate_fmu(folder)
    assert problems == fmpy_validate_fmu(str(folder)), names
    assert (problems == []) == valid, problems


def test_a_bad_name_in_an_fmu_archive_is_reported(fmu_dir, tmp_path):
    src = fmu_dir / "PDController.fmu"
    bad = tmp_path / "PDController.fmu"
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(bad, "w", zipfile.ZIP_DEFLATED) as zout:
        for i in zin.infolist():
            data = zin.read(i.filename)
            if i.filename == "modelDescription.xml":
                text = data.decode("utf-8")
                first = text.index('name="', text.index("<ModelVariables>")) + len('name="')
                data = (text[:first] + "9" + text[first:]).encode("utf-8")  # a name starting with a digit
            zout.writestr(i, data)
    problems = validate_fmu(bad)
    assert problems and problems == fmpy_validate_fmu(str(bad))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.from_regex(PLAIN_STRUCTURED_NAME, fullmatch=True))
def test_the_regex_accepts_only_names_fmpy_accepts(tmp_path, name):
    folder = _xml(tmp_path / "fmu", [name])
    assert fmpy_validate_fmu(str(folder)) == [], name
