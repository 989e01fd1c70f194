# TLD.fmu in Ecos (ecospy): the scene of docs/USING.md; inputs set between steps are passed on just
# before the next fmi2DoStep. Needs the `tbb` wheel (libtbb.so.12) and `unzip` on PATH.
# From the repository root, after scripts/package:  .venv/bin/python examples/ecospy_scene.py [seconds]
import ctypes
import os
import shutil
import sys

import numpy as np

fmu = os.path.abspath(os.environ.get("TLD_FMU_PATH", "target/fmu/TLD.fmu"))
if not os.path.isfile(fmu):   # Ecos would only say "Unable to resolve model"
    sys.exit(f"{fmu} not found: run scripts/package in the repository root, or set TLD_FMU_PATH")
if not shutil.which("unzip"):  # Ecos unpacks the FMU with it, and crashes without it
    sys.exit("Ecos needs the `unzip` command on PATH")
ctypes.CDLL(f"{sys.prefix}/lib/libtbb.so.12", mode=ctypes.RTLD_GLOBAL)  # from the tbb wheel
from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure  # noqa: E402

T = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0    # duration [s]
dt, w, A = 0.01, 5.64, 0.005     # step [s]; forcing [rad/s], near omega_f; base amplitude [m]
n = round(T / dt)
a = -w**2 * A * np.sin(w * np.arange(n) * dt)   # base.a held over step k [m/s2]

EcosLib.set_log_level("warn")
ss = EcosSimulationStructure()
ss.add_model("tld", fmu)
# Ecos cannot set Enumeration variables: the Integer alias damping_id sets `damping`.
# It also ignores FMI errors: a value the FMU refuses keeps its start value (read it back).
ss.add_parameter_set("p", {"tld::zeta": 0.02, "tld::damping_id": 1})   # 1 = Constant
sim = EcosSimulation(step_size=dt, structure=ss)
sim.init(parameter_set="p")
x, f = np.empty(n), np.empty(n)
for k in range(n):
    sim.set_real("tld::base.a", a[k])
    sim.step()
    x[k], f[k] = sim.get_real("tld::slosh.x"), sim.get_real("tld::force")
sim.terminate()
sim.free()
ss.free()
print(f"ecos: {n} steps, max|slosh.x| = {np.max(np.abs(x)):.9g} m, "
      f"max|force| = {np.max(np.abs(f)):.9g} N, force(T) = {f[-1]:.9g} N")
