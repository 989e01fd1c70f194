"""A structural master for TLD.fmu: an N-storey shear building (storey masses, stiffnesses and
Rayleigh damping from a TOML file) with TLD FMU instances on chosen floors, under a harmonic
ground-motion sweep, a ground-acceleration record, or band-limited wind-like random forces on the
floors, coupled by a fixed-step explicit scheme.

The building, the dampers and the coupling are python/tld_fmu/building.py; this file reads the
TOML (damper parameters by name; an enumeration's item by name, e.g. amplitude = "Tracked"), runs
the load case and writes the results.

    .venv/bin/python scripts/building.py scripts/examples/building.toml [--out out/building]

Writes a CSV and PNG plots (sweep: peak roof displacement with and without the dampers;
record and wind: storey drifts, roof displacement and acceleration with and without the dampers,
damper forces and energies)."""
import argparse
import sys
import tempfile
import tomllib
from pathlib import Path

import numpy as np

from tld_fmu.building import Building, harmonic_ground, simulate, wind_forces
from tld_fmu.paths import FMU, REPO


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("config")
    ap.add_argument("--out", default=str(REPO / "out" / "building"))
    ap.add_argument("--fmu", default=str(FMU))
    args = ap.parse_args(argv)
    cfg = tomllib.loads(Path(args.config).read_text())
    from fmpy import extract, read_model_description
    from tqdm import tqdm
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    md = read_model_description(args.fmu)
    unzipdir = extract(args.fmu, tempfile.mkdtemp())
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    load, h = cfg["load"], cfg["coupling"]["step"]
    derivs = bool(cfg["coupling"].get("derivatives", False))
    if load["kind"] == "harmonic":
        b = cfg["building"]
        w1 = Building(b["masses"], b["stiffnesses"], b["rayleigh"]).omega1
        Ag = load["ground_amplitude"]
        ratios = np.linspace(load["from"], load["to"], load["points"])
        rows = []
        for r in tqdm(ratios, desc="sweep"):
            w = r * w1
            ground = harmonic_ground(w, Ag)
            peak = []
            for damped in (False, True):
                s = simulate(cfg, unzipdir, md, ground, h, load["duration"], with_dampers=damped,
                             derivatives=derivs)
                tail = s["t"] > load["duration"] - 20.0
                peak.append(np.max(np.abs(s["X"][tail, -1])))
            rows.append((r, *peak))
        rows = np.array(rows)
        np.savetxt(out / "sweep.csv", rows, delimiter=",", header="w_over_w1,roof_peak_bare,roof_peak_damped", comments="")
        plt.figure(figsize=(7, 4))
        plt.plot(rows[:, 0], rows[:, 1] * 1e3, "k-o", ms=3, label="without dampers")
        plt.plot(rows[:, 0], rows[:, 2] * 1e3, "C0-o", ms=3, label="with TLD.fmu")
        plt.xlabel("w / w_1"); plt.ylabel("peak roof displacement [mm]"); plt.grid(alpha=0.3); plt.legend()
        plt.tight_layout(); plt.savefig(out / "sweep.png", dpi=120)
        print(f"peak roof displacement: {rows[:, 1].max() * 1e3:.3f} mm without, {rows[:, 2].max() * 1e3:.3f} mm "
              f"with dampers ({100 * (1 - rows[:, 2].max() / rows[:, 1].max()):.1f} % less); wrote {out}/sweep.csv, sweep.png")
    elif load["kind"] in ("record", "wind"):
        if load["kind"] == "record":
            rec = np.loadtxt(Path(args.config).parent / load["record"], delimiter=",")
            tt, aa = rec[:, 0], rec[:, 1]
            vv = np.concatenate([[0], np.cumsum((aa[1:] + aa[:-1]) / 2 * np.diff(tt))])
            xx = np.concatenate([[0], np.cumsum((vv[1:] + vv[:-1]) / 2 * np.diff(tt))])
            ground = lambda t: (np.interp(t, tt, aa), np.interp(t, tt, vv), np.interp(t, tt, xx))  # noqa: E731
            duration, forces = tt[-1], None
        else:
            duration = load["duration"]
            ground = lambda t: (0.0, 0.0, 0.0)  # noqa: E731
            # on the RK4 stage times of the master's grid: 2 samples per communication step
            _, forces = wind_forces(len(cfg["building"]["masses"]), h / 2, 2 * int(round(duration / h)),
                                    load["force_rms"],
                                    load.get("band", [0.02, 5.0]), load.get("corner", 0.1),
                                    load.get("coherence", 0.5), load.get("seed", 1))
        runs = {}
        for damped in tqdm((False, True), desc=load["kind"]):
            runs[damped] = simulate(cfg, unzipdir, md, ground, h, duration, with_dampers=damped,
                                   floor_forces=forces, derivatives=derivs)
        write_histories(out, load["kind"], runs[True], runs[False], plt)
    else:
        sys.exit(f"unknown load kind {load['kind']!r}: harmonic, record or wind")


def write_histories(out, kind, s, bare, plt):
    """CSV and PNG of a time-history run (with dampers: s; without: bare), and the reductions."""
    drift = np.diff(np.column_stack([np.zeros(len(s["t"])), s["X"]]), axis=1)
    cols = [s["t"], *drift.T, s["X"][:, -1], bare["X"][:, -1], s["A"][:, -1], bare["A"][:, -1], *s["F"].T, *s["E"].T]
    names = (["t"] + [f"drift{i + 1}" for i in range(drift.shape[1])]
             + ["roof_disp", "roof_disp_bare", "roof_acc", "roof_acc_bare"]
             + [f"force{j}" for j in range(s["F"].shape[1])] + [f"dissipated{j}" for j in range(s["E"].shape[1])])
    np.savetxt(out / f"{kind}.csv", np.column_stack(cols), delimiter=",", header=",".join(names), comments="")
    fig, ax = plt.subplots(5, 1, figsize=(8, 11), sharex=True)
    ax[0].plot(s["t"], drift * 1e3); ax[0].set_ylabel("storey drift [mm]")
    ax[1].plot(bare["t"], bare["X"][:, -1] * 1e3, "k", lw=0.6, label="without dampers")
    ax[1].plot(s["t"], s["X"][:, -1] * 1e3, "C0", lw=0.6, label="with TLD.fmu")
    ax[1].set_ylabel("roof displ. [mm]"); ax[1].legend(loc="upper right")
    ax[2].plot(bare["t"], bare["A"][:, -1], "k", lw=0.6); ax[2].plot(s["t"], s["A"][:, -1], "C0", lw=0.6)
    ax[2].set_ylabel("roof acc. [m/s2]")
    ax[3].plot(s["t"], s["F"]); ax[3].set_ylabel("damper force [N]")
    ax[4].plot(s["t"], s["E"]); ax[4].set_ylabel("dissipated [J]"); ax[4].set_xlabel("t [s]")
    fig.tight_layout(); fig.savefig(out / f"{kind}.png", dpi=120)
    rms = lambda y: float(np.sqrt(np.mean(y ** 2)))  # noqa: E731
    peak = lambda y: float(np.max(np.abs(y)))  # noqa: E731
    for label, f in (("rms", rms), ("peak", peak)):
        d, d0 = f(s["X"][:, -1]), f(bare["X"][:, -1])
        a, a0 = f(s["A"][:, -1]), f(bare["A"][:, -1])
        print(f"{label} roof displacement {d0 * 1e3:.3f} -> {d * 1e3:.3f} mm ({100 * (1 - d / d0):.1f} % less), "
              f"roof acceleration {a0:.4f} -> {a:.4f} m/s2 ({100 * (1 - a / a0):.1f} % less)")
    print(f"wrote {out}/{kind}.csv, {kind}.png")


if __name__ == "__main__":
    main()
