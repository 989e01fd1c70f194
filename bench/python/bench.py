"""Work-precision benchmark of TLD.fmu (driven by scripts/bench).

Everything runs in this one process tree, in this order:
  1. references: tld_fmu.reference's fixed-step 8th-order Runge-Kutta with held inputs
     (`simulate_held`) at the SAME communication steps and inputs, substeps <= h_ref, cached on
     disk; each also checked against a run with twice the substeps (its own error estimate);
  2. native runs: bench/native's `tld-bench` host dlopens the FMU's TLD.so and times the
     stepping loop (median of repeats), and runs the plain-Rust baselines the same way;
  3. Python baselines on a window at the start of each scene: scipy solve_ivp (DOP853, LSODA)
     restarted on every communication interval with the held input, the same model as a
     pythonfmu FMU through fmpy, and TLD.fmu through fmpy (cross-check and fmpy's overhead);
  4. the shallow-water model's cost against its cells and error (workprec/swe.py);
  5. the report: docs/BENCHMARKS.md, docs/bench/*.png, docs/bench/results.json.

Error of a run = max over the history of |x - x_ref| / max |x_ref| (x = slosh.x).
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tld_fmu.machine import git_info
from tld_fmu.paths import FMU, REPO
from tld_fmu.scenes import (FmuInfo, check_scenes, compute_references, make_scenes, n_steps,
                            rel_err, _stats)

from workprec.baselines import build_pythonfmu, python_window, run_python, slave_for
from workprec.formats import dt_label, fmt_ns
from workprec.native import run_native
from workprec.plots import plots
from workprec.report import write_report
from workprec.sweep import sweep_section, sweep_throughput
from workprec.swe import swe_cost, swe_section
from workprec.latency import latency_cost, latency_section

WORK = REPO / "target" / "bench"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="smoke run (< 1 minute)")
    ap.add_argument("--fmu", default=str(FMU))
    ap.add_argument("--out", default=None, help="report directory (default: docs, or "
                    "target/bench/quick with --quick)")
    ap.add_argument("--only", choices=["study", "study-report"], help="study: measure the design-study "
                    "throughput alone and replace its section of the existing report (about 4 minutes); "
                    "study-report: rewrite that section from the last measurement (bench/study.json)")
    ap.add_argument("--swe-only", action="store_true", help="only the shallow-water section: "
                    "print it, write it to target/bench/swe.md and (without --quick) put it in place of "
                    "the report's")
    ap.add_argument("--latency-only", action="store_true", help="only the step-time tails "
                    "section: print it, write it to target/bench/latency.md and (without --quick) "
                    "put it in place of the report's")
    args = ap.parse_args()
    from tqdm import tqdm

    t_start = time.perf_counter()
    timings = {}
    out = Path(args.out) if args.out else (WORK / "quick" if args.quick else REPO / "docs")
    img = out / "bench"
    img.mkdir(parents=True, exist_ok=True)
    WORK.mkdir(parents=True, exist_ok=True)
    # a private copy: a rebuild of target/fmu during the run must not change what is measured
    fmu_copy = WORK / "TLD.fmu"
    shutil.copyfile(args.fmu, fmu_copy)
    if args.only:
        return only_study(args, fmu_copy, out)
    fi = FmuInfo(fmu_copy)
    fi.path = Path(args.fmu)
    print(f"FMU {args.fmu} (sha256 {fi.sha256[:16]}), solver items: "
          + ", ".join(f"{n}={v}" for n, v, _ in fi.items("solver")), flush=True)
    # one section alone: printed and written to target/bench/<name>.md
    alone = {"swe": (swe_cost, swe_section), "latency": (latency_cost, latency_section)}
    name = "swe" if args.swe_only else "latency" if args.latency_only else None
    if name:
        cost, write = alone[name]
        lines = write(cost(fi, args.quick, WORK))
        section = "\n".join(lines)
        (WORK / f"{name}.md").write_text(section)
        print(section)
        shutil.rmtree(fi.unzip, ignore_errors=True)
        if not args.quick:
            # measured anew: in place of the report's section, saying when, on what and
            # under what load (the machine is shared)
            load = " ".join(f"{x:.2f}" for x in os.getloadavg())
            lines[2:2] = [f"Measured {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} by "
                          f"`scripts/bench --{name}-only` on {git_info()} (load average after "
                          f"the runs: {load}, 2 cores).", ""]
            replace_section(out / "BENCHMARKS.md", lines)
            print(f"wrote {out / 'BENCHMARKS.md'} (its {lines[0][3:]} section)")
        return

    scenes = make_scenes(args.quick)
    inputs = {}
    for sc in scenes:
        for dt in sc.dts:
            if sc.kind == "open":
                inputs[(sc.key, dt)] = sc.make_input(dt, n_steps(sc, dt))

    t0 = time.perf_counter()
    refs = compute_references(scenes, inputs, args.quick, tqdm)
    timings["references"] = time.perf_counter() - t0
    ref_computed = _stats.get("ref_computed", 0)

    t0 = time.perf_counter()
    rows, stderr_lines = [], []
    tmp = Path(tempfile.mkdtemp(prefix="tld_bench_runs_", dir=str(WORK)))
    combos = [(sc, dt) for sc in scenes for dt in sc.dts]
    for sc, dt in tqdm(combos, desc="native runs (FMU + Rust baselines)", unit="scene×dt"):
        r, e = run_native(fi, sc, dt, inputs.get((sc.key, dt)), refs, args.quick, tmp)
        rows += r
        stderr_lines += [f"[{sc.key} dt={dt:g}] {l}" for l in e]
    shutil.rmtree(tmp, ignore_errors=True)
    timings["native"] = time.perf_counter() - t0
    # a scene its best run misses by far is broken (FMU and reference differ): said now, in the
    # report's head and by the exit status
    scene_failures = check_scenes(refs, rows)
    for f in scene_failures:
        print(f"scripts/bench: SCENE CHECK FAILED: {f}", file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    pyfmu, pyfmu_note = build_pythonfmu(WORK)
    if pyfmu is None:
        print(f"pythonfmu FMU could not be built: {pyfmu_note}", file=sys.stderr)
        py_slave = None
    else:
        py_slave, _ = slave_for(pyfmu)
    tld_slave, _ = slave_for(fmu_copy)
    xcheck = []
    for sc, dt in tqdm(combos, desc="Python baselines (scipy, pythonfmu, fmpy)", unit="scene×dt"):
        pr = run_python(fi, sc, dt, inputs.get((sc.key, dt)), refs, args.quick, tld_slave, py_slave)
        nw = python_window(sc, dt, args.quick)
        xref_w = refs[(sc.key, dt)]["x"][: nw + 1]
        for r in rows:
            if r["scene"] == sc.key and r["dt"] == dt and r["status"] == "ok" and "_x" in r \
                    and not r["window"]:
                r["err_win"] = rel_err(r["_x"][: nw + 1], xref_w)
        nat = [r for r in rows if r["scene"] == sc.key and r["dt"] == dt
               and r["impl"] == "TLD.fmu" and r["method"] == "default" and r["status"] == "ok"]
        via = [r for r in pr if r["impl"] == "TLD.fmu via fmpy" and r["status"] == "ok"]
        if nat and via:
            d = float(np.max(np.abs(nat[0]["_x"][: nw + 1] - via[0]["_x"])))
            xcheck.append(f"{sc.key.split('_')[0]} {dt_label(dt)}: max |Δx| = {d:.1e} m, fmpy "
                          f"{fmt_ns(via[0]['ns_step'])} vs native {fmt_ns(nat[0]['ns_step'])} ns/step")
        rows += pr
    timings["python baselines"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    sweep_result = sweep_throughput(fmu_copy, args.quick)
    timings["sweep throughput"] = time.perf_counter() - t0
    print("\n".join(sweep_section(sweep_result)), flush=True)

    t0 = time.perf_counter()
    swe_result = swe_cost(fi, args.quick, WORK)
    timings["shallow water"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    latency_result = latency_cost(fi, args.quick, WORK)
    timings["step-time tails"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    plots(scenes, rows, img, "")
    timings["report"] = time.perf_counter() - t0
    timings["total"] = time.perf_counter() - t_start
    timings["_ref_computed"] = ref_computed
    tgt = write_report(args, scenes, refs, rows, stderr_lines, timings, out / "BENCHMARKS.md", img,
                       pyfmu_note, fi, xcheck,
                       sweep_section(sweep_result) + swe_section(swe_result)
                       + latency_section(latency_result), scene_failures)
    clean = [{k: v for k, v in r.items() if not k.startswith("_")} for r in rows]
    (img / "results.json").write_text(json.dumps(dict(
        timings=timings, targets=tgt, rows=clean, shallow_water=swe_result,
        step_time_tails=latency_result,
        scenes=[dict(key=s.key, title=s.title, T=s.T, dts=s.dts, describe=s.describe)
                for s in scenes], sweep=sweep_result), indent=1, default=str))
    shutil.rmtree(fi.unzip, ignore_errors=True)
    print(f"wrote {out / 'BENCHMARKS.md'} and {img}/ in {timings['total']:.0f} s")
    for k, v in tgt["summary"].items():
        print(f"  target ({k}): {v}")
    if scene_failures:
        for f in scene_failures:
            print(f"scripts/bench: SCENE CHECK FAILED: {f}", file=sys.stderr)
        sys.exit(3)


def replace_section(md: Path, section: list[str]):
    """Put `section` (its first line the heading) in place of the report's section of that
    heading, or before "## Reproduce" when the report has none."""
    text = md.read_text() if md.exists() else "# TLD.fmu work-precision benchmark\n\n## Reproduce\n"
    lines = text.split("\n")
    start = next((i for i, l in enumerate(lines) if l == section[0]), None)
    if start is None:
        start = end = next(i for i, l in enumerate(lines) if l.startswith("## Reproduce"))
    else:
        end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    md.write_text("\n".join(lines[:start] + section + lines[end:]))


def only_study(args, fmu: Path, out: Path):
    """--only study: the design-study section measured anew and put in place of the report's;
    --only study-report: the section written again from the last measurement."""
    saved = out / "bench" / "study.json"
    if args.only == "study-report":
        res = json.loads(saved.read_text())
    else:
        t0 = time.perf_counter()
        res = sweep_throughput(fmu, args.quick)
        commit = git_info()
        res["measured"] = (f"Measured {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} by "
                           f"`scripts/bench --only study` on {commit} in {time.perf_counter() - t0:.0f} s.")
    section = sweep_section(res)
    section[2:2] = [res.get("measured", ""), ""]
    md = out / "BENCHMARKS.md"
    replace_section(md, section)
    saved.parent.mkdir(parents=True, exist_ok=True)
    saved.write_text(json.dumps(res, indent=1, default=str))
    print("\n".join(section))
    print(f"wrote {md} (its design-study section) and {saved}")


if __name__ == "__main__":
    main()
