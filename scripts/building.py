"""A structural master for TLD.fmu: an N-storey shear building (storey masses, stiffnesses and
Rayleigh damping from a TOML file) with TLD FMU instances on chosen floors, under a harmonic
ground-motion sweep, a ground-acceleration record, or band-limited wind-like random forces on the
floors, coupled by a fixed-step explicit scheme.

The building, the dampers and the coupling are python/tld_fmu/building.py; this file reads the
TOML (damper parameters by name; an enumeration's item by name, e.g. amplitude = "Tracked"), runs
the load case and writes the results.

    .venv/bin/python scripts/building.py scripts/examples/building.toml [--out out/building]

Writes a CSV and PNG plots (sweep: peak roof displacement with and without the dampers, every
peak refined by tld_fmu.peaks to --xtol, the grid and the refinement runs shown as points;
record and wind: storey drifts, roof displacement and acceleration with and without the dampers,
damper forces and energies)."""
import argparse
import multiprocessing as mp
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tld_fmu import fmulog
from tld_fmu import peaks as pk
from tld_fmu.building import Building, check_plausible, harmonic_ground, record_ground, simulate, wind_forces
from tld_fmu.contract import Contract
from tld_fmu.studyfile import StudyError, load_building
from tld_fmu.paths import FMU, REPO


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("config")
    ap.add_argument("--out", default=str(REPO / "out" / "building"))
    ap.add_argument("--fmu", default=str(FMU))
    ap.add_argument("--xtol", type=float, default=2e-3,
                    help="harmonic sweep: tolerance of the refined peak frequencies, in w/w_1 (default 0.002)")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel runs (default: one per core)")
    ap.add_argument("--force", action="store_true",
                    help=f"run a configuration refused as implausible (water mass above "
                         f"{fmulog.MASS_RATIO_MAX:g} of the modal mass); its results are flagged")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    from fmpy import extract, read_model_description
    from tqdm import tqdm
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    if not Path(args.fmu).is_file():
        raise SystemExit(f"{args.fmu} not found: run scripts/package first")
    md = read_model_description(args.fmu)
    try:
        cfg = load_building(Path(args.config), Contract(md))
    except StudyError as e:
        raise SystemExit(f"scripts/building.py: {e}") from None
    unzipdir = extract(args.fmu, tempfile.mkdtemp())
    check_plausible(cfg, unzipdir, md, args.force)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    load, h = cfg["load"], cfg["coupling"]["step"]
    derivs = bool(cfg["coupling"].get("derivatives", False))
    if load["kind"] == "harmonic":
        sweep(cfg, unzipdir, md, out, args, plt)
    elif load["kind"] in ("record", "wind"):
        if load["kind"] == "record":
            rec = np.loadtxt(Path(args.config).parent / load["record"], delimiter=",")
            ground = record_ground(rec[:, 0], rec[:, 1])
            duration, forces = rec[-1, 0], None
        else:
            duration = load["duration"]
            ground = lambda t: (0.0, 0.0, 0.0)  # noqa: E731
            # on the RK4 stage times of the master's grid: 2 samples per communication step
            _, forces = wind_forces(len(cfg["building"]["masses"]), h / 2, 2 * int(round(duration / h)),
                                    load["force_rms"],
                                    load.get("band", [0.02, 5.0]), load.get("corner", 0.1),
                                    load.get("coherence", 0.5), load.get("seed", 1))
        runs = {}
        for damped in tqdm((False, True), desc=load["kind"], disable=None):
            runs[damped] = simulate(cfg, unzipdir, md, ground, h, duration, with_dampers=damped,
                                   floor_forces=forces, derivatives=derivs)
        write_histories(out, load["kind"], runs[True], runs[False], plt)
    else:
        sys.exit(f"unknown load kind {load['kind']!r}: harmonic, record or wind")
    print(f"wall time {time.perf_counter() - t_start:.0f} s")
    fmulog.REPORT.print_summary()


_RUN = {}   # what the sweep's worker processes need (set before the pool forks)


def _roof_peak(job):
    """Steady peak roof displacement of one sweep run: (with_dampers, w / w_1) -> metres."""
    damped, r = job
    cfg, unzipdir, md, w1, load, h, derivs = (_RUN[k] for k in ("cfg", "unzipdir", "md", "w1", "load", "h", "derivs"))
    s = simulate(cfg, unzipdir, md, harmonic_ground(r * w1, load["ground_amplitude"]), h, load["duration"],
                 with_dampers=damped, derivatives=derivs)
    tail = s["t"] > load["duration"] - 20.0
    # the FMU's warnings go back to the parent, which shows them (a worker's line would land in
    # the parent's progress bar)
    return float(np.max(np.abs(s["X"][tail, -1]))), fmulog.REPORT.drain()


def _peaks(results):
    """The peaks of _roof_peak's results; their warnings merged into this process's report."""
    out = []
    for peak, warned in results:
        fmulog.REPORT.merge(warned)
        out.append(peak)
    return out


def sweep(cfg, unzipdir, md, out, args, plt):
    """Harmonic ground motion over a grid of frequencies, with and without the dampers; every
    local maximum of both curves refined (golden section, tld_fmu.peaks) to args.xtol in w/w_1.
    The bare building's steady state is also given in closed form (it is linear): its transient
    decays as exp(-zeta w t), slowly at 1 % damping, so the co-simulated bare peaks over the last
    20 s of a run can fall short of it."""
    from tqdm import tqdm
    load, h = cfg["load"], cfg["coupling"]["step"]
    b = cfg["building"]
    bare_bld = Building(b["masses"], b["stiffnesses"], b["rayleigh"])
    w1, Ag = bare_bld.omega1, load["ground_amplitude"]
    _RUN.update(cfg=cfg, unzipdir=unzipdir, md=md, w1=w1, load=load, h=h,
                derivs=bool(cfg["coupling"].get("derivatives", False)))
    ratios = np.linspace(load["from"], load["to"], load["points"])
    jobs = [(damped, float(r)) for r in ratios for damped in (False, True)]
    with mp.get_context("fork").Pool(max(1, min(args.jobs, len(jobs))), initializer=fmulog.quiet_worker) as pool:
        got = _peaks(tqdm(pool.imap(_roof_peak, jobs), total=len(jobs), desc="sweep grid", disable=None))
        grid = {False: np.array(got[0::2]), True: np.array(got[1::2])}
        bar = tqdm(desc="peak refinement runs", disable=None)

        def evaluate(batch):
            bar.update(len(batch))
            return _peaks(pool.map(_roof_peak, batch))

        found = pk.refine_curves({d: (ratios, grid[d]) for d in (False, True)}, evaluate, args.xtol)
        bar.close()
    # the bare building in closed form: its peak refined to 1e-6
    closed = lambda r: bare_bld.steady_amplitudes(r * w1, Ag)[-1]  # noqa: E731
    bare_exact = pk.refine_peak(closed, ratios, xtol=1e-6)
    top_bare, top_damped = pk.highest(found[False]), pk.highest(found[True])
    pts = sorted([(r, d, y) for d in (False, True) for r, y in zip(ratios, grid[d])]
                 + [(x, d, y) for d in (False, True) for p in found[d] for x, y in p.points])
    np.savetxt(out / "sweep.csv", [(r, int(d), y) for r, d, y in pts], delimiter=",",
               header="w_over_w1,with_dampers,roof_peak", comments="", fmt=["%.6f", "%d", "%.9g"])
    with open(out / "sweep-peaks.csv", "w") as fh:
        fh.write("curve,w_over_w1,roof_peak,xtol,grid_w_over_w1,grid_roof_peak,bounded,refinement_runs\n")
        for d, name in ((False, "without dampers (co-simulated)"), (True, "with TLD.fmu")):
            for p in found[d]:
                fh.write(f"{name},{p.x:.6f},{p.y:.9g},{p.xtol:g},{p.grid_x:.6f},{p.grid_y:.9g},{p.bounded},{len(p.points)}\n")
        fh.write(f"without dampers (closed form),{bare_exact.x:.6f},{bare_exact.y:.9g},1e-06,"
                 f"{bare_exact.grid_x:.6f},{bare_exact.grid_y:.9g},{bare_exact.bounded},{len(bare_exact.points)}\n")

    fig, ax = plt.subplots(figsize=(8, 5))
    fine = np.linspace(load["from"], load["to"], 801)
    ax.plot(fine, [1e3 * closed(r) for r in fine], "-", color="0.6", lw=1,
            label="without dampers, closed-form steady state")
    for d, col, name in ((False, "k", "without dampers"), (True, "C0", "with TLD.fmu")):
        ax.plot(ratios, 1e3 * grid[d], "o", color=col, ms=4, label=f"{name}: co-simulation, grid")
        rp = np.array([q for p in found[d] for q in p.points]).reshape(-1, 2)
        ax.plot(rp[:, 0], 1e3 * rp[:, 1], ".", color=col, ms=5, alpha=0.6,
                label=f"{name}: refinement runs" if len(rp) else None)
        for p in found[d]:
            ax.plot(p.x, 1e3 * p.y, "*", color=col, ms=12, mec="k", mew=0.5)
            ax.annotate(f"{1e3 * p.y:.2f} mm at {p.x:.3f}", (p.x, 1e3 * p.y), textcoords="offset points",
                        xytext=(6, 4), fontsize=8, color=col)
    ax.plot([], [], "*", color="0.5", mec="k", ms=10, label=f"refined peak (+-{args.xtol:g} w_1)")
    reduction = 1 - top_damped.y / bare_exact.y
    n_tanks = sum(d.get("tanks", 1) for d in cfg.get("dampers", []))
    ax.set_title(f"{len(b['masses'])}-storey building (w_1 = {w1:.3f} rad/s, {100 * b['rayleigh'][0]:g} % damping), "
                 f"{n_tanks} tank(s), ground amplitude {1e3 * Ag:g} mm\n"
                 f"peak roof displacement {1e3 * bare_exact.y:.2f} -> {1e3 * top_damped.y:.2f} mm "
                 f"({100 * reduction:.1f} % less)", fontsize=10)
    ax.set_xlabel("w / w_1 (first mode of the bare building)")
    ax.set_ylabel("peak roof displacement relative to the ground [mm]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "sweep.png", dpi=120)
    print(f"peak roof displacement without dampers: {1e3 * bare_exact.y:.3f} mm at w/w_1 = {bare_exact.x:.4f} "
          f"(closed-form steady state; co-simulated: {pk.describe(top_bare, ' mm', 1e3, 'w/w_1')})")
    print(f"with dampers: {pk.describe(top_damped, ' mm', 1e3, 'w/w_1')}")
    for p in found[True]:
        if p is not top_damped:
            print(f"  other peak with dampers: {pk.describe(p, ' mm', 1e3, 'w/w_1')}")
    print(f"peak reduction: {100 * reduction:.1f} % (against the co-simulated bare peak: "
          f"{100 * (1 - top_damped.y / top_bare.y):.1f} %); wrote {out}/sweep.csv, sweep-peaks.csv, sweep.png")


def write_histories(out, kind, s, bare, plt):
    """CSV and PNG of a time-history run (with dampers: s; without: bare), and the reductions."""
    drift = np.diff(np.column_stack([np.zeros(len(s["t"])), s["X"]]), axis=1)
    cols = [s["t"], *drift.T, s["X"][:, -1], bare["X"][:, -1], s["A"][:, -1], bare["A"][:, -1], *s["F"].T, *s["E"].T]
    names = (["t"] + [f"drift{i + 1}" for i in range(drift.shape[1])]
             + ["roof_disp", "roof_disp_bare", "roof_acc", "roof_acc_bare"]
             + [f"force{j}" for j in range(s["F"].shape[1])] + [f"dissipated{j}" for j in range(s["E"].shape[1])])
    np.savetxt(out / f"{kind}.csv", np.column_stack(cols), delimiter=",", header=",".join(names), comments="")
    rms = lambda y: float(np.sqrt(np.mean(y ** 2)))  # noqa: E731
    peak = lambda y: float(np.max(np.abs(y)))  # noqa: E731
    bare_drift = np.diff(np.column_stack([np.zeros(len(bare["t"])), bare["X"]]), axis=1)
    less = lambda a, b: f"rms {1e3 * rms(b):.2f} -> {1e3 * rms(a):.2f} mm, {100 * (1 - rms(a) / rms(b)):.0f} % less"  # noqa: E731
    fig, ax = plt.subplots(5, 1, figsize=(9, 12), gridspec_kw={"height_ratios": [1.2, 1, 1, 1, 1]})
    # storey drifts: rms and peak per storey, without and with the dampers (a time history of
    # several storeys on top of each other hides the reduction)
    storeys = np.arange(1, drift.shape[1] + 1)
    for off, d, col, name in ((-0.2, bare_drift, "0.5", "without dampers"), (0.2, drift, "C0", "with TLD.fmu")):
        ax[0].bar(storeys + off, [1e3 * rms(d[:, i]) for i in range(d.shape[1])], 0.4, color=col,
                  label=f"{name}: rms")
        ax[0].plot(storeys + off, [1e3 * peak(d[:, i]) for i in range(d.shape[1])], "v", color=col, mec="k",
                   label=f"{name}: peak")
    for i in range(drift.shape[1]):
        r0, r1 = rms(bare_drift[:, i]), rms(drift[:, i])
        p0, p1 = peak(bare_drift[:, i]), peak(drift[:, i])
        ax[0].annotate(f"rms {100 * (1 - r1 / r0):.0f} % less\npeak {100 * (1 - p1 / p0):.0f} % less",
                       (storeys[i], 1e3 * max(p0, p1)), textcoords="offset points", xytext=(0, 8), ha="center",
                       fontsize=8)
    ax[0].set_xticks(storeys, [f"storey {i}" for i in storeys])
    ax[0].set_xlim(0.4, drift.shape[1] + 0.6)
    ax[0].set_ylim(0, 1.45e3 * max(peak(bare_drift), peak(drift)))
    ax[0].set_ylabel("storey drift [mm]")
    ax[0].legend(fontsize=7, ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.12), frameon=False)
    ax[0].set_title("storey drifts over the whole run", fontsize=9)
    t = s["t"]
    long = t[-1] > 60.0
    if long:
        # a long record's oscillations fill the panel solid: the running rms over 10 s shows how
        # the response evolves, and a 20 s window around the bare building's largest roof
        # displacement shows the oscillations themselves
        n = max(1, int(round(10.0 / (t[1] - t[0]))))

        def running(y):
            c = np.concatenate([[0.0], np.cumsum(y * y)])
            out = np.sqrt((c[n:] - c[:-n]) / n)
            return t[n // 2:n // 2 + len(out)], out

        for y0, y1, unit, scale, k in ((bare["X"][:, -1], s["X"][:, -1], "mm", 1e3, 1),
                                       (bare["A"][:, -1], s["A"][:, -1], "m/s2", 1.0, 3)):
            tt, r0 = running(y0)
            _, r1 = running(y1)
            ax[k].plot(tt, scale * r0, "k", lw=1, label=f"without dampers (rms {scale * rms(y0):.3g} {unit})")
            ax[k].plot(tt, scale * r1, "C0", lw=1.2, label=f"with TLD.fmu (rms {scale * rms(y1):.3g} {unit}, "
                                                           f"{100 * (1 - rms(y1) / rms(y0)):.0f} % less)")
            ax[k].set_ylim(bottom=0)
        ax[1].set_ylabel("roof displ.,\n10 s running rms [mm]")
        ax[3].set_ylabel("roof acc.,\n10 s running rms [m/s2]")
        i = int(np.argmax(np.abs(bare["X"][:, -1])))
        lo = max(0.0, min(t[i] - 10.0, t[-1] - 20.0))
        w = (t >= lo) & (t <= lo + 20.0)
        ax[1].axvspan(lo, lo + 20.0, color="C1", alpha=0.15, label="the window below")
        ax[2].plot(t[w], 1e3 * bare["X"][w, -1], "k", lw=0.8, label="without dampers")
        ax[2].plot(t[w], 1e3 * s["X"][w, -1], "C0", lw=0.8, label="with TLD.fmu")
        ax[2].set_xlim(lo, lo + 20.0)
        ax[2].set_ylabel("roof displ. [mm]")
        ax[2].set_title(f"{lo:.0f}-{lo + 20:.0f} s, around the bare building's largest roof displacement",
                        fontsize=9)
        ax[2].set_xlabel("t [s]")
        ax[4].plot(t, s["E"])
        ax[4].set_ylabel("dissipated by\nthe dampers [J]")
        ax[4].sharex(ax[1])
        ax[3].sharex(ax[1])
        for a_ in (ax[1], ax[3]):
            a_.tick_params(labelbottom=False)
    else:
        for a_ in ax[2:]:
            a_.sharex(ax[1])
        ax[1].plot(bare["t"], bare["X"][:, -1] * 1e3, "k", lw=0.6, label="without dampers")
        ax[1].plot(t, s["X"][:, -1] * 1e3, "C0", lw=0.6,
                   label=f"with TLD.fmu ({less(s['X'][:, -1], bare['X'][:, -1])})")
        ax[1].set_ylabel("roof displ. [mm]")
        ax[2].plot(bare["t"], bare["A"][:, -1], "k", lw=0.6, label="without dampers")
        ax[2].plot(t, s["A"][:, -1], "C0", lw=0.6,
                   label=f"with TLD.fmu (rms {rms(bare['A'][:, -1]):.3f} -> {rms(s['A'][:, -1]):.3f} m/s2, "
                         f"{100 * (1 - rms(s['A'][:, -1]) / rms(bare['A'][:, -1])):.0f} % less)")
        ax[2].set_ylabel("roof acc. [m/s2]")
        ax[3].plot(t, s["F"], lw=0.6)
        ax[3].set_ylabel("damper force [N]")
        ax[4].plot(t, s["E"])
        ax[4].set_ylabel("dissipated [J]")
        for a_ in ax[1:4]:
            a_.tick_params(labelbottom=False)
    for a_ in ax[1:4]:
        if a_.get_legend_handles_labels()[0]:
            a_.legend(loc="upper right", fontsize=7)
    ax[4].set_xlabel("t [s]")
    fig.suptitle(f"{len(s['X'][0])}-storey building under {'wind-like random floor forces' if kind == 'wind' else 'a ground-motion record'}: "
                 f"with and without TLD.fmu", fontsize=10)
    fig.tight_layout(); fig.savefig(out / f"{kind}.png", dpi=120)
    for label, f in (("rms", rms), ("peak", peak)):
        d, d0 = f(s["X"][:, -1]), f(bare["X"][:, -1])
        a, a0 = f(s["A"][:, -1]), f(bare["A"][:, -1])
        print(f"{label} roof displacement {d0 * 1e3:.3f} -> {d * 1e3:.3f} mm ({100 * (1 - d / d0):.1f} % less), "
              f"roof acceleration {a0:.4f} -> {a:.4f} m/s2 ({100 * (1 - a / a0):.1f} % less)")
    print(f"wrote {out}/{kind}.csv, {kind}.png")


if __name__ == "__main__":
    main()
