"""The shallow-water model's cost against its cells and its error (issue #15): the lab tank
(the FMU's default tank) with `model` = ShallowWater and `damping` = BoundaryLayer, harmonic
base.a at Lambda = A_e/a = 0.02 at resonance held over 10 ms communication steps, through the
native host (bench/native's `tld-bench`, the same timed loop as the work-precision scenes) for
`swe.cells` from 25 to 800 against a fine-grid run of the same scene."""
from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from tld_fmu import reference as R
from tld_fmu.scenes import NATIVE_BIN, FmuInfo, rel_err

from workprec.formats import fmt_e, fmt_ns

DT = 0.01
A_E = 0.005          # Lambda = A_e / a = 0.02 in the 0.25 m lab tank
# (cells, repeats); the reference is the last, run once
FULL = dict(cells=[(25, 5), (50, 5), (100, 5), (150, 5), (200, 5), (250, 5), (400, 3), (800, 3),
                   (1600, 1)],
            T=60.0, tail=30.0)
QUICK = dict(cells=[(25, 3), (50, 3), (100, 3), (150, 3), (200, 1)], T=10.0, tail=5.0)


def rms_err(y, ref) -> float:
    """The rms over time of y - ref, relative to the largest |ref| (the time-history measure of
    issue #29: force.mean's history against the finest count's)."""
    k = min(len(y), len(ref))
    return float(np.sqrt(np.mean((y[:k] - ref[:k]) ** 2)) / np.max(np.abs(ref[:k])))


def at_equal_error(rows, target: float):
    """The cells and the CPU per doStep at which the rms force.mean error reaches `target`,
    interpolated log-log between the two counts either side of it (None if no pair brackets
    it)."""
    for a, b in zip(rows, rows[1:]):
        if a["rms_mean"] >= target >= b["rms_mean"] > 0:
            t = np.log(target / a["rms_mean"]) / np.log(b["rms_mean"] / a["rms_mean"])
            cells = a["cells"] * (b["cells"] / a["cells"]) ** t
            ns = (a["ns"] / a["steps"]) * ((b["ns"] / b["steps"]) / (a["ns"] / a["steps"])) ** t
            return cells, ns
    return None


def swe_cost(fi: FmuInfo, quick: bool, work: Path):
    """Per cell count: cells, median ns of the stepping loop, steps, the force amplitude after
    `tail`, the errors of slosh.x and force histories against the finest count; and the
    scene."""
    cfg = QUICK if quick else FULL
    p = R.TLD()
    w = p.omega_f
    n = int(round(cfg["T"] / DT))
    a = -w * w * A_E * np.sin(w * DT * np.arange(n))
    tmp = Path(tempfile.mkdtemp(prefix="tld_bench_swe_", dir=str(work)))
    try:
        (tmp / "input.f64").write_bytes(a.astype("<f8").tobytes())
        lines = [f"lib {fi.lib}", f"guid {fi.md.guid}", fi.vrs_line(), f"dt {DT!r}",
                 f"outdir {tmp}", f"input {tmp / 'input.f64'} {n}", "clock cpu"]
        common = [fi.token("model", "ShallowWater"), fi.token("damping", "BoundaryLayer")]
        for cells, repeats in cfg["cells"]:
            lines.append(f"repeats {repeats}")
            lines.append(f"run swe_{cells} fmu {' '.join(common)} "
                         f"{fi.token('swe.cells', cells)}")
        # Once more, untimed, with force.mean in the host's force slot: the step's impulse over
        # h, from the wall fluxes (the state force extrapolates the wall depths).
        lines.append(fi.vrs_line().replace(f"force={fi.vr('force')}",
                                           f"force={fi.vr('force.mean')}"))
        lines.append("repeats 1")
        for cells, _ in cfg["cells"]:
            lines.append(f"run mean_{cells} fmu {' '.join(common)} "
                         f"{fi.token('swe.cells', cells)}")
        job = tmp / "jobs.txt"
        job.write_text("\n".join(lines) + "\n")
        proc = subprocess.run([str(NATIVE_BIN), str(job)], capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"tld-bench failed on {job}:\n{proc.stderr}")
        runs, means = {}, {}
        for line in proc.stdout.splitlines():
            tok = line.split()
            if len(tok) < 5 or tok[0] != "result" or tok[2] != "ok":
                if tok and tok[0] == "result":
                    raise RuntimeError(f"shallow-water run failed: {line}")
                continue
            kind, cells = tok[1].split("_")
            x = np.fromfile(tmp / f"{tok[1]}.x.f64", dtype="<f8")
            f = np.fromfile(tmp / f"{tok[1]}.f.f64", dtype="<f8")
            if kind == "swe":
                runs[int(cells)] = dict(ns=int(tok[4]), steps=int(tok[3]), x=x, f=f)
            else:
                means[int(cells)] = f
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    finest = cfg["cells"][-1][0]
    ref, ref_mean = runs[finest], means[finest]
    tail = slice(int(round(cfg["tail"] / DT)) + 1, None)
    amplitude = lambda y: float(np.max(np.abs(y[tail])))
    rows = []
    for cells, _ in cfg["cells"]:
        r, mean = runs[cells], means[cells]
        rows.append(dict(cells=cells, ns=r["ns"], steps=r["steps"],
                         force_amplitude=amplitude(r["f"]),
                         err_amplitude=amplitude(r["f"]) / amplitude(ref["f"]) - 1.0,
                         mean_amplitude=amplitude(mean),
                         err_mean_amplitude=amplitude(mean) / amplitude(ref_mean) - 1.0,
                         err_x=rel_err(r["x"], ref["x"]), err_force=rel_err(r["f"], ref["f"]),
                         err_mean=rel_err(mean, ref_mean),
                         rms_mean=rms_err(mean, ref_mean)))
    scene = dict(T=cfg["T"], tail=cfg["tail"], omega=w, reference=cfg["cells"][-1][0],
                 default=int(fi.vars["swe.cells"].start))
    return rows, scene


def swe_section(result) -> list[str]:
    rows, sc = result
    ref = sc["reference"]
    fit = [r for r in rows if r["cells"] >= 50]
    k = np.polyfit(np.log([r["cells"] for r in fit]), np.log([r["ns"] for r in fit]), 1)[0]
    L = ["## The shallow-water model: cost against cells and error", "",
         f"`model` = ShallowWater, `damping` = BoundaryLayer, the lab tank (the FMU's defaults), "
         f"base.a = −w² A_e sin(w t) held over each 10 ms step, A_e = {A_E * 1e3:g} mm "
         f"(Lambda = 0.02), w = omega_f = {sc['omega']:.4f} rad/s (resonance: bores), from rest, "
         f"{sc['T']:g} s; the same timed loop as above (set base.a, doStep, get 3 outputs), "
         f"median of the repeats. Error against `swe.cells` = {ref} on the same scene: of the "
         f"histories of slosh.x, force and force.mean (max |y − y_ref| / max |y_ref|), the rms over "
         f"the whole history of force.mean − its reference relative to the reference's largest "
         f"|force.mean| (issue #29's time-history measure: the bores' arrival at the walls decides "
         f"it), and of the "
         f"amplitudes of force and force.mean after {sc['tail']:g} s (the quantities of the "
         f"swe.cells convergence study in docs/SHALLOW_WATER.md). Time = the CPU time of the host's "
         f"thread in the stepping loop (`clock cpu`; the scenes above time the wall clock, the "
         f"same on a quiet machine), so that other processes do not stretch it; × real time = "
         f"simulated seconds per second of it. The pointwise force errors "
         f"are dominated by the bores: the instant a bore reaches a wall shifts a little with "
         f"the grid, and a bore's reflection starts with a spike in the wall cell (up to "
         f"about 20 % above the reflected level under MUSCL-Hancock, whose bores are sharp, "
         f"for about a cell's transit) that a 10 ms sample of the "
         f"state force may or may not land on (force.mean, the step's impulse, converges).", "",
         "| cells | ns/doStep (CPU) | ms CPU per simulated s | × real time | ns/s ÷ cells² | "
         "err slosh.x | err force | err force.mean | rms force.mean | force amplitude [N] | "
         "vs ref. | force.mean amplitude [N] | vs ref. |",
         "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        per_s = r["ns"] / (r["steps"] * DT)
        last = r["cells"] == ref
        pct = lambda v: f"{100 * v:+.2f} %"
        e = ("—",) * 6 if last else (fmt_e(r["err_x"]), fmt_e(r["err_force"]),
                                      fmt_e(r["err_mean"]), pct(r["err_amplitude"]),
                                      pct(r["err_mean_amplitude"]), f"{100 * r['rms_mean']:.2f} %")
        L.append(f"| {r['cells']}{' (ref.)' if last else ''} | {fmt_ns(r['ns'] / r['steps'])} | "
                 f"{per_s / 1e6:.3g} | {1e9 / per_s:,.0f} | {per_s / r['cells'] ** 2:.3g} | "
                 f"{e[0]} | {e[1]} | {e[2]} | {e[5]} | {r['force_amplitude']:.5f} | {e[3]} | "
                 f"{r['mean_amplitude']:.5f} | {e[4]} |")
    default = next((r for r in rows if r["cells"] == sc["default"]), None)
    L.append("")
    L.append(
        f"Cost per simulated second grows as cells^{k:.2f} (fit from 50 cells up): linear in the "
        "cells per substep, times the substeps: a substep is at most the 10 ms step and at most "
        "0.9 dx over the fastest wave (MUSCL-Hancock at Courant 0.9), so one substep per step "
        "up to about 35 cells here (cost linear in the cells), then substeps proportional to "
        "the cells (cost as cells², the column ns/s ÷ cells² then constant, up to the fixed cost "
        "per doStep).")
    if default is not None:
        per_s = default["ns"] / (default["steps"] * DT)
        verdict = "met" if 1e9 / per_s >= 1000 else "NOT met"
        L.append(f"At the default {sc['default']} cells (`swe.cells`' start value): "
                 f"{1e9 / per_s:,.0f}× real time (target ≥ 1000×: {verdict}).")
    for target in (0.02, 0.01, 0.005):
        eq = at_equal_error([r for r in rows if r["cells"] != ref], target)
        if eq is not None:
            cells, ns = eq
            L.append(f"Cost at equal error, rms force.mean = {100 * target:g} %: about "
                     f"{cells:.0f} cells, {ns / 1e3:.1f} µs CPU per doStep "
                     f"({1e9 / (ns / DT):,.0f}× real time), interpolated log-log between the "
                     f"counts either side.")
    if default is not None:
        L.append(f"At the default {sc['default']} cells: rms force.mean "
                 f"{100 * default['rms_mean']:.2f} % (target ≤ 1 %: "
                 f"{'met' if default['rms_mean'] <= 0.01 else 'NOT met'}).")
    L.append("")
    return L
