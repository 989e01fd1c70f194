# TLD.fmu in fmpy: harmonic base motion near resonance, 0.01 s steps (the scene of docs/USING.md).
# From the repository root, after scripts/package:  .venv/bin/python examples/fmpy_scene.py [seconds]
import os
import sys

import numpy as np
from fmpy import simulate_fmu

fmu = os.environ.get("TLD_FMU_PATH", "target/fmu/TLD.fmu")   # where scripts/package writes it
if not os.path.isfile(fmu):
    sys.exit(f"{fmu} not found: run scripts/package in the repository root, or set TLD_FMU_PATH")
T = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0    # duration [s]
dt, w, A = 0.01, 5.64, 0.005     # step [s]; forcing [rad/s], near omega_f; base amplitude [m]

t = np.arange(round(T / dt) + 1) * dt
a = -w**2 * A * np.sin(w * t)    # base.a [m/s2]: the tank moves A sin(w t)
u = np.array(list(zip(t, a)), dtype=[("time", float), ("base.a", float)])
# fmpy warns that the inputs base.v and base.x are not in `u`: they stay at 0, which is right
# here (base.x is never used; base.v only refines the amplitude estimate of amplitude = Tracked,
# which then works from base.a alone, and damping = Constant below uses no amplitude at all).
res = simulate_fmu(fmu, stop_time=T, output_interval=dt, input=u,
                   start_values={"zeta": 0.02, "damping": 1},   # damping 1 = Constant
                   output=["slosh.x", "force"])
x, f = res["slosh.x"][1:], res["force"][1:]   # after each step (row 0 is t = 0)
print(f"fmpy: {len(x)} steps, max|slosh.x| = {np.max(np.abs(x)):.9g} m, "
      f"max|force| = {np.max(np.abs(f)):.9g} N, force(T) = {f[-1]:.9g} N")
