"""The careful C FMU of the Nonlinear model (bench/c/tld_c.c, issue #29): compiled with gcc -O2
for the benchmark's native runs, which time it through the same host and calls as TLD.fmu."""
from __future__ import annotations

import subprocess
from pathlib import Path

from tld_fmu.paths import REPO

SOURCE = REPO / "bench" / "c" / "tld_c.c"
FLAGS = ["-O2", "-shared", "-fPIC"]
_built: dict = {}


def c_fmu(work: Path) -> Path:
    """The C FMU's shared library under `work`, compiled once per process."""
    if "lib" not in _built:
        out = work / "tld_c.so"
        subprocess.run(["gcc", *FLAGS, "-o", str(out), str(SOURCE), "-lm"], check=True)
        _built["lib"] = out
    return _built["lib"]


def c_tokens(fi, p):
    """The C FMU's parameter tokens for the scene's physics p: TLD.fmu's value references; the
    damping as the constant zeta the scene's law gives (the C FMU models damping = Constant
    only)."""
    params = fi.physics_params(p)
    params["damping"] = fi.enum_value("damping", "Constant")
    params["zeta"] = p.zeta_fixed
    return [fi.token(k, v) for k, v in params.items()]
