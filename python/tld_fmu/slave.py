"""One FMU instance driven through fmpy's low-level FMU2Slave API: parameters by name (an
Enumeration's item by name or value), the FMU's log messages captured through a logger callback,
and long fixed-step co-simulations run with the raw ctypes entry points (no per-call Python
conversions), so 60 000 steps take well under a second. The fmpy suite's `slave_factory`
fixture makes these; the state test's child process and the benchmark use them directly."""
from __future__ import annotations

import ctypes

import numpy as np

from . import fmulog
from .contract import Contract


class Slave:
    """One FMU instance driven through fmpy.fmi2.FMU2Slave."""

    def __init__(self, md, unzipdir, variables, name="tld", logging_on=True, quiet=False):
        """logging_on: fmi2Instantiate's loggingOn. quiet: restrict the debug log to the
        status categories (no per-call logging), for long runs."""
        from fmpy.fmi2 import FMU2Slave

        self.vars = variables
        self.contract = Contract(md)
        self.messages: list[tuple[int, str, str]] = []   # (status, category, message)

        # this instance's messages, through the process's one logger router (tld_fmu.fmulog)
        self._callbacks = cb = fmulog.callbacks(lambda _i, st, cat, msg, to=self.messages: to.append((st, cat, msg)))
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(callbacks=cb, loggingOn=logging_on)
        if quiet and logging_on:
            cats = [c.name for c in md.logCategories if c.name.startswith("logStatus")]
            if cats:
                arr = (ctypes.c_char_p * len(cats))(*[c.encode() for c in cats])
                self.fmu.fmi2SetDebugLogging(self.fmu.component, 1, len(cats), arr)
        self.time = 0.0
        self._closed = False

    # -- variable access by name ----------------------------------------------------------------
    def vr(self, name):
        return self.vars[name].valueReference

    def set_vars(self, values: dict):
        """{name: value}, each through its type's setter; an Enumeration's item by name or value."""
        self.contract.set(self.fmu, values)

    def get(self, *names):
        out = []
        for name in names:
            v = self.vars[name]
            if v.type == "Real":
                out.append(self.fmu.getReal([v.valueReference])[0])
            else:
                out.append(self.fmu.getInteger([v.valueReference])[0])
        return out if len(out) > 1 else out[0]

    # -- life cycle -------------------------------------------------------------------------------
    def initialize(self, params: dict | None = None, tolerance=None, start=0.0):
        self.contract.initialise(self.fmu, params or {}, start=start, tolerance=tolerance)
        self.time = start
        return self

    def close(self):
        if self._closed:
            return
        self._closed = True
        from fmpy.fmi1 import FMICallException
        try:
            self.fmu.terminate()
        except FMICallException:
            pass
        self.fmu.freeInstance()

    # -- fast fixed-step run --------------------------------------------------------------------------
    def run(self, dt, inputs: dict, outputs, n_steps=None, derivatives: dict | None = None):
        """Co-simulate n steps of length dt. inputs: {name: array of length n} set before step k
        (held during it, unless derivatives are given). derivatives: {(name, order): array of
        length n} passed with fmi2SetRealInputDerivatives before step k. Returns {name: array of
        length n+1} for outputs, sampled at the start (index 0) and after every step, BEFORE the
        next inputs are set."""
        try:
            return self._run(dt, inputs, outputs, n_steps, derivatives or {})
        except Exception as e:
            tail = "\n".join(f"  [{st}] {cat}: {msg}" for st, cat, msg in self.messages[-5:])
            raise AssertionError(f"{e}\nlast FMU log messages:\n{tail or '  (none)'}") from e

    def _run(self, dt, inputs, outputs, n_steps, derivatives):
        from fmpy.fmi1 import FMICallException
        f = self.fmu._functions
        setReal, getReal, doStep = f["fmi2SetReal"], f["fmi2GetReal"], f["fmi2DoStep"]
        setDer = f["fmi2SetRealInputDerivatives"]
        nd = len(derivatives)
        d_vr = (ctypes.c_uint * max(nd, 1))(*[self.vr(k[0]) for k in derivatives])
        d_order = (ctypes.c_int * max(nd, 1))(*[k[1] for k in derivatives])
        d_val = (ctypes.c_double * max(nd, 1))()
        d_rows = [np.asarray(a, float) for a in derivatives.values()]
        comp = self.fmu.component
        in_names = list(inputs)
        n = n_steps if n_steps is not None else len(next(iter(inputs.values())))
        rows = (np.column_stack([np.asarray(inputs[k], float)[:n] for k in in_names]).tolist()
                if in_names else [[]] * n)
        nin, nout = len(in_names), len(outputs)
        in_vr = (ctypes.c_uint * max(nin, 1))(*[self.vr(k) for k in in_names])
        in_val = (ctypes.c_double * max(nin, 1))()
        out_vr = (ctypes.c_uint * nout)(*[self.vr(k) for k in outputs])
        out_val = (ctypes.c_double * nout)()
        res = np.empty((n + 1, nout))
        st = getReal(comp, out_vr, nout, out_val)
        if st > 1:
            raise FMICallException("fmi2GetReal", st)
        res[0] = out_val[:]
        t0 = self.time
        for k in range(n):
            if nin:
                in_val[:nin] = rows[k]
                st = setReal(comp, in_vr, nin, in_val)
                if st > 1:
                    raise FMICallException("fmi2SetReal", st)
            if nd:
                d_val[:nd] = [float(a[k]) for a in d_rows]
                st = setDer(comp, d_vr, nd, d_order, d_val)
                if st > 1:
                    raise FMICallException("fmi2SetRealInputDerivatives", st)
            st = doStep(comp, t0 + k * dt, dt, 1)
            if st > 1:
                raise FMICallException(f"fmi2DoStep (step {k}, t = {t0 + k * dt})", st)
            st = getReal(comp, out_vr, nout, out_val)
            if st > 1:
                raise FMICallException("fmi2GetReal", st)
            res[k + 1] = out_val[:]
        self.time = t0 + n * dt
        return {name: res[:, i] for i, name in enumerate(outputs)}

    def error_messages(self, since=0):
        """Messages logged with status fmi2Discard or worse, from index `since` on."""
        return [m for m in self.messages[since:] if m[0] >= 2]

