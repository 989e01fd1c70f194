"""What a generated report says of where it ran: the machine and the repository's revision
(docs/BENCHMARKS.md, docs/bench/ab.md, docs/CALIBRATION.md)."""
from __future__ import annotations

import os
import platform
import subprocess

from .paths import REPO


def machine_info() -> dict:
    model = cores = "?"
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        for line in out.splitlines():
            k, _, v = line.partition(":")
            if k.strip() == "Model name":
                model = v.strip()
            if k.strip() == "CPU(s)":
                cores = v.strip()
    except OSError:
        pass
    mem = "?"
    try:
        for line in open("/proc/meminfo"):
            if line.startswith("MemTotal"):
                mem = f"{int(line.split()[1]) / 1024 / 1024:.1f} GiB"
    except OSError:
        pass
    return dict(cpu=model, cores=cores, mem=mem, python=platform.python_version(),
                kernel=platform.release(), openblas=os.environ.get("OPENBLAS_CORETYPE", "unset"))


def machine_line() -> str:
    """The machine as one table cell."""
    mi = machine_info()
    return (f"{mi['cpu']}, {mi['cores']} cores, {mi['mem']} RAM, Linux {mi['kernel']}, "
            f"Python {mi['python']}, OPENBLAS_CORETYPE={mi['openblas']}")


def git_info() -> str:
    """The short HEAD, and whether the sources the FMU is built from have uncommitted changes."""
    try:
        head = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain", "--", "src",
                                "Cargo.toml", "modelDescription", "build", "tools"],
                               capture_output=True, text=True).stdout.strip()
        return head + (" + uncommitted changes in src/Cargo.toml/modelDescription" if dirty else "")
    except OSError:
        return "?"
