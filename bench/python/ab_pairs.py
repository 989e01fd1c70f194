"""Paired timing of two cases of issue #29's scene (ab_settings.py's cases and the C FMU's), for
one or more builds of the FMU library: each round runs, for every build, the two cases back to
back (3 repeats of STEPS steps, CPU time of the host's thread), and the report gives the median
time of each and the median of the per-round ratios, first / second, and between the builds'
same cases, later / first build. On a loaded shared machine the ratio of two medians taken apart
moves by a few per cent between runs; the ratios of neighbours in time move far less.
With --c C.so:CASE each round also runs the C FMU's CASE (a C build of bench/c/tld_c.c) after
the builds, and every build's cases are given against it, paired within the round.

    .venv/bin/python bench/python/ab_pairs.py --cases RK4_n1,RK4_n1_Fixed [--rounds 150]
                     [--steps 30000] [--c C.so:C_RK4_n1] LIB.so [LIB.so ...]

Prints the figures (nothing is written): docs/ARCHITECTURE.md quotes them with the command.
The native host (tld-bench) must be built (`cargo build --release -p tld-bench`).
"""
from __future__ import annotations

import argparse
import math
import shutil
import statistics
import tempfile
from pathlib import Path

import numpy as np

from ab import run
from ab_settings import Description, c_cases, cases
from tld_fmu.paths import REPO


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", required=True, help="two case names, comma-separated")
    ap.add_argument("--rounds", type=int, default=150)
    ap.add_argument("--steps", type=int, default=30_000)
    ap.add_argument("--c", action="append", default=[], metavar="C.so:CASE",
                    help="a C FMU build and its case, run in every round (repeatable)")
    ap.add_argument("libs", nargs="+")
    args = ap.parse_args(argv)
    names = args.cases.split(",")
    libs = [Path(p) for p in args.libs]
    anchors = [(Path(lib), case) for lib, case in (c.rsplit(":", 1) for c in args.c)]
    d = Description(REPO / "modelDescription" / "modelDescription.xml")
    tokens = dict(cases(d)) | dict(c_cases(d))
    tmp = Path(tempfile.mkdtemp(prefix="tld_ab_pairs_"))
    # issue #29's scene, as ab_settings.py's job
    wf = math.sqrt(math.pi * 9.81 / 0.25 * math.tanh(math.pi * 0.021 / 0.25))
    w, amp, dt = 1.05 * wf, 0.003, 1e-3
    f = tmp / "input.f64"
    (-w * w * amp * np.sin(w * dt * np.arange(args.steps))).astype("<f8").tofile(f)
    lines = [f"guid {d.guid}",
             f"vrs base_a={d.vr('base.a')} x={d.vr('slosh.x')} v={d.vr('slosh.v')} "
             f"force={d.vr('force')} mass_inactive={d.vr('mass.inactive')}",
             "repeats 3", f"outdir {tmp}", f"input {f} {args.steps}", f"dt {dt!r}", "clock cpu"]
    for r in range(args.rounds):
        for i, lib in enumerate(libs):
            lines.append(f"lib {lib}")
            lines += [f"run {i}_{n}_{r} fmu {' '.join(tokens[n])}" for n in names]
        for k, (lib, case) in enumerate(anchors):
            lines += [f"lib {lib.resolve()}", f"run c{k}_{r} fmu {' '.join(tokens[case])}"]
    job = tmp / "pairs.job"
    job.write_text("\n".join(lines) + "\n")
    try:
        t = run(job)
    finally:
        # the runs' histories (hundreds of MB for long jobs): only the times are used
        shutil.rmtree(tmp, ignore_errors=True)
    rounds = range(args.rounds)
    for i, lib in enumerate(libs):
        med = " ".join(f"{n}={statistics.median(t[f'{i}_{n}_{r}'] for r in rounds):.1f}"
                       for n in names)
        line = f"{lib}: {med} ns/step"
        if len(names) == 2:
            ratio = statistics.median(t[f"{i}_{names[0]}_{r}"] / t[f"{i}_{names[1]}_{r}"]
                                      for r in rounds)
            line += f"; paired {names[0]}/{names[1]} {ratio:.3f}"
        print(line)
    for k, (lib, case) in enumerate(anchors):
        print(f"{lib}: {case}={statistics.median(t[f'c{k}_{r}'] for r in rounds):.1f} ns/step")
        for i, tld in enumerate(libs):
            for n in names:
                ratio = statistics.median(t[f"{i}_{n}_{r}"] / t[f"c{k}_{r}"] for r in rounds)
                print(f"{n}: {tld.name} / {lib.name} {case} paired {ratio:.3f}")
    for i in range(1, len(libs)):
        for n in names:
            ratio = statistics.median(t[f"{i}_{n}_{r}"] / t[f"0_{n}_{r}"] for r in rounds)
            print(f"{n}: {libs[i].name} / {libs[0].name} paired {ratio:.3f}")


if __name__ == "__main__":
    main()
