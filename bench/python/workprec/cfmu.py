"""The careful C FMU of the Nonlinear model (bench/c/tld_c.c, issue #29): compiled with gcc -O2
for the benchmark's native runs, which time it through the same host and calls as TLD.fmu, as
it is and with the energies TLD.fmu also integrates (-DTLD_C_ENERGIES: energy.input and
energy.dissipated, two more components of every stage), the same outputs as TLD.fmu's; and as it
is with clang -O2, the LLVM back end rustc compiles TLD.fmu with (the same source through the
other compiler: what of the difference to the gcc build is the back end's)."""
from __future__ import annotations

import subprocess
from pathlib import Path

from tld_fmu.paths import REPO

SOURCE = REPO / "bench" / "c" / "tld_c.c"
OPT = "-O2"
FLAGS = [OPT, "-shared", "-fPIC"]
_built: dict = {}


#: The builds: (implementation name in the report, compiler, extra flags, library file name,
#: the prefix of its run ids).
BUILDS = [("C FMU", "gcc", [], "tld_c.so", "c"),
          ("C FMU, energies", "gcc", ["-DTLD_C_ENERGIES"], "tld_c_energies.so", "cE"),
          ("C FMU, clang", "clang", [], "tld_c_clang.so", "cL")]


def compiled_by(impl: str) -> str:
    """How the build named `impl` in the report is compiled, e.g. "gcc -O2"."""
    return next(f"{cc} {OPT}" for name, cc, _, _, _ in BUILDS if name == impl)


def c_fmu(work: Path, build: int = 0) -> Path:
    """The shared library of the C FMU's build `build` (an index into BUILDS) under `work`,
    compiled once per process."""
    _, cc, extra, name, _ = BUILDS[build]
    if name not in _built:
        out = work / name
        subprocess.run([cc, *FLAGS, *extra, "-o", str(out), str(SOURCE), "-lm"], check=True)
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
