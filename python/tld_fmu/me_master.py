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
        if self.types[name] in ("Integer", "Enumeration"):
            return self.fmu.getInteger([self.vr[name]])[0]
        return self.fmu.getReal([self.vr[name]])[0]

    def set(self, name, value):
        self.fmu.setReal([self.vr[name]], [value])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)


class Pair:
    """The two FMUs as one ODE system: the stacked states, the loop closed algebraically."""

    def __init__(self, building: MeFmu, tld: MeFmu):
        self.building, self.tld, self.nb = building, tld, building.nx

    def close_loop(self, t=None, y=None):
        """States `y` at `t` into both FMUs (if given), then force -> tld.force and tld.a ->
        base.a (in that order: TLD's force has no feedthrough)."""
        if y is not None:
            self.building.set_states(t, y[:self.nb])
            self.tld.set_states(t, y[self.nb:])
        self.building.set("tld.force", self.tld.get("force"))
        self.tld.set("base.a", self.building.get("tld.a"))

    def rhs(self, t, y):
        self.close_loop(t, y)
        return np.concatenate([self.building.derivatives(), self.tld.derivatives()])


def coupled(building: MeFmu, tld: MeFmu, t_eval, rtol=1e-10, atol=1e-14):
    """Integrate both FMUs as one system over `t_eval`; returns time, X (roof.x: the one-storey
    building's displacement relative to the ground) and x (slosh.x) at t_eval."""
    pair = Pair(building, tld)
    close_loop, rhs = pair.close_loop, pair.rhs

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


class Events:
    """The host's side of state events for the coupled pair: the TLD's event indicators (S^2's
    wall contact functions) as root functions, and the event iteration across both FMUs."""

    def __init__(self, building: MeFmu, tld: MeFmu, transfer: bool = True):
        self.building, self.tld, self.transfer = building, tld, transfer
        self.nz = tld.md.numberOfEventIndicators
        self._z = np.zeros(self.nz)

    def indicators(self):
        self.tld.fmu.getEventIndicators(MeFmu._ptr(self._z), self.nz)
        return self._z.copy()

    def iterate(self, close_loop, max_rounds=20):
        """Event mode for both FMUs, then FMI 2.0's event iteration over the connection: each
        FMU's fmi2NewDiscreteStates, the discrete outputs passed on (impact.impulse ->
        tld.impulse, tld.v.jump -> base.v.jump) and the continuous ones (force -> tld.force,
        tld.a -> base.a), until no FMU asks for another round and no connected output changed.
        `transfer=False`: the discrete connection left open (the impulses lost, as before)."""
        b, d = self.building, self.tld
        b.fmu.enterEventMode()
        d.fmu.enterEventMode()
        for _ in range(max_rounds):
            close_loop()
            needed = d.fmu.newDiscreteStates()[0]
            changed = False
            if self.transfer:
                changed |= _pass(d, "impact.impulse", b, "tld.impulse")
            close_loop()
            needed |= b.fmu.newDiscreteStates()[0]
            if self.transfer:
                changed |= _pass(b, "tld.v.jump", d, "base.v.jump")
            if not (needed or changed):
                break
        else:
            raise RuntimeError(f"the event iteration did not settle in {max_rounds} rounds")
        close_loop()
        b.fmu.enterContinuousTimeMode()
        d.fmu.enterContinuousTimeMode()


def _pass(src: MeFmu, output: str, dst: MeFmu, input_: str) -> bool:
    value = src.get(output)
    if value == dst.get(input_):
        return False
    dst.set(input_, value)
    return True


def coupled_with_events(building: MeFmu, tld: MeFmu, t_eval, rtol=1e-10, atol=1e-14,
                        transfer=True, outputs=("roof.x", "slosh.x", "impact.z"),
                        on_event=None):
    """Both FMUs as one ODE system (DOP853) with the TLD's state events: integrate to the first
    root of an event indicator (located on the dense output), hand the event to both FMUs
    (`Events.iterate`), restart from the states they give back. `outputs`: names read from
    either FMU at `t_eval`; `on_event(t, before, after)` gets the stacked states around each
    event. Returns {name: array} with "time" and "events" (their times)."""
    pair = Pair(building, tld)
    close_loop, rhs = pair.close_loop, pair.rhs
    events = Events(building, tld, transfer)
    names = {n: (building if n in building.vr else tld) for n in outputs}

    def root(k):
        def f(t, y):
            close_loop(t, y)
            return events.indicators()[k]
        f.terminal, f.direction = True, -1
        return f

    roots = [root(k) for k in range(events.nz)]
    t_end = t_eval[-1]
    t, y = t_eval[0], np.concatenate([building.states(), tld.states()])
    out = {n: np.full(len(t_eval), np.nan) for n in outputs}
    out["time"], out["events"] = np.asarray(t_eval, float), []
    done, idle = 0, 0
    while True:
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol,
                        events=roots, dense_output=True)
        assert sol.status >= 0, sol.message
        t_stop = sol.t[-1]
        while done < len(t_eval) and t_eval[done] <= t_stop:
            close_loop(t_eval[done], sol.sol(t_eval[done]))
            for n, f in names.items():
                out[n][done] = f.get(n)
            done += 1
        if sol.status != 1:
            break
        t, y = t_stop, sol.y[:, -1]
        close_loop(t, y)
        events.iterate(close_loop)
        after = np.concatenate([building.states(), tld.states()])
        # A root the FMU finds no event at (located a hair before the crossing) comes back at
        # once: give up rather than loop (this master does not step past it).
        idle = idle + 1 if np.array_equal(after, y) else 0
        if idle > 10:
            raise RuntimeError(f"t = {t}: 10 events in a row changed nothing")
        if on_event is not None:
            on_event(t, y, after)
        out["events"].append(t)
        y = after
    out["events"] = np.asarray(out["events"])
    return out
