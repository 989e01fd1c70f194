"""The documentation's host snippets are the files in examples/, and they run (issue #18).

- The README and the documents it links for hosts (docs/USING.md, docs/COUPLING.md: DOCUMENTS)
  show each example verbatim in a fenced block right after a marker line
  `<!-- example: examples/NAME.py -->`; every ```python block carries either such a marker or a
  `<!-- not run: REASON -->` one, and every examples/*.py is shown. So a snippet cannot drift
  from the file the suite runs, and no untested snippet can be added.
- Every example runs as a user would start it (its own Python process, from the repository
  root), shortened to a couple of seconds through its duration argument, and must print the
  numbers of the suite's own run of the scene (fmpy's low-level API, parameters and enumeration
  items by name): this checks the examples' literal parameter values (damping 1 = Constant),
  that all of them run the same scene (the old ecospy snippet had 2 tanks), and their output.
- Without the FMU each example stops with a message naming the path (libcosim alone would die
  with SIGSEGV and no word).
- The integers these documents give for the enumeration items are those of the modelDescription.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

from ecos_unzip import write_standin
from tld_fmu.contract import items
from tld_fmu.paths import REPO

README = REPO / "README.md"
# where the snippets and the enumeration values are shown (the README links them)
DOCUMENTS = [README, REPO / "docs" / "USING.md", REPO / "docs" / "COUPLING.md"]
EXAMPLES = sorted(p.name for p in (REPO / "examples").glob("*.py"))
SECONDS = 2.0            # the duration the suite runs each example for (their default: 60 s)
DT = 0.01                # the examples' scene
W, A = 5.64, 0.005
PARAMS = {"zeta": 0.02, "damping": "Constant"}

_FENCE = re.compile(r"^```python\n(.*?)^```$", re.S | re.M)
_MARK = re.compile(r"<!-- (example|not run): *(.*?) *-->\n\Z")


def readme_blocks(text: str):
    """[(kind, what, code)] for every ```python block of a README text: kind 'example' (what is
    the file's path) or 'not run' (what is the reason), from the marker on the line before the
    block; kind None for an unmarked block."""
    out = []
    for m in _FENCE.finditer(text):
        before = text[:m.start()]
        line = before[before[:-1].rfind("\n") + 1:]   # the line right above the fence
        mark = _MARK.search(line)
        out.append((mark.group(1), mark.group(2), m.group(1)) if mark else (None, None, m.group(1)))
    return out


def drift(text: str) -> list[str]:
    """What is wrong between a README text and examples/: [] when they agree."""
    problems, shown = [], set()
    for kind, what, code in readme_blocks(text):
        if kind is None:
            problems.append(f"a python block without marker: {code.splitlines()[0]!r}")
        elif kind == "not run":
            if not what:
                problems.append("a `not run` marker without a reason")
        else:
            path = REPO / what
            shown.add(path.name)
            if path.parent != REPO / "examples" or not path.is_file():
                problems.append(f"{what}: no such example file")
            elif code != path.read_text():
                problems.append(f"{what}: the README's block differs from the file")
    problems += [f"examples/{name} is not shown in the README" for name in EXAMPLES if name not in shown]
    return problems


def documents_text() -> str:
    """The DOCUMENTS, one after the other (each ends with a newline)."""
    return "".join(p.read_text() for p in DOCUMENTS)


def test_readme_links_the_documents_with_the_snippets():
    readme = README.read_text()
    for p in DOCUMENTS[1:]:
        assert f"(docs/{p.name})" in readme and p.is_file(), p


def test_readme_blocks_are_the_example_files():
    text = documents_text()
    assert len(EXAMPLES) >= 3
    assert drift(text) == []


def test_drift_is_detected():
    """The check can fail: an edited block, an unmarked block, a missing example."""
    text = documents_text()
    edited = text.replace('"zeta": 0.02', '"zeta": 0.03', 1)
    assert edited != text
    assert any("differs" in p for p in drift(edited))
    assert any("without marker" in p for p in drift(text + "\n```python\nprint(1)\n```\n"))
    first = f"<!-- example: examples/{EXAMPLES[0]} -->"
    assert any("not shown" in p for p in drift(text.replace(first, "<!-- not run: gone -->")))


@pytest.fixture(scope="module")
def reference(model_description, unzipdir, variables):
    """The scene through the suite's own fmpy host: held base.a, parameters by name."""
    from tld_fmu.slave import Slave
    n = round(SECONDS / DT)
    s = Slave(model_description, unzipdir, variables, quiet=True)
    try:
        s.initialize(dict(PARAMS))
        res = s.run(DT, {"base.a": -W**2 * A * np.sin(W * np.arange(n) * DT)}, ["slosh.x", "force"])
    finally:
        s.close()
    x, f = res["slosh.x"][1:], res["force"][1:]
    return {"steps": n, "x": np.max(np.abs(x)), "f": np.max(np.abs(f)), "fT": f[-1]}


_PRINTED = re.compile(r"(\d+) steps, max\|slosh\.x\| = (\S+) m, max\|force\| = (\S+) N, "
                      r"force\(T\) = (\S+) N")


def run_example(name, env_update, *args, tmp_path=None):
    env = {**os.environ, **env_update}
    if name.startswith("ecospy") and not shutil.which("unzip", path=env.get("PATH")):
        write_standin(tmp_path)
        env["PATH"] = f"{tmp_path}{os.pathsep}{env.get('PATH', '')}"
    return subprocess.run([sys.executable, f"examples/{name}", *args], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_runs_the_scene(name, fmu_path, reference, tmp_path):
    r = run_example(name, {"TLD_FMU_PATH": str(fmu_path)}, str(SECONDS), tmp_path=tmp_path)
    assert r.returncode == 0, f"examples/{name} failed ({r.returncode}):\n{r.stdout}\n{r.stderr}"
    m = _PRINTED.search(r.stdout)
    assert m, f"examples/{name} printed no result:\n{r.stdout}"
    steps, x, f, fT = int(m.group(1)), *map(float, m.groups()[1:])
    print(f"\n{r.stdout.strip()}")
    assert steps == reference["steps"]
    assert reference["x"] > 1e-3          # the scene does move the liquid
    for got, want in ((x, reference["x"]), (f, reference["f"]), (fT, reference["fT"])):
        assert got == pytest.approx(want, rel=1e-8, abs=1e-9 * reference["f"]), (name, m.group(0))
    assert "TRACE" not in r.stdout + r.stderr     # libcosim's log level is lowered


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_without_the_fmu_says_where_it_looked(name, tmp_path):
    missing = tmp_path / "nowhere" / "TLD.fmu"
    r = run_example(name, {"TLD_FMU_PATH": str(missing)}, "0.1", tmp_path=tmp_path)
    assert r.returncode == 1, (r.returncode, r.stderr)
    assert f"{missing} not found" in r.stderr and "scripts/package" in r.stderr


def readme_enumeration_values(text: str):
    """{(variable, item): value} for every "`name` 1 = Item, 2 = Item" list in the README."""
    out = {}
    for m in re.finditer(r"`(\w+)`\s+((?:\d+ = \w+(?:,\s*)?)+)", text):
        for value, item in re.findall(r"(\d+) = (\w+)", m.group(2)):
            out[(m.group(1), item)] = int(value)
    return out


def test_readme_enumeration_values_are_the_model_descriptions():
    stated = readme_enumeration_values(documents_text())
    assert {v for v, _ in stated} >= {"damping", "amplitude", "solver"}
    for (variable, item), value in stated.items():
        actual = {n: v for n, v, _ in items(variable)}
        assert actual.get(item) == value, f"README: `{variable}` {value} = {item}; the XML: {actual}"
    # the check can fail
    assert readme_enumeration_values("`damping` 2 = Constant")[("damping", "Constant")] != \
        {n: v for n, v, _ in items("damping")}["Constant"]
