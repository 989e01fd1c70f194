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
    fig, grid = plt.subplots(nr, nc, figsize=(4.6 * nc + 1.2, 4.2 * nr), squeeze=False, layout="constrained")
    bare = bare_peak_amplification(zeta) if zeta else None
    small = len(tunings) > 6
    # one colour scale for all panels (they are compared with each other): one colour bar
    vals = [r["peak_amplification"] for r in peaks if not math.isnan(r["peak_amplification"])]
    vmin, vmax = (min(vals), max(vals)) if vals else (None, None)
    im = None
    for (row, combo), (col, amp) in itertools.product(enumerate(combos), enumerate(amps)):
        ax = grid[row][col]
        mine = [r for r in peaks if r["ground_amplitude"] == amp and tuple(r[a] for a in axes) == combo]
        ratios = sorted({r["mass_ratio"] for r in mine})
        Z = np.full((len(ratios), len(tunings)), np.nan)
        edge = np.zeros_like(Z, dtype=bool)
        flag = np.zeros_like(Z, dtype=bool)
        for r in mine:
            i, j = ratios.index(r["mass_ratio"]), tunings.index(r["tuning"])
            Z[i, j], edge[i, j] = r["peak_amplification"], not r["bounded"]
            flag[i, j] = bool(r.get("plausibility"))
        im = ax.imshow(Z, origin="lower", aspect="auto", cmap="viridis", vmin=vmin, vmax=vmax)
        # every other tuning labelled when there are many: the labels never touch
        ax.set_xticks(range(len(tunings)), [f"{t:g}" if not small or j % 2 == 0 else "" for j, t in enumerate(tunings)],
                      fontsize=8)
        ax.set_yticks(range(len(ratios)), [f"{100 * m:.2g} %" for m in ratios], fontsize=8)
        mid = (vmin + vmax) / 2 if vals else 0
        for i, j in itertools.product(range(len(ratios)), range(len(tunings))):
            text = f"{Z[i, j]:.0f}" + ("*" if edge[i, j] else "") + ("!" if flag[i, j] else "")
            if bare and not small:
                text += f"\n{100 * (1 - Z[i, j] / bare):.0f} % less"
            # dark text on the light (high) cells, white on the dark ones
            ax.text(j, i, text, ha="center", va="center", color="k" if Z[i, j] > mid else "w",
                    fontsize=7 if small else 8)
        if row == nr - 1:
            ax.set_xlabel(r"tuning $\omega_f / \omega_s$")
        if col == 0:
            ax.set_ylabel("mass ratio")
        what = ", ".join(f"{a} {v}" for a, v in zip(axes, combo))
        ax.set_title(f"{what}{chr(10) if what else ''}ground amplitude {amp * 1e3:g} mm", fontsize=10)
    if im is not None:
        fig.colorbar(im, ax=grid.ravel().tolist(), label="peak |X| / ground amplitude", shrink=0.6)
    head = f"{title}: " if title else ""
    ref = (f"without dampers {bare:.0f} (closed form 1/(2 zeta sqrt(1 - zeta^2)), zeta = {100 * zeta:g} %)"
           if bare else "")
    fig.suptitle(f"{head}peak amplification over frequency, refined; {ref}\n"
                 "* = at the edge of the frequency range (the peak may lie outside); "
                 "! = implausible (sweep.py's plausibility column)", fontsize=9)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)


def best_tuning(peaks: list[dict], path: Path, zeta: float | None = None, title: str = "", axes: list[str] = ()):
    """The design chart: a panel per combination of the varied parameters; in each, for each
    amplitude (a colour and a marker), the lowest refined peak amplification over the tunings
    against the mass ratio, and under it a table of the tuning that reaches it."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    amps = sorted({r["ground_amplitude"] for r in peaks if not math.isnan(r["ground_amplitude"])})
    combos = list(dict.fromkeys(tuple(r[a] for a in axes) for r in peaks))
    ratios = sorted({r["mass_ratio"] for r in peaks})
    fig, panels = plt.subplots(1, len(combos), figsize=(4.4 * len(combos) + 1.0, 4.2 + 0.22 * len(amps)),
                               sharey=True, squeeze=False)
    top, flagged = 0.0, False
    for ci, combo in enumerate(combos):
        ax = panels[0][ci]
        table = []
        for ai, amp in enumerate(amps):
            best = {}
            for r in peaks:
                if r["ground_amplitude"] == amp and tuple(r[a] for a in axes) == combo \
                        and not math.isnan(r["peak_amplification"]):
                    m = r["mass_ratio"]
                    if m not in best or r["peak_amplification"] < best[m]["peak_amplification"]:
                        best[m] = r
            table.append([f"{best[m]['tuning']:g}" if m in best else "-" for m in ratios])
            if not best:
                continue
            ms = sorted(best)
            ys = [best[m]["peak_amplification"] for m in ms]
            top = max(top, *ys)
            ax.plot([100 * m for m in ms], ys, ["o", "s", "^", "D"][ai % 4] + "-", color=f"C{ai}", ms=5,
                    label=f"ground amplitude {amp * 1e3:g} mm")
            bad = [m for m in ms if best[m].get("plausibility")]
            if bad:
                ax.plot([100 * m for m in bad], [best[m]["peak_amplification"] for m in bad], "x", color="C3",
                        ms=10, mew=2, label="implausible (sweep.py's plausibility column)" if not flagged else None)
                flagged = True
        what = ", ".join(f"{a} {v}" for a, v in zip(axes, combo))
        if what:
            ax.set_title(what, fontsize=10)
        ax.set_xticks([100 * m for m in ratios], [f"{100 * m:g}" for m in ratios])
        ax.set_xlabel("mass ratio [%]")
        ax.grid(alpha=0.3)
        # the best tuning of each point, as a table under the panel (labels on the points collide)
        tab = ax.table(cellText=table, rowLabels=[f"{amp * 1e3:g} mm" for amp in amps],
                       colLabels=[f"{100 * m:g} %" for m in ratios], cellLoc="center",
                       bbox=[0.0, -0.3 - 0.075 * len(amps), 1.0, 0.075 * (len(amps) + 1)])
        tab.auto_set_font_size(False)
        tab.set_fontsize(7)
        for ai in range(len(amps)):
            tab[ai + 1, -1].get_text().set_color(f"C{ai}")
    for ax in panels[0]:
        ax.set_ylim(0, 1.1 * top if top else None)
    panels[0][0].set_ylabel("peak |X| / ground amplitude at the best tuning")
    panels[0][-1].legend(fontsize=8, loc="upper right")
    bare = f"; without dampers {bare_peak_amplification(zeta):.0f}" if zeta else ""
    fig.suptitle(f"{title + ': ' if title else ''}the best tuning of each mass ratio, refined peaks{bare}\n"
                 "tables: the tuning omega_f / omega_s that reaches each point, per ground amplitude and mass ratio",
                 fontsize=10)
    fig.subplots_adjust(top=1 - 0.85 / fig.get_figheight(), wspace=0.3)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
