"""Building.fmu and TLD.fmu coupled as the model descriptions say (Building.tld.a/v/x ->
TLD.base.a/v/x, TLD.force -> Building.tld.force, TLD.mass.inactive -> Building.tld.mass), both
through fmpy, against the monolithic linear system integrated by scipy (DOP853, rtol 1e-11):
one storey carrying the Linear single-mode damper with constant damping, under harmonic ground
motion near resonance. Building.fmu steps exactly, so the coupled run's error is the coupling's
alone: first order in the communication step with held inputs (halving the step halves it).

The damper's mode (mass.slosh, omega_f) and inactive mass are read from TLD.fmu's calculated
parameters; the building's damping is rebuilt from its definition (one storey: c = 2 zeta w M)."""
from __future__ import annotations

import shutil
import tempfile

import numpy as np
import pytest
from scipy.integrate import solve_ivp

M, K, ZETA, ZETA_F, AG, T_END = 168.0, 5342.0, 0.02, 0.05, 0.05, 20.0


class Fmu:
    def __init__(self, path, identifier):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave
        md = read_model_description(str(path))
        self.dir = tempfile.mkdtemp(prefix=f"{identifier}_")
        extract(str(path), self.dir)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=self.dir, modelIdentifier=identifier,
                             instanceName=identifier)
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()

    def set(self, **values):
        names = [k.replace("__", ".") for k in values]
        self.fmu.setReal([self.vr[n] for n in names], list(values.values()))

    def get(self, *names):
        return self.fmu.getReal([self.vr[n] for n in names])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)


def coupled(fmu_path, building_path, h):
    tld = Fmu(fmu_path, "TLD")
    tld.fmu.setInteger([tld.vr["model"], tld.vr["modes"], tld.vr["damping"]], [1, 1, 1])
    tld.set(zeta=ZETA_F)
    tld.fmu.exitInitializationMode()
    m1, wf, inactive = tld.get("mass.slosh", "omega_f", "mass.inactive")
    bld = Fmu(building_path, "Building")
    bld.fmu.setReal([bld.vr["storey[1].mass"], bld.vr["storey[1].stiffness"], bld.vr["damping.zeta"],
                     bld.vr["tld.mass"]], [M, K, ZETA, inactive])
    bld.fmu.exitInitializationMode()
    w = np.sqrt(K / (M + inactive))
    t, roof = 0.0, [0.0]
    for _ in range(int(round(T_END / h))):
        bld.set(ground__a=AG * np.sin(w * t), tld__force=tld.get("force")[0])
        a, v, x = bld.get("tld.a", "tld.v", "tld.x")
        tld.set(base__a=a, base__v=v, base__x=x)
        bld.fmu.doStep(t, h)
        tld.fmu.doStep(t, h)
        t += h
        roof.append(bld.get("roof.x")[0])
    tld.close()
    bld.close()
    return np.array(roof), (m1, wf, inactive, w)


def monolithic(m1, wf, inactive, w, h):
    mt = M + inactive
    c = 2 * ZETA * w * mt

    def rhs(t, y):
        u, du, x, dx = y
        ag = AG * np.sin(w * t)
        force = m1 * (2 * ZETA_F * wf * dx + wf ** 2 * x)
        a_abs = (force - c * du - K * u) / mt
        return [du, a_abs - ag, dx, -a_abs - 2 * ZETA_F * wf * dx - wf ** 2 * x]

    times = np.arange(int(round(T_END / h)) + 1) * h
    sol = solve_ivp(rhs, (0, times[-1]), [0, 0, 0, 0], t_eval=times, method="DOP853",
                    rtol=1e-11, atol=1e-14)
    assert sol.success
    return sol.y[0]


def test_coupled_pair_converges_to_the_monolithic_system(fmu_path, building_path):
    errors = []
    for h in (4e-3, 2e-3):
        roof, params = coupled(fmu_path, building_path, h)
        ref = monolithic(*params, h)
        errors.append(np.abs(roof - ref).max() / np.abs(ref).max())
    print(f"coupled vs monolithic, largest roof error over {T_END} s: "
          f"{errors[0]:.2e} at 4 ms, {errors[1]:.2e} at 2 ms")
    assert errors[1] < 1e-2
    assert 1.6 < errors[0] / errors[1] < 2.4, "first order in the communication step"
