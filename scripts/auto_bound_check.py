"""Auto's bound on |x| over a linear step (src/model/auto.rs `linear_step`, docs/MUTANTS.md,
auto.rs 54:89): is the response from rest of x'' + 2 zeta w x' + w^2 x = -p(t),
p = a0 + a1 t + a2 t^2/2, within 2 a_max/w^2 over [0, h] (a_max = |a0| + h (|a1| + h |a2|/2))?
w = 1 by scaling time. The response in closed form (the particular solution of the quadratic
input and the damped transient that starts it from rest), sampled at 801 points per step, for
random inputs and steps per damping range. Prints the largest ratio |x| w^2 / (2 a_max) found:
at most 1 means the bound's static term alone covers the forced motion.

usage: .venv/bin/python scripts/auto_bound_check.py [--samples N] [--seed S]
(numpy; about 30 s at the default 200,000 samples per damping range)"""
import argparse

import numpy as np
from tqdm import tqdm

POINTS = 801  # samples of each step's response


def largest_ratio(rng, n, zmax, bar):
    """The largest |x| / (2 a_max / w^2) over n random steps with zeta in [0, zmax)."""
    z = rng.uniform(0, zmax, n)
    h = 10 ** rng.uniform(-2, 1.7, n)
    a = rng.normal(size=(3, n)) * 10 ** rng.uniform(-2, 2, (3, n))
    a[rng.random((3, n)) < 0.3] = 0
    a0, a1, a2 = a
    amax = np.abs(a0) + h * (np.abs(a1) + 0.5 * h * np.abs(a2))
    wd = np.sqrt(1 - z * z)

    def xp(t):  # the particular solution of the quadratic input
        return -(a0 + a1 * t + a2 * t * t / 2) + a2 + 2 * z * (a1 + a2 * t) - 4 * z * z * a2

    def vp(t):
        return -(a1 + a2 * t) + 2 * z * a2

    c1 = -xp(0)
    c2 = (-vp(0) + z * c1) / wd
    m = np.zeros(n)
    for f in np.linspace(0, 1, POINTS):
        t = f * h
        y = xp(t) + np.exp(-z * t) * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t))
        m = np.maximum(m, np.abs(y))
        bar.update(1)
    r = np.where(amax > 0, m / np.where(amax > 0, 2 * amax, 1), 0)
    k = int(np.argmax(r))
    return r[k], h[k], z[k], (a0[k], a1[k], a2[k])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=200_000, help="random steps per damping range")
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    ranges = [0.3, 1.0]
    with tqdm(total=len(ranges) * POINTS, desc="response samples", unit="pt") as bar:
        found = [(zmax, largest_ratio(rng, args.samples, zmax, bar)) for zmax in ranges]
    for zmax, (r, h, z, (a0, a1, a2)) in found:
        print(f"zeta <= {zmax}: largest |x| / (2 a_max / w^2) = {r:.6f} at h w = {h:.3g}, "
              f"zeta {z:.3g}, a = {a0:.3g}, {a1:.3g}, {a2:.3g}")


if __name__ == "__main__":
    main()
