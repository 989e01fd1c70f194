"""Plots and the report of tld-calibrate's results (scripts/calibrate, scripts/calibration-report).

tld-calibrate writes the samples with the fit (`--csv`: a `# phi=...` comment line, then
lambda,kappa_data,kappa_model,zeta_data,zeta_model,kappa_nsd,zeta_nsd) and, for the shallow-water
source, every swept point (`--sweeps`: lambda,direction,ratio,x,phase,x_peak,zeta_eq,cycles,settled,jump; jump = 1 on
the last point before a sweep's jump, as tld-calibrate finds it) and, with `--curve`, the fitted
model and the NSD laws on a fine grid of Lambda (lambda,kappa_model,zeta_model,kappa_nsd,zeta_nsd),
drawn as the plot's curves.

kappa is the jump frequency over w_f as docs/MODEL.md defines it: where a slow up-sweep falls
off the upper branch of the response. The shallow-water source measures it where the up-sweep's
response is in quadrature with the excitation (that point, the top of the upper branch when the
sweep jumps; the equivalent linear resonance when it does not).
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np


def read_fit(path: Path) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    """The fit (the comment line) and the sample columns of a --csv file."""
    with open(path) as fh:
        fit = {k: float(v) for k, v in
               (kv.split("=", 1) for kv in fh.readline().lstrip("# ").strip().split(","))}
        rows = list(csv.DictReader(fh))
    cols = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]} if rows else {}
    return fit, cols


def read_sweeps(path: Path) -> list[dict]:
    """The swept points of a --sweeps file."""
    with open(path) as fh:
        return [{**r, **{k: float(r[k]) for k in ("lambda", "ratio", "x", "phase", "x_peak", "zeta_eq")},
                 "cycles": int(r["cycles"]), "settled": r["settled"] == "1",
                 "jump": r["jump"] == "1"}
                for r in csv.DictReader(fh)]


def read_curve(path: Path) -> dict[str, np.ndarray]:
    """The columns of a --curve file."""
    data = np.genfromtxt(path, delimiter=",", names=True)
    return {k: data[k] for k in data.dtype.names}


def plot(csv_path: Path, png: Path, title: str, sweeps_path: Path | None = None,
         length: float | None = None, curve_path: Path | None = None) -> None:
    """kappa(Lambda) and zeta(Lambda): the data, the fitted model and the NSD laws (smooth
    curves from curve_path; else lines through the samples); with the sweeps, a third panel with
    the swept response curves (amplitude over the tank half-length)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fit, d = read_fit(csv_path)
    sweeps = read_sweeps(sweeps_path) if sweeps_path else []
    panels = 3 if sweeps else 2
    fig, axes = plt.subplots(1, panels, figsize=(5.5 * panels, 4.5))
    lam = d["lambda"]
    data_label = "shallow-water sweeps" if sweeps else "data"

    curve = read_curve(curve_path) if curve_path and Path(curve_path).exists() else None
    x = curve["lambda"] if curve is not None else lam

    def fit_panel(ax, draw, quantity, model_label, nsd_label, ylabel, **grid):
        """`quantity` over Lambda, drawn by the axes' method `draw`: data, fitted model, NSD law."""
        draw = getattr(ax, draw)
        src = curve if curve is not None else d
        draw(lam, d[f"{quantity}_data"], "o", label=data_label)
        draw(x, src[f"{quantity}_model"], "-", label=model_label)
        draw(x, src[f"{quantity}_nsd"], "k--", lw=1, label=nsd_label)
        ax.set_xlabel("Lambda = A_e / a")
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3, **grid)

    fit_panel(axes[0], "semilogx", "kappa",
              f"Nonlinear model fitted: phi = {fit['phi']:.3g}, eta = {fit['eta']:.3g}",
              "NSD law (fit of experiments)", "kappa = jump frequency / w_f")
    fit_panel(axes[1], "loglog", "zeta", f"zeta = {fit['nsd_c']:.3g} Lambda^{fit['nsd_p']:.3g} fitted",
              "NSD law: 0.5 Lambda^0.35", "zeta = damping ratio",
              which="both")
    if sweeps:
        a3 = axes[2]
        half = (length or 1.0) / 2
        for k, lv in enumerate(sorted({p["lambda"] for p in sweeps})):
            colour = f"C{k % 10}"
            # up-sweeps a line, down-sweeps open circles: where the two coincide (no jump) the
            # circles sit on the line and stay visible
            for direction, style in (("up", dict(ls="-", lw=1)), ("down", dict(ls="none", marker="o", ms=3, mfc="none",
                                                                                mew=0.6))):
                pts = [p for p in sweeps if p["lambda"] == lv and p["direction"] == direction]
                pts.sort(key=lambda p: p["ratio"])
                a3.semilogy([p["ratio"] for p in pts], [p["x"] / half for p in pts], color=colour,
                            label=f"Lambda = {lv:.3g}" if direction == "up" else None, **style)
        a3.set_xlabel("w / w_f")
        a3.set_ylabel("first harmonic of slosh.x / (a/2)")
        a3.set_title("up-sweeps: lines; down-sweeps: open circles (on the line where no jump)", fontsize=8)
        a3.legend(fontsize=7)
        a3.grid(alpha=0.3, which="both")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def table(csv_path: Path, sweeps_path: Path) -> str:
    """The report's markdown table for one tank: per Lambda the shallow-water kappa and zeta,
    the NSD laws' and the fitted Nonlinear model's, and the jumps of the sweeps."""
    fit, d = read_fit(csv_path)
    sweeps = read_sweeps(sweeps_path)
    lines = ["| Lambda | kappa SWE | kappa NSD | kappa fitted model | zeta SWE | zeta NSD "
             "| up-sweep jump down | down-sweep jump up | unsettled points |",
             "|---|---|---|---|---|---|---|---|---|"]
    for i, lv in enumerate(d["lambda"]):
        def jump(direction: str) -> str:
            pts = [p for p in sweeps if p["lambda"] == lv and p["direction"] == direction]
            at = next((k for k, p in enumerate(pts) if p["jump"]), None)
            if at is None or at + 1 >= len(pts):
                return "none"
            p, q = pts[at], pts[at + 1]
            change = max(p["x"] / q["x"], q["x"] / p["x"])
            return f"{p['ratio']:.2f} -> {q['ratio']:.2f} (x{change:.1f})"
        unsettled = sum(1 for p in sweeps if p["lambda"] == lv and not p["settled"])
        lines.append(
            f"| {lv:.4g} | {d['kappa_data'][i]:.3f} | {d['kappa_nsd'][i]:.3f} "
            f"| {d['kappa_model'][i]:.3f} | {d['zeta_data'][i]:.4f} | {d['zeta_nsd'][i]:.4f} "
            f"| {jump('up')} | {jump('down')} | {unsettled} |")
    lines.append("")
    lines.append(f"Fitted to these points: phi = {fit['phi']:.4g}, eta = {fit['eta']:.4g}, "
                 f"nsd.c = {fit['nsd_c']:.4g}, nsd.p = {fit['nsd_p']:.4g} (the NSD laws' defaults: "
                 f"nsd.c = 0.5, nsd.p = 0.35); largest kappa residual of the fitted model "
                 f"{100 * fit['worst_kappa_residual']:.1f} %; w_f = {fit['omega_f']:.4f} rad/s.")
    return "\n".join(lines)
