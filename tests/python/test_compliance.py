"""FMI 2.0 compliance of the packed TLD.fmu and Building.fmu (each test runs on both), by checkers independent of fmpy.validate_fmu (which
has its own test in test_interface.py):

- the modelDescription.xml packed inside TLD.fmu (not the source copy) against the FMI 2.0 XML
  schema that fmpy ships (fmpy/schema/fmi2/*.xsd), validated with lxml;
- fmu-manipulation-toolbox's checker (`fmutool -input X.fmu -check`, i.e. its
  "FMU Generic Conformity Checks", an XSD validation with xmlschema, and its
  "FMU Semantic Checks": causality/variability/initial/start combinations, unique names,
  ModelStructure indices, dependencies and <Outputs> against the output variables).

Each checker is also run on a deliberately broken copy, which it must reject, so a checker that
silently accepts everything (wrong schema path, swallowed errors) cannot make these tests pass.
"""
from __future__ import annotations

import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from lxml import etree as lxml_etree   # scripts/requirements.txt; a missing package fails, never skips

MD_NAME = "modelDescription.xml"
ANSI = re.compile(r"\x1b\[[0-9;]*m")


# -- helpers -----------------------------------------------------------------------------------------
def packed_model_description(fmu_path: Path) -> bytes:
    """The modelDescription.xml as packed inside the FMU."""
    with zipfile.ZipFile(fmu_path) as z:
        return z.read(MD_NAME)


def schema_errors(schema, xml: bytes) -> list[str]:
    """All violations of `schema` in the document `xml`, one readable line each."""
    doc = lxml_etree.fromstring(xml)
    if schema.validate(doc):
        return []
    return [f"line {e.line}: {e.message}" for e in schema.error_log]


def serialize(root) -> bytes:
    return lxml_etree.tostring(root, xml_declaration=True, encoding="UTF-8")


def break_unknown_attribute(xml: bytes) -> bytes:
    root = lxml_etree.fromstring(xml)
    root.set("notAnFmiAttribute", "1")
    return serialize(root)


def break_missing_guid(xml: bytes) -> bytes:
    root = lxml_etree.fromstring(xml)
    del root.attrib["guid"]
    return serialize(root)


def break_missing_value_reference(xml: bytes) -> bytes:
    root = lxml_etree.fromstring(xml)
    sv = root.find("ModelVariables/ScalarVariable")
    del sv.attrib["valueReference"]
    return serialize(root)


def break_unlist_first_output(xml: bytes) -> tuple[bytes, str]:
    """Drop the first <Outputs> entry: a semantic error no XSD can see. Returns (xml, name)."""
    root = lxml_etree.fromstring(xml)
    outputs = root.find("ModelStructure/Outputs")
    first = outputs.find("Unknown")
    name = root.findall("ModelVariables/ScalarVariable")[int(first.get("index")) - 1].get("name")
    outputs.remove(first)
    return serialize(root), name


def repack(fmu_path: Path, out: Path, xml: bytes) -> Path:
    """A copy of the FMU with its modelDescription.xml replaced by `xml`."""
    with zipfile.ZipFile(fmu_path) as zin, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in zin.infolist():
            zout.writestr(info, xml if info.filename == MD_NAME else zin.read(info.filename))
    return out


def run_fmutool_check(fmu: Path) -> tuple[int, str]:
    """fmu-manipulation-toolbox's command line checker; returns (exit code, output)."""
    proc = subprocess.run(
        [sys.executable, "-m", "fmu_manipulation_toolbox", "-input", str(fmu), "-check"],
        capture_output=True, text=True, timeout=120)
    return proc.returncode, ANSI.sub("", proc.stdout + proc.stderr)


# -- the FMI 2.0 XML schema (as shipped by fmpy), with lxml -----------------------------------------
@pytest.fixture(scope="module")
def fmi2_schema():
    import fmpy
    xsd = Path(fmpy.__file__).parent / "schema" / "fmi2" / "fmi2ModelDescription.xsd"
    assert xsd.is_file(), f"fmpy does not ship the FMI 2.0 schema at {xsd}"
    return lxml_etree.XMLSchema(lxml_etree.parse(str(xsd)))


def test_packed_model_description_passes_fmi2_schema(any_fmu, fmi2_schema):
    errors = schema_errors(fmi2_schema, packed_model_description(any_fmu))
    print(f"FMI 2.0 XSD (lxml) on {any_fmu}!/{MD_NAME}: "
          + ("no errors" if not errors else f"{len(errors)} error(s)"))
    for e in errors:
        print("  " + e)
    assert errors == [], "modelDescription.xml violates the FMI 2.0 schema:\n" + "\n".join(errors)


@pytest.mark.parametrize("breakage, expected", [
    (break_unknown_attribute, "attribute 'notAnFmiAttribute'"),
    (break_missing_guid, "attribute 'guid' is required"),
    (break_missing_value_reference, "attribute 'valueReference' is required"),
], ids=["unknown-attribute", "missing-guid", "missing-valueReference"])
def test_fmi2_schema_rejects_broken_copies(any_fmu, fmi2_schema, breakage, expected):
    """The validator above is really active: the same schema rejects a broken copy."""
    good = packed_model_description(any_fmu)
    errors = schema_errors(fmi2_schema, breakage(good))
    print("\n".join(errors))
    assert errors, f"{breakage.__name__}: the schema accepted a broken modelDescription.xml"
    assert any(expected in e for e in errors), f"{breakage.__name__}: expected '{expected}' in {errors}"


# -- fmu-manipulation-toolbox's checker ------------------------------------------------------------
def test_fmu_manipulation_toolbox_check(any_fmu):
    code, out = run_fmutool_check(any_fmu)
    print(out)
    errors = [line for line in out.splitlines() if line.startswith(("ERROR", "CRITICAL", "WARNING"))]
    assert code == 0 and not errors, (
        f"fmutool -check exit code {code}; it reported:\n" + "\n".join(errors or out.splitlines()))
    # both checkers ran and said so (not just an empty run)
    assert "This FMU seems to be compliant with FMI-2.0." in out, out
    assert "No semantic error against the FMI-2 standard." in out, out


def test_fmu_manipulation_toolbox_check_rejects_broken_fmu(any_fmu, tmp_path):
    """The checker is really active: a copy with a schema error and a semantic error fails."""
    xml, unlisted = break_unlist_first_output(packed_model_description(any_fmu))
    xml = break_unknown_attribute(xml)
    code, out = run_fmutool_check(repack(any_fmu, tmp_path / "broken.fmu", xml))
    print(out)
    assert code == 7, f"fmutool -check should exit with CHECK_FAILED (7), got {code}:\n{out}"
    assert "notAnFmiAttribute" in out, out                          # the XSD check
    assert "This FMU does not validate with FMI standard." in out, out
    assert f"Output '{unlisted}' is not listed in <Outputs>" in out, out   # the semantic check
