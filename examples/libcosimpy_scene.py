# TLD.fmu in libcosim (libcosimpy): the scene of docs/USING.md as a fixed-step execution; the input goes
# in through an override manipulator before each step, the outputs come from a last-value observer.
# From the repository root, after scripts/package:  .venv/bin/python examples/libcosimpy_scene.py [seconds]
import os
import sys

import numpy as np
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimManipulator import CosimManipulator
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

fmu = os.path.abspath(os.environ.get("TLD_FMU_PATH", "target/fmu/TLD.fmu"))
if not os.path.isfile(fmu):   # libcosim itself would crash (SIGSEGV) without a word
    sys.exit(f"{fmu} not found: run scripts/package in the repository root, or set TLD_FMU_PATH")
T = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0    # duration [s]
dt, w, A = 0.01, 5.64, 0.005     # step [s]; forcing [rad/s], near omega_f; base amplitude [m]
n = round(T / dt)
a = -w**2 * A * np.sin(w * np.arange(n) * dt)   # base.a held over step k [m/s2]

log_output_level(CosimLogLevel.WARNING)         # libcosim traces every FMI call otherwise
ex = CosimExecution.from_step_size(round(dt * 1e9))          # libcosim counts nanoseconds
i = ex.add_local_slave(CosimLocalSlave(fmu_path=fmu, instance_name="tld"))
vr = {v.name.decode(): v.reference for v in ex.slave_variables(i)}   # from the modelDescription
# libcosim cannot set Enumeration variables (it warns that it ignores model, damping, amplitude
# and solver): the Integer alias damping_id sets `damping`
ex.integer_initial_value(i, vr["damping_id"], 1)             # 1 = Constant
ex.real_initial_value(i, vr["zeta"], 0.02)
man, obs = CosimManipulator.create_override(), CosimObserver.create_last_value()
ex.add_manipulator(man)
ex.add_observer(obs)
x, f = np.empty(n), np.empty(n)
for k in range(n):
    man.slave_real_values(i, [vr["base.a"]], [a[k]])
    ex.step(1)
    x[k], f[k] = obs.last_real_values(i, [vr["slosh.x"], vr["force"]])
print(f"libcosim: {n} steps, max|slosh.x| = {np.max(np.abs(x)):.9g} m, "
      f"max|force| = {np.max(np.abs(f)):.9g} N, force(T) = {f[-1]:.9g} N")
