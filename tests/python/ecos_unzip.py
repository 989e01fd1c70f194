"""Ecos unpacks an .fmu by running the system `unzip` and crashes (SIGSEGV) without one on PATH.
On a machine without Debian's unzip package, tests put this small Python stand-in (same
arguments, zipfile) first on PATH: test_hosts_ecospy.py for its runs, test_examples.py for
examples/ecospy_scene.py."""
from __future__ import annotations

import stat
import sys
from pathlib import Path

UNZIP_STANDIN = '''#!{python}
"""Stand-in for `unzip -o ZIP -d DIR` (all Ecos runs), written by tests/python/ecos_unzip.py."""
import sys, zipfile
args, dest, files = sys.argv[1:], ".", []
i = 0
while i < len(args):
    if args[i] == "-d":
        dest = args[i + 1]; i += 2
    elif args[i].startswith("-"):
        i += 1
    else:
        files.append(args[i]); i += 1
with zipfile.ZipFile(files[0]) as z:
    z.extractall(dest)
'''


def write_standin(directory: Path) -> Path:
    """Write an executable `unzip` stand-in into `directory`; put that directory on PATH."""
    exe = Path(directory) / "unzip"
    exe.write_text(UNZIP_STANDIN.format(python=sys.executable))
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return exe
