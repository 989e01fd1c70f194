"""The careful C FMU of the Nonlinear model (bench/c/tld_c.c, issue #29): compiled with gcc -O2
for the benchmark's native runs, which time it through the same host and calls as TLD.fmu, as
it is and with the energies TLD.fmu also integrates (-DTLD_C_ENERGIES: energy.input and
energy.dissipated, two more components of every stage), the same outputs as TLD.fmu's."""
from __future__ import annotations

import subprocess
from pathlib import Path

from tld_fmu.paths import REPO

SOURCE = REPO / "bench" / "c" / "tld_c.c"
FLAGS = ["-O2", "-shared", "-fPIC"]
_built: dict = {}


#: The two builds: (implementation name in the report, extra gcc flags, library file name).
BUILDS = [("C FMU", [], "tld_c.so"),
          ("C FMU, energies", ["-DTLD_C_ENERGIES"], "tld_c_energies.so")]


def c_fmu(work: Path, energies: bool = False) -> Path:
    """The C FMU's shared library under `work` (with the energies if `energies`), compiled once
    per process."""
    _, extra, name = BUILDS[int(energies)]
    if name not in _built:
        out = work / name
        subprocess.run(["gcc", *FLAGS, *extra, "-o", str(out), str(SOURCE), "-lm"], check=True)
        _built[name] = out
    return _built[name]


def c_tokens(fi, p):
    """The C FMU's parameter tokens for the scene's physics p: TLD.fmu's value references; the
    damping as the constant zeta the scene's law gives (the C FMU models damping = Constant
    only)."""
    params = fi.physics_params(p)
    params["damping"] = fi.enum_value("damping", "Constant")
    params["zeta"] = p.zeta_fixed
    return [fi.token(k, v) for k, v in params.items()]
