"""The work-precision plots: one figure per scene, native runs on top and the Python window
below, one column per communication step."""
from __future__ import annotations

from pathlib import Path

from .formats import dt_label


def plots(scenes, rows, outdir: Path, tag):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    files = []
    style = {
        ("TLD.fmu", "DormandPrince45"): dict(color="C0", marker="o"),
        ("TLD.fmu", "RK4"): dict(color="C1", marker="s"),
        ("TLD.fmu", "RK5"): dict(color="darkgoldenrod", marker="p"),
        ("TLD.fmu", "RK8"): dict(color="teal", marker="h"),
        ("C FMU", "DP45"): dict(color="navy", marker="o", ls=":", mfc="none", ms=9),
        ("C FMU", "RK4"): dict(color="saddlebrown", marker="s", ls=":", mfc="none", ms=9),
        ("C FMU, energies", "DP45"): dict(color="navy", marker="P", ls="-.", mfc="none", ms=9),
        ("C FMU, energies", "RK4"): dict(color="saddlebrown", marker="X", ls="-.", mfc="none",
                                         ms=9),
        ("C FMU, clang", "DP45"): dict(color="slateblue", marker="d", ls=(0, (1, 3)), mfc="none",
                                       ms=8),
        ("C FMU, clang", "RK4"): dict(color="peru", marker="d", ls=(0, (1, 3)), mfc="none", ms=8),
        ("C FMU, Rust port", "DP45"): dict(color="darkcyan", marker="v", ls=(0, (3, 1, 1, 1)),
                                           mfc="none", ms=8),
        ("C FMU, Rust port", "RK4"): dict(color="chocolate", marker="v", ls=(0, (3, 1, 1, 1)),
                                          mfc="none", ms=8),
        ("C FMU, Rust port, energies", "DP45"): dict(color="darkcyan", marker="^",
                                                     ls=(0, (5, 2)), mfc="none", ms=8),
        ("C FMU, Rust port, energies", "RK4"): dict(color="chocolate", marker="^",
                                                    ls=(0, (5, 2)), mfc="none", ms=8),
        ("Rust baseline", "DP45"): dict(color="C0", marker="o", ls="--", mfc="none"),
        ("Rust baseline", "RK4"): dict(color="C1", marker="s", ls="--", mfc="none"),
        ("scipy solve_ivp", "DOP853"): dict(color="C2", marker="^"),
        ("scipy solve_ivp", "LSODA"): dict(color="C4", marker="v"),
        ("pythonfmu", "RK4"): dict(color="C3", marker="D"),
        ("Rust diagnostic", "RK4 over (t+dt)-t"): dict(color="0.5", marker="x", ls="none", ms=9),
        ("TLD.fmu via fmpy", "default"): dict(color="k", marker="*", ms=12, ls="none",
                                              mfc="none"),
    }
    extra = ["C5", "C6", "C8", "C9"]
    for sc in scenes:
        dts = sc.dts
        fig, axes = plt.subplots(2, len(dts), figsize=(4.2 * len(dts), 8.2), squeeze=False)
        for j, dt in enumerate(dts):
            for i, window in enumerate((False, True)):
                ax = axes[i][j]
                rs = [r for r in rows if r["scene"] == sc.key and r["dt"] == dt
                      and r["status"] == "ok"]
                if window:
                    # Python side: FMU errors recomputed on the same window
                    rs = [r for r in rs if r["window"] or r["impl"] == "TLD.fmu"]
                else:
                    rs = [r for r in rs if not r["window"]]
                groups = {}
                for r in rs:
                    groups.setdefault((r["impl"], r["method"]), []).append(r)
                k_extra = 0
                for (impl, method), g in sorted(groups.items()):
                    ekey = "err_win" if window and impl == "TLD.fmu" else "err"
                    pts = sorted((max(r[ekey], 1e-17), r["ns_step"]) for r in g)
                    if (impl, method) in style:
                        st = dict(style[(impl, method)])
                    elif method in ("default", "defaults"):
                        st = dict(color="k", marker="*", ms=14, ls="none")
                    else:
                        st = dict(color=extra[k_extra % len(extra)], marker="P")
                        k_extra += 1
                    label = f"{impl} {method}"
                    ax.loglog([p[0] for p in pts], [p[1] for p in pts], label=label,
                              **{"lw": 1.2, "ms": 5, **st})
                ax.grid(True, which="both", alpha=0.3)
                ax.set_title(f"dt = {dt_label(dt)}" + (" (Python window)" if window else ""),
                             fontsize=9)
                ax.set_xlabel("error  max|x - x_ref| / max|x_ref|", fontsize=8)
                if j == 0:
                    ax.set_ylabel("ns per doStep (median)", fontsize=8)
                ax.tick_params(labelsize=7)
                if j == len(dts) - 1:
                    ax.legend(fontsize=6.5, loc="best")
        fig.suptitle(f"Scene {sc.title}: work-precision\ntop: native host, error over the "
                     "whole history; bottom: Python baselines and TLD.fmu, error over the Python "
                     "window", fontsize=10)
        fig.tight_layout()
        f = outdir / f"{sc.key}.png"
        fig.savefig(f, dpi=90)
        plt.close(fig)
        files.append(f)
    return files
