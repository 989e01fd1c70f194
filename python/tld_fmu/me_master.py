"""Building.fmu and TLD.fmu in Model Exchange, integrated as ONE ODE system by one solver
(scipy's DOP853): the host stacks both FMUs' continuous states and closes the loop
algebraically at every derivative evaluation, TLD's force -> Building's tld.force and
Building's tld.a -> TLD's base.a. There is no communication step, hence no coupling error: the
result agrees with the monolithic solution of the same equations to the solver's tolerance
(tests/python/test_model_exchange.py), where a co-simulation's agrees to O(h) or O(h^2)
(tests/python/test_cosim.py).

TLD's force depends on its states only (no feedthrough), Building's tld.a on its states and
tld.force: the loop has one order, force first, no algebraic iteration."""
from __future__ import annotations

import ctypes
import shutil

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model
from scipy.integrate import solve_ivp


class MeFmu:
    """One FMU instantiated for Model Exchange, initialised with `params`, in continuous-time
    mode; its states and derivatives as numpy arrays."""

    def __init__(self, path, params: dict, name: str):
        self.md = read_model_description(str(path))
        self.dir = extract(str(path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.types = {v.name: v.type for v in self.md.modelVariables}
        self.nx = self.md.numberOfContinuousStates
        self.fmu = FMU2Model(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.modelExchange.modelIdentifier,
                             instanceName=name)
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for k, v in params.items():
            if self.types[k] in ("Integer", "Enumeration"):
                self.fmu.setInteger([self.vr[k]], [int(v)])
            else:
                self.fmu.setReal([self.vr[k]], [float(v)])
        self.fmu.exitInitializationMode()
        while self.fmu.newDiscreteStates()[0]:
            pass
        self.fmu.enterContinuousTimeMode()
        self._x = np.zeros(self.nx)
        self._dx = np.zeros(self.nx)

    @staticmethod
    def _ptr(a):
        return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))

    def states(self):
        self.fmu.getContinuousStates(self._ptr(self._x), self.nx)
        return self._x.copy()

    def set_states(self, t, x):
        self.fmu.setTime(t)
        self._x[:] = x
        self.fmu.setContinuousStates(self._ptr(self._x), self.nx)

    def derivatives(self):
        self.fmu.getDerivatives(self._ptr(self._dx), self.nx)
        return self._dx.copy()

    def get(self, name):
        return self.fmu.getReal([self.vr[name]])[0]

    def set(self, name, value):
        self.fmu.setReal([self.vr[name]], [value])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)


def coupled(building: MeFmu, tld: MeFmu, t_eval, rtol=1e-10, atol=1e-14):
    """Integrate both FMUs as one system over `t_eval`; returns time, X (roof.x: the one-storey
    building's displacement relative to the ground) and x (slosh.x) at t_eval."""
    nb = building.nx

    def close_loop(t, y):
        building.set_states(t, y[:nb])
        tld.set_states(t, y[nb:])
        building.set("tld.force", tld.get("force"))
        tld.set("base.a", building.get("tld.a"))

    def rhs(t, y):
        close_loop(t, y)
        return np.concatenate([building.derivatives(), tld.derivatives()])

    y0 = np.concatenate([building.states(), tld.states()])
    sol = solve_ivp(rhs, (t_eval[0], t_eval[-1]), y0, method="DOP853", t_eval=t_eval,
                    rtol=rtol, atol=atol)
    assert sol.success, sol.message
    out = {"time": sol.t, "X": [], "x": []}
    for k, t in enumerate(sol.t):
        close_loop(t, sol.y[:, k])
        out["X"].append(building.get("roof.x"))
        out["x"].append(tld.get("slosh.x"))
    return {k: np.asarray(v) for k, v in out.items()}
