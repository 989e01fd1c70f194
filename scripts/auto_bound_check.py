"""Auto's bound on |x| over a linear step (src/model/auto.rs `linear_step`, docs/MUTANTS.md,
auto.rs 54:89): is the response from rest of x'' + 2 zeta w x' + w^2 x = -p(t),
p = a0 + a1 t + a2 t^2/2, within 2 a_max/w^2 over [0, h] (a_max = |a0| + h (|a1| + h |a2|/2))?
w = 1 by scaling time. The response in closed form (the particular solution of the quadratic
input and the damped transient that starts it from rest), sampled at 801 points per step, for
200,000 random inputs and steps per damping range. Run: .venv/bin/python scripts/auto_bound_check.py
(numpy; about 30 s). Prints the largest ratio |x| w^2 / (2 a_max) found: at most 1 means the
bound's static term alone covers the forced motion."""
import numpy as np
rng = np.random.default_rng(7)
N = 200000
for zmax in [0.3, 1.0]:
    z = rng.uniform(0, zmax, N); h = 10 ** rng.uniform(-2, 1.7, N)
    a = rng.normal(size=(3, N)) * 10 ** rng.uniform(-2, 2, (3, N))
    mask = rng.random((3, N)) < 0.3; a[mask] = 0
    a0, a1, a2 = a
    amax = np.abs(a0) + h * (np.abs(a1) + 0.5 * h * np.abs(a2))
    s = z; wd = np.sqrt(1 - z * z)
    xp = lambda t: -(a0 + a1 * t + a2 * t * t / 2) + a2 + 2 * s * (a1 + a2 * t) - 4 * s * s * a2
    vp = lambda t: -(a1 + a2 * t) + 2 * s * a2
    c1 = -xp(0); c2 = (-vp(0) + s * c1) / wd
    m = np.zeros(N)
    for f in np.linspace(0, 1, 801):
        t = f * h
        y = xp(t) + np.exp(-s * t) * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t))
        m = np.maximum(m, np.abs(y))
    r = np.where(amax > 0, m / np.where(amax > 0, 2 * amax, 1), 0)
    k = np.argmax(r)
    print(f"zeta <= {zmax}: largest |x| / (2 a_max / w^2) = {r[k]:.6f} at h w = {h[k]:.3g}, zeta {z[k]:.3g}, a = {a0[k]:.3g}, {a1[k]:.3g}, {a2[k]:.3g}")
