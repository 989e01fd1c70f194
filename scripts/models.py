"""Which model for which scene: error and cost of each model of the ladder on the benchmark's
open-loop scenes (tld_fmu.scenes), measured through the native host (bench/native).

Error: max |x - x_ref| / max |x_ref| over the whole history, x_ref the Nonlinear model's
high-accuracy solution (tld_fmu.reference) with the same held inputs, so it measures
how far each model is from Eq 2.11 with the NSD-free scene physics. Cost: median ns per doStep.
Writes out/MODELS.md (--docs: regenerates the tracked docs/MODELS.md), with the run's wall time.
Needs target/fmu/TLD.fmu (scripts/package) and the native benchmark host target/release/tld-bench,
which it builds first with cargo if it is missing (saying so: a few minutes the first time).
    .venv/bin/python scripts/models.py --dt 0.01 --docs"""
import argparse
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from tld_fmu import scenes as bench
from tld_fmu.machine import machine_line
from tld_fmu.paths import FMU, REPO

# parameters per model (enumeration items by name; solver.fixed_step None: the communication step)
MODELS = [
    ("Linear, 1 mode", {"model": "Linear", "modes": 1}),
    ("Linear, 3 modes", {"model": "Linear", "modes": 3}),
    ("Nonlinear (defaults)", {"model": "Nonlinear"}),
    ("Nonlinear, RK4 one substep", {"model": "Nonlinear", "solver": "RK4", "solver.fixed_step": None}),
    ("Nonlinear, ExpRK4 one substep", {"model": "Nonlinear", "solver": "ExpRK4", "solver.fixed_step": None}),
    ("Nonlinear, RK8 one substep", {"model": "Nonlinear", "solver": "RK8", "solver.fixed_step": None}),
    ("Auto, threshold = tolerance", {"model": "Auto"}),
    ("Auto, threshold 1e-4", {"model": "Auto", "auto.threshold": 1e-4}),
    ("Auto, threshold 1e-2", {"model": "Auto", "auto.threshold": 1e-2}),
    ("SloshingSlamming, Omega 1", {"model": "SloshingSlamming", "slamming.Omega": 1.0}),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dt", type=float, default=0.01, help="communication step [s] (default 0.01)")
    ap.add_argument("--docs", action="store_true", help="regenerate the tracked docs/MODELS.md (default: out/MODELS.md)")
    args = ap.parse_args()
    dt = args.dt
    t0 = time.perf_counter()
    # check what the runs need before the references (about a minute) are computed
    if not FMU.is_file():
        raise SystemExit(f"models.py: {FMU} not found: run scripts/package first")
    if not bench.NATIVE_BIN.is_file():
        print(f"models.py: building the native benchmark host {bench.NATIVE_BIN.relative_to(REPO)} "
              "(cargo build --release -p tld-bench; a few minutes the first time)", flush=True)
    build = subprocess.run(["cargo", "build", "--release", "--quiet", "-p", "tld-bench"], cwd=REPO)
    if build.returncode != 0 or not bench.NATIVE_BIN.is_file():
        raise SystemExit("models.py: cargo build --release -p tld-bench failed")
    fi = bench.FmuInfo(FMU)
    scenes = [sc for sc in bench.make_scenes(False) if sc.kind == "open"]
    # A wind-level scene, where the hardening is small: the benchmark's scenes are all strongly
    # nonlinear (2x/a about 0.5).
    p0 = scenes[0].p
    scenes.insert(0, bench.Scene(
        "s0_wind", "0: wind-level harmonic, Lambda = 4e-4", p0, 60.0, [dt], 1e-3,
        "base.x = 0.1 mm sin(w_f t)", make_input=bench.harmonic_input(p0.omega_f, 1e-4)))
    for sc in scenes:
        sc.dts = [dt]
    inputs = {(sc.key, dt): sc.make_input(dt, bench.n_steps(sc, dt)) for sc in scenes}
    from tqdm import tqdm
    refs = bench.compute_references(scenes, inputs, False, tqdm)
    rows = []
    tmp = Path(tempfile.mkdtemp())
    for sc in tqdm(scenes, desc="models x scenes", disable=None):
        n = bench.n_steps(sc, dt)
        a = inputs[(sc.key, dt)]
        p = sc.p
        f = tmp / "input.f64"
        a.astype("<f8").tofile(f)
        lines = [f"lib {fi.lib}", f"guid {fi.md.guid}", fi.vrs_line(),
                 f"dt {dt!r}", f"repeats {3 if n > 1e5 else 5}", f"outdir {tmp}",
                 f"model omega={p.omega_f!r} zeta={p.zeta_fixed!r} eta={p.eta!r} phi={p.phi!r} a={p.a!r} m={p.m!r}",
                 f"input {f} {n}"]
        for k, (label, params) in enumerate(MODELS):
            toks = fi.physics_tokens(p) + [fi.token(name, dt if v is None else v) for name, v in params.items()]
            lines.append(f"run m{k} fmu {' '.join(toks)}")
        job = tmp / "jobs.txt"
        job.write_text("\n".join(lines) + "\n")
        out = subprocess.run([str(bench.NATIVE_BIN), str(job)], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            tok = line.split()
            if tok and tok[0] == "result" and tok[2] == "ok":
                k = int(tok[1][1:])
                x = np.fromfile(tmp / f"{tok[1]}.x.f64", dtype="<f8")
                rows.append((sc.title, MODELS[k][0], bench.rel_err(x, refs[(sc.key, dt)]["x"]), int(tok[4]) / int(tok[3])))
    shutil.rmtree(tmp, ignore_errors=True)
    md = [f"# Which model for which scene (regenerated by `scripts/models.py --dt {dt:g}{' --docs' if args.docs else ''}`, "
          f"dt = {dt * 1e3:g} ms)", "",
          "Error against the Nonlinear model's high-accuracy solution (Eq 2.11, same held inputs), over "
          "the whole history; cost through the native host, median ns per doStep, this machine "
          f"({machine_line()}); the run took {time.perf_counter() - t0:.0f} s.", "",
          "| scene | model | error | ns per doStep |", "|---|---|---|---|"]
    md += [f"| {s} | {m} | {e:.2e} | {c:.0f} |" for s, m, e, c in rows]
    path = REPO / ("docs" if args.docs else "out") / "MODELS.md"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(md) + "\n")
    print("\n".join(md))
    print(f"wrote {path.relative_to(REPO)}")


if __name__ == "__main__":
    main()
