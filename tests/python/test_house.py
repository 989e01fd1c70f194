"""The shape of the source tree (docs/ARCHITECTURE.md): no source file over 600 lines, and no
import cycle between the Rust source files (data flows one way: fmi -> model -> physics,
solver). Read from the files themselves, so a change that breaks either fails here."""
import re
import subprocess
from pathlib import Path

from tld_fmu.paths import REPO

LIMIT = 600
SOURCE = re.compile(r"\.(rs|py|c|h)$")


def tracked_files():
    out = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True,
                         check=True).stdout
    return [REPO / line for line in out.splitlines()]


def test_no_source_file_is_over_600_lines():
    long = {str(p.relative_to(REPO)): n for p in tracked_files()
            if SOURCE.search(p.name) and p.is_file()
            and (n := len(p.read_text(errors="replace").splitlines())) > LIMIT}
    assert not long, f"split these along their seams: {long}"


def module_of(path: Path, src: Path) -> tuple[str, ...]:
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib"):
        parts = parts[:-1]
    return tuple(parts)


def use_targets(text: str, here: tuple[str, ...], modules: dict) -> set:
    """The source files that the `use crate::/super::/self::` items of `text` name."""
    text = re.split(r"#\[cfg\(test\)\]\s*mod tests", text)[0]
    found = set()

    def resolve(path: str):
        segs = path.split("::")
        if segs[0] == "crate":
            base, segs = [], segs[1:]
        elif segs[0] == "super":
            base = list(here)
            while segs and segs[0] == "super":
                base, segs = base[:-1], segs[1:]
        elif segs[0] == "self":
            base, segs = list(here), segs[1:]
        else:
            return None
        full = base + segs
        for k in range(len(full), 0, -1):
            if tuple(full[:k]) in modules:
                return modules[tuple(full[:k])]
        return None

    for m in re.finditer(r"\buse\s+((?:crate|super|self)(?:::\w+)*)(?:::\{([^}]*)\})?", text):
        heads = [m.group(1)]
        if m.group(2):
            heads += [m.group(1) + "::" + item.strip().split("::")[0].split(" ")[0]
                      for item in m.group(2).split(",") if item.strip()]
        for h in heads:
            target = resolve(h)
            if target is not None:
                found.add(target)
    return found


def import_cycles(src: Path):
    files = sorted(src.rglob("*.rs"))
    modules = {module_of(p, src): p for p in files}
    graph = {p: use_targets(p.read_text(), module_of(p, src), modules) - {p} for p in files}
    # Tarjan's strongly connected components; any with two or more files is a cycle.
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(str(p.relative_to(src)) for p in comp))

    for v in files:
        if v not in index:
            visit(v)
    return cycles


def test_no_import_cycles_between_rust_source_files():
    assert import_cycles(REPO / "src") == []


def test_the_cycle_check_finds_a_cycle(tmp_path):
    # The check itself can fail: two files that use each other.
    src = tmp_path / "src"
    (src / "a").mkdir(parents=True)
    (src / "lib.rs").write_text("pub mod a;\n")
    (src / "a" / "mod.rs").write_text("mod x;\nmod y;\n")
    (src / "a" / "x.rs").write_text("use super::y::Thing;\npub struct Other;\n")
    (src / "a" / "y.rs").write_text("use super::x::Other;\npub struct Thing;\n")
    assert import_cycles(src) == [["a/x.rs", "a/y.rs"]]
