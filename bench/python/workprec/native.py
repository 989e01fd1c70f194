"""Native runs: one job file per scene and communication step for bench/native's `tld-bench`
host, which dlopens the FMU, times the stepping loop and runs the plain-Rust baselines the same
way; its result lines become the benchmark's rows."""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np

from tld_fmu.scenes import (TOLS, NATIVE_BIN, FmuInfo, Scene, n_steps, rel_err,
                            substep_counts)

from .cfmu import BUILDS, c_fmu, c_tokens


def run_native(fi: FmuInfo, sc: Scene, dt, a, refs, quick, tmp: Path):
    n = n_steps(sc, dt)
    long_scene = sc.T * 1.0 / dt > 1e6
    repeats = 3 if (quick or long_scene) else 5
    outdir = tmp / f"{sc.key}_{dt:g}"
    outdir.mkdir(parents=True, exist_ok=True)
    p = sc.p
    lines = [
        f"lib {fi.lib}", f"guid {fi.md.guid}", fi.vrs_line(),
        f"dt {dt!r}", f"repeats {repeats}", f"outdir {outdir}",
        f"model omega={p.omega_f!r} zeta={p.zeta_fixed!r} eta={p.eta!r} phi={p.phi!r} "
        f"a={p.a!r} m={p.m!r}",
    ]
    if sc.kind == "coupled":
        c = sc.coupled
        lines.append(f"coupled M={c['M']!r} C={c['C']!r} K={c['K']!r} Ag={c['Ag']!r} "
                     f"wg={c['wg']!r} sub={c['sub']} n={n} m0={p.m0!r}")
    else:
        f = outdir / "input.f64"
        a.astype("<f8").tofile(f)
        lines.append(f"input {f} {n}")
    phys = fi.scene_tokens(sc)
    meta = {}
    for method, setting, toks in fi.solver_settings(dt, quick, p.omega_f):
        rid = f"fmu_{method}_{setting}".replace("=", "").replace("+", "")
        meta[rid] = dict(impl="TLD.fmu", method=method, setting=setting)
        lines.append(f"run {rid} fmu {' '.join(phys + toks)}")
    for tol in (TOLS if not quick else [1e-6, 1e-10]):
        rid = f"rust_DP45_{tol:g}"
        meta[rid] = dict(impl="Rust baseline", method="DP45", setting=f"tol={tol:g}")
        lines.append(f"run {rid} dp45 rtol={tol!r}")
    for ns in substep_counts(dt, quick):
        rid = f"rust_RK4_{ns}"
        meta[rid] = dict(impl="Rust baseline", method="RK4", setting=f"n={ns}")
        lines.append(f"run {rid} rk4 sub={ns}")
    # diagnostic (not a baseline): the most accurate RK4 integrating over (t + dt) - t
    ns = substep_counts(dt, quick)[-1]
    rid = f"rust_RK4abs_{ns}"
    meta[rid] = dict(impl="Rust diagnostic", method="RK4 over (t+dt)-t", setting=f"n={ns}")
    lines.append(f"run {rid} rk4 sub={ns} span=abs")
    # the careful C FMU (bench/c/tld_c.c) through the same host and calls, as it is, with the
    # energies TLD.fmu integrates, and through clang: RK4 with the same substeps as TLD.fmu's,
    # DormandPrince45 at the same tolerances
    ctoks = c_tokens(fi, p)
    for build, (impl, _, _, _, tag) in enumerate(BUILDS):
        lines.append(f"lib {c_fmu(tmp, build)}")
        for ns in substep_counts(dt, quick):
            rid = f"{tag}_RK4_{ns}"
            meta[rid] = dict(impl=impl, method="RK4", setting=f"n={ns}")
            lines.append(f"run {rid} fmu {' '.join(ctoks)} {fi.token('solver', 'RK4')} "
                         f"{fi.token('solver.fixed_step', dt / ns)}")
        for tol in (TOLS if not quick else [1e-6, 1e-10]):
            rid = f"{tag}_DP45_{tol:g}"
            meta[rid] = dict(impl=impl, method="DP45", setting=f"tol={tol:g}")
            lines.append(f"run {rid} fmu {' '.join(ctoks)} "
                         f"{fi.token('solver', 'DormandPrince45')} "
                         f"{fi.token('solver.tolerance', tol)}")
    job = outdir / "jobs.txt"
    job.write_text("\n".join(lines) + "\n")
    proc = subprocess.run([str(NATIVE_BIN), str(job)], capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"tld-bench failed on {job}:\n{proc.stderr}")
    xref = refs[(sc.key, dt)]["x"]
    rows = []
    for line in proc.stdout.splitlines():
        tok = line.split()
        if not tok or tok[0] != "result":
            continue
        rid, status = tok[1], tok[2]
        row = dict(scene=sc.key, dt=dt, n=n, **meta[rid], window=False)
        if status == "ok":
            N, med = int(tok[3]), int(tok[4])
            x = np.fromfile(outdir / f"{rid}.x.f64", dtype="<f8")
            row.update(status="ok", ns_step=med / N, ns_simsec=med / (N * dt),
                       times=[int(t) for t in tok[5].split(",")], err=rel_err(x, xref),
                       _x=x)
        else:
            row.update(status="fail", fail_step=int(tok[3]), message=" ".join(tok[4:]),
                       err=None, ns_step=None, ns_simsec=None)
        rows.append(row)
    stderr = [l for l in proc.stderr.splitlines() if l.strip()]
    shutil.rmtree(outdir, ignore_errors=True)
    return rows, stderr
