"""The careful C FMU of the Nonlinear model (bench/c/tld_c.c, issue #29): compiled with gcc -O2
for the benchmark's native runs, which time it through the same host and calls as TLD.fmu, as
it is and with the energies TLD.fmu also integrates (-DTLD_C_ENERGIES: energy.input and
energy.dissipated, two more components of every stage), the same outputs as TLD.fmu's; as it is
with clang -O2, the LLVM back end rustc compiles TLD.fmu with (the same source through the other
compiler); and its Rust port (bench/port: the same program statement by statement, the same bits,
tests/python/test_c_port.py) built by cargo with the workspace's release profile, TLD.fmu's own,
as it is and with the energies: what rustc makes of the C FMU's program."""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

from tld_fmu.paths import REPO

SOURCE = REPO / "bench" / "c" / "tld_c.c"
OPT = "-O2"
FLAGS = [OPT, "-shared", "-fPIC"]
_built: dict = {}


PORT = "tld-c-port"   # bench/port's package
#: The builds: (implementation name in the report, compiler ("cargo": the Rust port), extra
#: flags, library file name, the prefix of its run ids).
BUILDS = [("C FMU", "gcc", [], "tld_c.so", "c"),
          ("C FMU, energies", "gcc", ["-DTLD_C_ENERGIES"], "tld_c_energies.so", "cE"),
          ("C FMU, clang", "clang", [], "tld_c_clang.so", "cL"),
          ("C FMU, Rust port", "cargo", [], "tld_c_port.so", "cR"),
          ("C FMU, Rust port, energies", "cargo", ["--features", "energies"],
           "tld_c_port_energies.so", "cRE")]


def _compiler(impl: str) -> str:
    """The compiler of the build named `impl` in the report (BUILDS' second field)."""
    return next(cc for name, cc, _, _, _ in BUILDS if name == impl)


def compiled_by(impl: str) -> str:
    """How the build named `impl` in the report is compiled, e.g. "gcc -O2"."""
    cc = _compiler(impl)
    return ("rustc, the workspace's release profile (opt-level 3, fat LTO, TLD.fmu's own)"
            if cc == "cargo" else f"{cc} {OPT}")


def source_of(impl: str) -> str:
    """The source file of the build named `impl`, as the report names it."""
    return "bench/port" if _compiler(impl) == "cargo" else "bench/c/tld_c.c"


def c_fmu(work: Path, build: int = 0) -> Path:
    """The shared library of the C FMU's build `build` (an index into BUILDS) under `work`,
    compiled once per process."""
    _, cc, extra, name, _ = BUILDS[build]
    if name not in _built:
        out = work / name
        if cc == "cargo":
            # its own target directory: the features of one build never overwrite the other's
            target = work / f"cargo-{name}"
            env = {**os.environ, "CARGO_TARGET_DIR": str(target)}
            subprocess.run(["cargo", "build", "--release", "--quiet", "-p", PORT, *extra],
                           check=True, cwd=REPO, env=env)
            shutil.copyfile(target / "release" / "libtld_c_port.so", out)
        else:
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
