"""The plots of a design study (tld_fmu.study, scripts/sweep.py): heat maps of the refined peak
amplification over tuning x mass ratio, and the design chart of the best tuning per mass ratio."""
from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np


def bare_peak_amplification(zeta: float) -> float:
    """The bare one-mode structure's largest steady |X| / A_g under x_g = A_g sin(w t), closed
    form: max over r of r^2 / sqrt((1 - r^2)^2 + (2 zeta r)^2) = 1 / (2 zeta sqrt(1 - zeta^2))."""
    return 1.0 / (2.0 * zeta * math.sqrt(1.0 - zeta * zeta))


def heat_maps(peaks: list[dict], path: Path, zeta: float | None = None, title: str = "", axes: list[str] = ()):
    """Refined peak amplification over tuning x mass ratio, a panel per amplitude (columns) and
    per combination of the varied FMU parameters (rows); the bare structure's (closed form,
    damping ratio zeta) for reference."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    tunings = sorted({r["tuning"] for r in peaks})
    amps = sorted({r["ground_amplitude"] for r in peaks if not math.isnan(r["ground_amplitude"])})
    combos = list(dict.fromkeys(tuple(r[a] for a in axes) for r in peaks))
    nr, nc = max(1, len(combos)), max(1, len(amps))
    fig, grid = plt.subplots(nr, nc, figsize=(4.8 * nc, 4.4 * nr), squeeze=False)
    bare = bare_peak_amplification(zeta) if zeta else None
    small = len(tunings) > 6
    # one colour scale for all panels: they are compared with each other
    vals = [r["peak_amplification"] for r in peaks if not math.isnan(r["peak_amplification"])]
    vmin, vmax = (min(vals), max(vals)) if vals else (None, None)
    for (row, combo), (col, amp) in itertools.product(enumerate(combos), enumerate(amps)):
        ax = grid[row][col]
        mine = [r for r in peaks if r["ground_amplitude"] == amp and tuple(r[a] for a in axes) == combo]
        ratios = sorted({r["mass_ratio"] for r in mine})
        Z = np.full((len(ratios), len(tunings)), np.nan)
        edge = np.zeros_like(Z, dtype=bool)
        for r in mine:
            i, j = ratios.index(r["mass_ratio"]), tunings.index(r["tuning"])
            Z[i, j], edge[i, j] = r["peak_amplification"], not r["bounded"]
        im = ax.imshow(Z, origin="lower", aspect="auto", cmap="viridis", vmin=vmin, vmax=vmax)
        ax.set_xticks(range(len(tunings)), [f"{t:.3g}" for t in tunings], fontsize=7 if small else None,
                      rotation=90 if small else 0)
        ax.set_yticks(range(len(ratios)), [f"{100 * m:.2g} %" for m in ratios])
        for i, j in itertools.product(range(len(ratios)), range(len(tunings))):
            text = f"{Z[i, j]:.0f}" + ("*" if edge[i, j] else "")
            if bare and not small:
                text += f"\n{100 * (1 - Z[i, j] / bare):.0f} % less"
            ax.text(j, i, text, ha="center", va="center", color="w", fontsize=6 if small else 7)
        ax.set_xlabel(r"tuning $\omega_f / \omega_s$")
        ax.set_ylabel("mass ratio")
        what = ", ".join(f"{a} {v}" for a, v in zip(axes, combo))
        ax.set_title(f"{what}{', ' if what else ''}ground amplitude {amp * 1e3:g} mm", fontsize=10)
        fig.colorbar(im, ax=ax, label="peak |X| / ground amplitude")
    head = f"{title}: " if title else ""
    ref = (f"without dampers {bare:.0f} (closed form 1/(2 zeta sqrt(1 - zeta^2)), zeta = {100 * zeta:g} %)"
           if bare else "")
    fig.suptitle(f"{head}peak amplification over frequency, refined; {ref}\n"
                 "* = at the edge of the frequency range (the peak may lie outside)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def best_tuning(peaks: list[dict], path: Path, zeta: float | None = None, title: str = "", axes: list[str] = ()):
    """The design chart: for each combination of the varied parameters (a line style) and each
    amplitude (a colour), the lowest refined peak amplification over the tunings against the
    mass ratio, labelled with the tuning that reaches it."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    amps = sorted({r["ground_amplitude"] for r in peaks if not math.isnan(r["ground_amplitude"])})
    combos = list(dict.fromkeys(tuple(r[a] for a in axes) for r in peaks))
    fig, ax = plt.subplots(figsize=(8, 5))
    for (ci, combo), (ai, amp) in itertools.product(enumerate(combos), enumerate(amps)):
        best = {}
        for r in peaks:
            if r["ground_amplitude"] == amp and tuple(r[a] for a in axes) == combo \
                    and not math.isnan(r["peak_amplification"]):
                m = r["mass_ratio"]
                if m not in best or r["peak_amplification"] < best[m]["peak_amplification"]:
                    best[m] = r
        if not best:
            continue
        ms = sorted(best)
        what = ", ".join(f"{a} {v}" for a, v in zip(axes, combo))
        ax.plot([100 * m for m in ms], [best[m]["peak_amplification"] for m in ms], "o",
                ls=["-", "--", ":", "-."][ci % 4], color=f"C{ai}",
                label=f"{what}{', ' if what else ''}{amp * 1e3:g} mm")
        for m in ms:
            ax.annotate(f"{best[m]['tuning']:.3g}", (100 * m, best[m]["peak_amplification"]), fontsize=6,
                        textcoords="offset points", xytext=(3, 3), color=f"C{ai}")
    ax.set_xlabel("mass ratio [%]")
    ax.set_ylabel("peak |X| / ground amplitude at the best tuning")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=max(1, len(combos)))
    bare = f"; without dampers {bare_peak_amplification(zeta):.0f}" if zeta else ""
    ax.set_title(f"{title + ': ' if title else ''}the best tuning of each mass ratio (numbers: omega_f / omega_s), "
                 f"refined peaks{bare}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
