"""Helpers of scripts/design-example: a synthetic ground-motion record, and the PNG plots of
tld-design's response.csv.

usage: scripts/design_example.py record OUT.csv   (60 s of Kanai-Tajimi-filtered, enveloped
           white noise, seed 3, site 1.25 Hz / 0.6, peak 0.2 m/s^2, then 40 s at rest)
       scripts/design_example.py plot DIR         (DIR/response.csv -> DIR/response.png)
"""
import argparse

import numpy as np


def record(path):
    rng = np.random.default_rng(3)
    dt, strong, rest = 0.01, 60.0, 40.0
    n = int(round((strong + rest) / dt)) + 1
    t = dt * np.arange(n)
    w = rng.standard_normal(n) * (t <= strong)
    # Kanai-Tajimi: a_g = -(2 z w_g x' + w_g^2 x) for the filter x'' + 2 z w_g x' + w_g^2 x = w
    wg, z = 2 * np.pi * 1.25, 0.6
    x = v = 0.0
    a = np.zeros(n)
    for k in range(n):
        acc = w[k] - 2 * z * wg * v - wg * wg * x
        v += dt * acc
        x += dt * v
        a[k] = -(2 * z * wg * v + wg * wg * x)
    # Envelope: rise over 5 s, hold to 25 s, decay to the end of the strong part.
    env = np.clip(t / 5.0, 0, 1) * np.where(t < 25.0, 1.0, np.exp(-(t - 25.0) / 10.0))
    a *= env * (t <= strong)
    a *= 0.2 / np.abs(a).max()
    np.savetxt(path, np.column_stack([t, a]), delimiter=",", header="t [s], a_g [m/s^2]",
               fmt="%.6g")


def plot(folder):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    with open(f"{folder}/response.csv") as f:
        names = f.readline().strip().split(",")
    values = np.loadtxt(f"{folder}/response.csv", delimiter=",", skiprows=1)
    data = {n: values[:, k] for k, n in enumerate(names)}
    fig, ax = plt.subplots(figsize=(7.5, 4.0))
    if names[0] == "ratio":
        for name in names[1:]:
            ax.plot(data["ratio"], data[name], label=name,
                    color="black" if name == "bare" else None)
        ax.set_ylim(0, 1.3 * max(data[n].max() for n in names[2:]))
        ax.set_xlabel("forcing frequency / structure frequency")
        ax.set_ylabel("steady amplitude [m] (bare off the top)")
    else:
        ax.plot(data["t"], data["bare"], color="0.6", lw=0.6, label="bare")
        ax.plot(data["t"], data["design"], color="C0", lw=0.6, label="with the designed tanks")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("structure displacement [m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{folder}/response.png", dpi=110)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=["record", "plot"])
    parser.add_argument("path", help="the record to write, or the folder to plot")
    args = parser.parse_args()
    {"record": record, "plot": plot}[args.what](args.path)
