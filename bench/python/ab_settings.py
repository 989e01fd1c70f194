"""The per-step cost of TLD.fmu's settings (issue #29's scene) for two builds of the FMU library
through the same native host (tld-bench), rounds interleaved so that both see the same machine
load, medians reported.

    .venv/bin/python bench/python/ab_settings.py --base PATH.so|REV [--now PATH.so]
                     [--rounds N] [--steps N] [--out FILE]

The scene of issue #29: the Nonlinear model, eta = 2, phi = 1, damping = Constant (zeta = 0.02),
base.a = -w^2 A sin(w t) held over each 1 ms step, w = 1.05 omega_f, A = 3 mm, from rest. Cases:
the defaults (amplitude = Tracked, DormandPrince45 at 1e-10), the same with amplitude = Fixed,
RK4 with one substep (Tracked and Fixed) and with two (Fixed), DormandPrince45 at 1e-12 (tight,
Tracked and Fixed), and the defaults with damping = NSD (where the tracker is read every step).
--base: a built library, or a git revision built as bench/python/ab.py does. --now: default the
working tree's release library (built first). The value references come from
modelDescription/modelDescription.xml. The careful C FMU (bench/c/tld_c.c) runs in the same rounds
as the "now" build: RK4 with one and with two substeps (the same arithmetic and error as
TLD.fmu's) and DormandPrince45 at the same tolerances (not the same error: BENCHMARKS.md compares
the fronts at equal error), in each of the benchmark's builds (workprec/cfmu.py): gcc -O2 as it
is, with -DTLD_C_ENERGIES, where it also integrates energy.input and energy.dissipated as TLD.fmu
must (two more components of each stage), clang -O2 (LLVM, rustc's back end), and its Rust port
(bench/port) both ways.
"""
from __future__ import annotations

import argparse
import datetime
import math
import shutil
import statistics
import subprocess
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ab import build, run
from workprec.cfmu import BUILDS, c_fmu, compiled_by
from tld_fmu.machine import git_info, machine_line
from tld_fmu.paths import REPO
from tld_fmu.scenes import NATIVE_BIN

REPEATS = 5


class Description:
    """Value references and enumeration items of modelDescription.xml."""

    def __init__(self, path: Path):
        root = ET.parse(path).getroot()
        self.guid = root.get("guid")
        self.types = {t.get("name"): {i.get("name"): int(i.get("value"))
                                      for i in t.iter("Item")}
                      for t in root.iter("SimpleType")}
        self.vars = {}
        for v in root.iter("ScalarVariable"):
            kind = next(iter(v))
            self.vars[v.get("name")] = (int(v.get("valueReference")), kind.tag,
                                        kind.get("declaredType"))

    def vr(self, name):
        return self.vars[name][0]

    def token(self, name, value):
        vr, tag, declared = self.vars[name]
        if tag == "Real":
            return f"R:{vr}={float(value)!r}"
        if tag == "Enumeration" and isinstance(value, str):
            value = self.types[declared][value]
        return f"I:{vr}={int(value)}"


def _scene(d: Description) -> list[str]:
    """Issue #29's physics: eta 2, phi 1, Constant damping at zeta 0.02."""
    return [d.token("eta", 2.0), d.token("phi", 1.0), d.token("damping", "Constant"),
            d.token("zeta", 0.02)]


def _rk4(d: Description, step: float) -> list[str]:
    """RK4 with internal steps of at most `step` (1 ms: one substep, 0.5 ms: two)."""
    return [d.token("solver", "RK4"), d.token("solver.fixed_step", step)]


def cases(d: Description):
    """[(name, tokens)]: issue #29's settings."""
    phys = _scene(d)
    fixed = [d.token("amplitude", "Fixed")]
    rk4, rk4_n2 = _rk4(d, 1e-3), _rk4(d, 5e-4)
    tight = [d.token("solver.tolerance", 1e-12)]
    nsd = [d.token("eta", 2.0), d.token("phi", 1.0)]
    return [("defaults", phys), ("defaults_Fixed", phys + fixed),
            ("RK4_n1", phys + rk4), ("RK4_n1_Fixed", phys + rk4 + fixed),
            ("RK4_n2_Fixed", phys + rk4_n2 + fixed),
            ("tight", phys + tight), ("tight_Fixed", phys + tight + fixed),
            ("NSD_defaults", nsd)]


def c_cases(d: Description):
    """[(name, tokens)]: the careful C FMU (bench/c/tld_c.c) on the same scene: RK4 with one
    and with two substeps, DormandPrince45 at TLD.fmu's default tolerance and at the tight
    one."""
    phys = _scene(d)
    return [("C_RK4_n1", phys + _rk4(d, 1e-3)),
            ("C_RK4_n2", phys + _rk4(d, 5e-4)),
            ("C_DP45_1e-10", phys + [d.token("solver.tolerance", 1e-10)]),
            ("C_DP45_1e-12", phys + [d.token("solver.tolerance", 1e-12)])]


def job(d: Description, lib: Path, tmp: Path, steps: int,
        c_libs: list[tuple[str, Path]] | None = None) -> Path:
    wf = math.sqrt(math.pi * 9.81 / 0.25 * math.tanh(math.pi * 0.021 / 0.25))
    w, amp, dt = 1.05 * wf, 0.003, 1e-3
    a = -w * w * amp * np.sin(w * dt * np.arange(steps))
    f = tmp / "input.f64"
    a.astype("<f8").tofile(f)
    lines = [f"lib {lib}", f"guid {d.guid}",
             f"vrs base_a={d.vr('base.a')} x={d.vr('slosh.x')} v={d.vr('slosh.v')} "
             f"force={d.vr('force')} mass_inactive={d.vr('mass.inactive')}",
             f"repeats {REPEATS}", f"outdir {tmp}", f"input {f} {steps}", f"dt {dt!r}",
             # the CPU time of the host's thread: not stretched by the other processes of a
             # shared machine
             "clock cpu"]
    tag = lib.name.replace(".", "_")
    for name, toks in cases(d):
        lines.append(f"run {name} fmu {' '.join(toks)}")
    for prefix, c_lib in c_libs or []:
        lines.append(f"lib {c_lib}")
        for name, toks in c_cases(d):
            lines.append(f"run {prefix}{name} fmu {' '.join(toks)}")
    path = tmp / f"{tag}.job"
    path.write_text("\n".join(lines) + "\n")
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", required=True)
    ap.add_argument("--now", default=None)
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    subprocess.run(["cargo", "build", "--release", "--quiet", "-p", "tld-bench"], cwd=REPO,
                   check=True)
    base = Path(args.base) if args.base.endswith(".so") else build(args.base)
    now = Path(args.now) if args.now else build(None)
    d = Description(REPO / "modelDescription" / "modelDescription.xml")
    tmp = Path(tempfile.mkdtemp(prefix="tld_ab_settings_"))
    (tmp / "base").mkdir()
    (tmp / "now").mkdir()
    # the C FMU's builds, their cases prefixed by their tags less the "c": "" (as it is), "E"
    # (energies), "L" (clang), "R" and "RE" (the Rust port)
    c_libs = [(tag[1:], c_fmu(tmp, k)) for k, (_, _, _, _, tag) in enumerate(BUILDS)]
    # the C FMU runs in the "now" job: timed in the same rounds
    jobs = {"base": job(d, base, tmp / "base", args.steps),
            "now": job(d, now, tmp / "now", args.steps, c_libs)}
    names = [n for n, _ in cases(d)]
    c_names = [p + n for p, _ in c_libs for n, _ in c_cases(d)]
    times = {k: {n: [] for n in names + c_names} for k in jobs}
    for _ in tqdm(range(args.rounds), desc="A/B rounds"):
        for k in jobs:
            for n, t in run(jobs[k]).items():
                times[k][n].append(t)
    times["base"] = {n: v for n, v in times["base"].items() if v}
    # the histories of both builds, bit for bit
    same = {n: (tmp / "base" / f"{n}.x.f64").read_bytes() == (tmp / "now" / f"{n}.x.f64").read_bytes()
            for n in names}
    # the runs' histories (hundreds of MB): compared above, not kept
    shutil.rmtree(tmp, ignore_errors=True)
    uptime = Path("/proc/loadavg").read_text().split()[:3]
    lines = ["# Per-step cost of the settings, two builds", "",
             f"Generated by `bench/python/ab_settings.py`; "
             f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; "
             f"machine {machine_line()}; load average at the end {' '.join(uptime)}; "
             f"now {git_info()}; base {args.base}.", "",
             f"Median over {args.rounds} interleaved rounds of the median of {REPEATS} repeats of "
             f"{args.steps:,} steps, CPU time of the host's thread (fmi2SetReal + fmi2DoStep + fmi2GetReal of 3 outputs).", "",
             "| case | base ns/step | now ns/step | now/base | slosh.x bit-identical |",
             "|---|---|---|---|---|"]
    med = {k: {n: statistics.median(v) for n, v in times[k].items()} for k in jobs}
    for n in names:
        b, w = med["base"][n], med["now"][n]
        lines.append(f"| {n} | {b:.1f} | {w:.1f} | {w / b:.3f} | {'yes' if same[n] else 'NO'} |")
    c = med["now"]
    pairs = [("RK4_n1_Fixed", "C_RK4_n1", "RK4, one substep, the same error"),
             ("RK4_n2_Fixed", "C_RK4_n2", "RK4, two substeps, the same error"),
             ("defaults_Fixed", "C_DP45_1e-10", "DormandPrince45 at 1e-10 (TLD.fmu's default)"),
             ("defaults", "C_DP45_1e-10", "TLD.fmu's defaults (Tracked) against the C FMU's DP45 at 1e-10"),
             ("tight_Fixed", "C_DP45_1e-12", "DormandPrince45 at 1e-12")]
    lines += ["", "The careful C FMU (bench/c/tld_c.c) in the same rounds, each of the benchmark's "
              "builds (bench/python/workprec/cfmu.py: " + "; ".join(
                  f"{name}: {compiled_by(name)}" for name, *_ in BUILDS) + "):", "",
              "| case | TLD.fmu now ns/step | " + " | ".join(
                  f"{name} ns/step | TLD.fmu / it" for name, *_ in BUILDS) + " |",
              "|---|---|" + "---|---|" * len(BUILDS)]
    for a, b, what in pairs:
        lines.append(f"| {what} | {c[a]:.1f} | " + " | ".join(
            f"{c[p + b]:.1f} | {c[a] / c[p + b]:.2f}" for p, _ in c_libs) + " |")
    lines.append("")
    for k in jobs:
        for n in ("defaults", "RK4_n1", "tight"):
            lines.append(f"* {k}: {n} / {n}_Fixed = {med[k][n] / med[k][n + '_Fixed']:.3f}")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        Path(args.out).write_text(text)


if __name__ == "__main__":
    main()
