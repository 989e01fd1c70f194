"""Issue 27: S^2's impact impulses in a Model Exchange coupling, the figure and the numbers.
Building.fmu (1 storey, and 3) with TLD.fmu's SloshingSlamming model on the roof, both in
Model Exchange in one DOP853 (rtol 1e-10) with the TLD's impacts as state events
(python/tld_fmu/me_master.py), against the monolithic reference of the same equations with the
impacts handled exactly (python/tld_fmu/impacts.py), with and without the discrete connection
impact.impulse -> tld.impulse, tld.v.jump -> base.v.jump; and the total momentum across every
impact.

Writes out/me-impulse/me-impulse.png and report.md (--docs: docs/me-impulse.png and
docs/me-impulse.md). Needs the FMUs (scripts/package) and the project venv (scripts/pyenv).
Usage: .venv/bin/python scripts/me-impulse.py [--docs]"""
from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from tqdm import tqdm  # noqa: E402

from tld_fmu.me_impulse import SCENES, errors, run  # noqa: E402
from tld_fmu.paths import REPO  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--docs", action="store_true", help="write docs/me-impulse.{png,md}")
    args = ap.parse_args()
    out = REPO / "docs" if args.docs else REPO / "out" / "me-impulse"
    out.mkdir(parents=True, exist_ok=True)
    start = time.time()
    results = {}
    for scene in tqdm(sorted(SCENES), desc="scenes"):
        results[scene] = {k: run(scene, transfer=k) for k in (True, False)}
    fig, axes = plt.subplots(2, len(results), figsize=(6 * len(results), 7), squeeze=False)
    lines = ["# S^2's impact impulses in a Model Exchange coupling (issue 27)", "",
             f"`{' '.join(['.venv/bin/python', 'scripts/me-impulse.py'] + sys.argv[1:])}` on "
             f"{platform.node()} ({platform.machine()}, Python {platform.python_version()}), "
             f"{time.time() - start:.0f} s wall.", "",
             "Largest difference from the monolithic reference over the whole history, fraction "
             "of the reference's peak (one DOP853 at rtol 1e-10; reference DOP853 rtol 1e-12); "
             "momentum: largest |change of the total momentum| across an impact over that "
             "impact's impulse.", "",
             "| scene | transfer | events (reference) | roof.x | floor[1].x | slosh.x | impact.z | momentum |",
             "|---|---|---|---|---|---|---|---|"]
    for col, (scene, pair) in enumerate(results.items()):
        me, ref, ev = pair[True]
        for transfer, (m, _, e_) in ((True, pair[True]), (False, pair[False])):
            e = errors(m, ref)
            imp = np.diff(np.concatenate([[0.0], e_[:, 2]]))
            bal = np.max(np.abs(e_[:, 1] - e_[:, 0]) / np.abs(imp))
            lines.append(f"| {scene} | {'yes' if transfer else 'no (impulses lost)'} | "
                         f"{len(m['events'])} ({len(ref['events'])}) | "
                         + " | ".join(f"{e[k]:.1e}" for k in ("roof.x", "floor[1].x", "slosh.x", "impact.z"))
                         + f" | {bal:.1e} |")
            peak = np.max(np.abs(ref["u"][-1]))
            axes[0][col].semilogy(m["time"], np.abs(m["roof.x"] - ref["u"][-1]) / peak + 1e-17,
                                  label="with impact.impulse -> tld.impulse" if transfer
                                  else "without (force alone)")
        axes[0][col].set_title(f"{scene}: |roof.x - reference| / peak")
        axes[0][col].set_xlabel("t [s]")
        axes[0][col].legend()
        axes[1][col].step(np.concatenate([[0.0], ref["events"], [me["time"][-1]]]),
                          np.concatenate([[0.0], np.cumsum(ref["impulses"]),
                                          [np.sum(ref["impulses"])]]),
                          "k-", lw=1, where="post", label="reference: cumulative impulse")
        axes[1][col].plot(me["events"], ev[:, 2], "r.", ms=3, label="TLD.fmu impact.impulse")
        axes[1][col].set_xlabel("t [s]")
        axes[1][col].set_ylabel("N s")
        axes[1][col].legend()
    fig.tight_layout()
    fig.savefig(out / "me-impulse.png", dpi=110)
    (out / "me-impulse.md").write_text("\n".join(lines + ["", "![](me-impulse.png)", ""]))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
