"""The model documentation a user gets with the repository (issue #18): docs/MODEL.md describes
every variable of the FMU with its unit, and nothing user-facing points outside the repository
(to the specification it was written from)."""
from __future__ import annotations

import re
import subprocess

from tld_fmu.contract import default
from tld_fmu.paths import REPO

MODEL_MD = REPO / "docs" / "MODEL.md"


def variable_table(text: str) -> dict[str, str]:
    """{variable: unit} from the rows "| `name` | unit | meaning |" of a Markdown text."""
    return {m.group(1): m.group(2) for m in re.finditer(r"^\| `([\w.()\[\]]+)` \| ([^|]+?) \|", text, re.M)}


def xml_unit(v) -> str:
    unit = getattr(v, "unit", None) or (v.declaredType.unit if v.declaredType is not None else None)
    return "-" if unit in (None, "", "1") else unit


def test_model_md_describes_every_variable_with_its_unit():
    table = variable_table(MODEL_MD.read_text())
    variables = default().variables
    assert set(table) == set(variables), (
        f"missing from docs/MODEL.md: {sorted(set(variables) - set(table))}; "
        f"not in the modelDescription: {sorted(set(table) - set(variables))}")
    wrong = {n: (table[n], xml_unit(v)) for n, v in variables.items() if table[n] != xml_unit(v)}
    assert not wrong, f"docs/MODEL.md unit vs modelDescription unit: {wrong}"
    # the check can fail
    assert variable_table("| `force` | kN | force |") == {"force": "kN"}


def test_readme_links_the_model_documentation():
    readme = (REPO / "README.md").read_text()
    assert "(docs/MODEL.md)" in readme and MODEL_MD.is_file()


def test_nothing_points_outside_the_repository():
    """A user has only the repository: no pointer to ../shared/spec or the like in any file."""
    files = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard"],
                           cwd=REPO, capture_output=True, text=True, check=True).stdout.split()
    bad = re.compile(r"shared/spec|shared/seed|\.\./shared")
    hits = []
    for name in files:
        path = REPO / name
        if name == "tests/python/test_docs.py" or not path.is_file():
            continue
        try:
            text = path.read_text()
        except UnicodeDecodeError:
            continue
        hits += [f"{name}:{i}" for i, line in enumerate(text.splitlines(), 1) if bad.search(line)]
    assert not hits, f"pointers outside the repository: {hits}"
