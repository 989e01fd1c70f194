"""The seed's Table 2.1 structure (modal mass M = 168 kg, damping ratio 0.32 %, natural
frequency w_s = 5.636 rad/s, K = M w_s^2) and a co-simulation master that carries one TLD.fmu
instance on it under harmonic ground motion x_g = A_g sin(w t) (scripts/demo.py sweeps it,
scripts/fig25.py with the S^2 model, tests/python/test_cosim.py checks its convergence).

Coupling (why `force` and not `base_shear`)
-------------------------------------------
The total horizontal force of the liquid on the tank is base_shear = force - m_0 a_tank, where
m_0 = mass.inactive moves rigidly with the tank. Using base_shear would feed the structure's
acceleration straight back into the force it causes (an algebraic loop through base.a). Moving
the inactive mass to the structure's side removes it exactly: with X the structure's displacement
relative to the ground and a_tank = a_g + X'' its absolute acceleration,

    M a_tank + C X' + K X = force - m_0 a_tank   <=>   (M + m_0) a_tank = force - C X' - K X

So the structure carries mass M + mass.inactive, the coupling force is `force` (no direct
feedthrough: it depends on the FMU's state only), and the FMU's input base.a is the absolute
acceleration of the structure.

Master algorithm (explicit, fixed communication step h = 1 ms), at each communication point t_k:
  1. get `force` F_k from the FMU (state at t_k);
  2. compute the structure's absolute acceleration a_k = (F_k - C V_k - K X_k) / (M + m_0);
  3. set base.a = a_k, base.v = v_g + V_k, base.x = x_g + X_k (absolute tank motion) and doStep;
  4. advance the structure over the same step with the FMU's `force.mean` (the impulse the liquid
     delivered during the step, divided by h: momentum-consistent) held and the ground motion
     exact, by classical RK4.

Excitation amplitude for the damper's amplitude-dependent damping: amplitude = Tracked, so the
FMU estimates the excitation amplitude of the tank online from base.v and base.a - what a user
who does not know the response in advance would do. (A Fixed A_e would have to be set to the
structure's response amplitude near resonance, which is what the sweep is computing.)
"""
from __future__ import annotations

import ctypes
import math
import os

import numpy as np

from . import fmulog
from .contract import Contract

# seed Table 2.1 structure
M_S = 168.0            # kg, modal mass
ZETA_S = 0.0032        # structural damping ratio
W_S = 5.636            # rad/s
K_S = M_S * W_S ** 2
C_S = 2.0 * ZETA_S * M_S * W_S


def bare_structure_peak(w, A_g):
    """Steady-state amplitude of X for M X'' + C X' + K X = M w^2 A_g sin(w t)."""
    return M_S * w ** 2 * A_g / math.hypot(K_S - M_S * w ** 2, C_S * w)


def cosimulate(unzipdir, w, A_g, h, t_end, params=None, t_window=20.0, record=False,
               extrapolate=False):
    """Co-simulate the structure + TLD under x_g = A_g sin(w t) with the master described in
    the module docstring. params: FMU parameters {name: value}, an Enumeration's item by name
    or value (default: amplitude Tracked).

    extrapolate=True: the second-order variant. The master reads `force` and its exact time
    derivative (fmi2GetRealOutputDerivatives) at t_k, advances the structure with the force
    extrapolated linearly over the step, and gives the FMU base.a together with its derivative
    (fmi2SetRealInputDerivatives, order 1) computed from the structure's equation:
    a' = (F' - C X'' - K X') / (M + m_0). Both sides then see inputs that are right to O(h^2)
    over the step, and the co-simulation converges at second order instead of first.

    Returns {"peak": max |X| over the last t_window s, "peak_prev": over the t_window s before,
    "A_e": mean A_e.estimate over the last t_window s} and, with record=True, the histories
    "t", "X", "V" (structure relative to the ground) and "x" (slosh.x) at the communication
    points."""
    from fmpy import read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi1 import FMICallException

    if params is None:
        params = {"amplitude": "Tracked"}
    md = read_model_description(os.path.join(unzipdir, "modelDescription.xml"))
    contract = Contract(md)
    vr = {n: v.valueReference for n, v in contract.variables.items()}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName=f"tld_{w:.4f}")
    cb = fmulog.callbacks()   # warnings to fmulog.REPORT, each on its own line
    fmu.instantiate(callbacks=cb)
    try:
        contract.initialise(fmu, params)
        m0 = fmu.getReal([vr["mass.inactive"]])[0]
        mass = M_S + m0

        # raw ctypes entry points with preallocated buffers: the loop below is hot
        f = fmu._functions
        setReal, getReal, doStep = f["fmi2SetReal"], f["fmi2GetReal"], f["fmi2DoStep"]
        comp = fmu.component
        in_vr = (ctypes.c_uint * 3)(vr["base.a"], vr["base.v"], vr["base.x"])
        in_val = (ctypes.c_double * 3)()
        out_vr = (ctypes.c_uint * 4)(vr["force"], vr["force.mean"], vr["A_e.estimate"],
                                     vr["slosh.x"])
        out_val = (ctypes.c_double * 4)()
        if getReal(comp, out_vr, 4, out_val) > 1:
            raise FMICallException("fmi2GetReal", 3)
        F = out_val[0]
        if extrapolate:
            setDer, getDer = f["fmi2SetRealInputDerivatives"], f["fmi2GetRealOutputDerivatives"]
            a_vr, f_vr = (ctypes.c_uint * 1)(vr["base.a"]), (ctypes.c_uint * 1)(vr["force"])
            order1 = (ctypes.c_int * 1)(1)
            der_val = (ctypes.c_double * 1)()

            def force_rate():
                st = getDer(comp, f_vr, 1, order1, der_val)
                if st > 1:
                    raise FMICallException("fmi2GetRealOutputDerivatives", st)
                return der_val[0]

        n = int(round(t_end / h))
        k_window = n - int(round(t_window / h))
        k_half = n - 2 * int(round(t_window / h))
        X = V = 0.0
        peak = peak_prev = 0.0
        est = []
        if record:
            rec = np.zeros((n + 1, 3))
            rec[0, 2] = out_val[3]
        w2A = w * w * A_g
        sin, cos = math.sin, math.cos

        def acc(t, X, V, Fm):          # relative acceleration of the structure
            return (Fm - C_S * V - K_S * X) / mass + w2A * sin(w * t)

        for k in range(n):
            t = k * h
            s, c = sin(w * t), cos(w * t)
            a_abs = (F - C_S * V - K_S * X) / mass          # = a_g + X''
            in_val[0] = a_abs
            in_val[1] = A_g * w * c + V
            in_val[2] = A_g * s + X
            st = setReal(comp, in_vr, 3, in_val)
            if st > 1:
                raise FMICallException("fmi2SetReal", st)
            if extrapolate:
                # the force's rate now, with this step's base.a set (it depends on it); then
                # a_tank' from the structure's equation, X'' = a_tank - a_g
                dF = force_rate()
                der_val[0] = (dF - C_S * (a_abs + w2A * s) - K_S * V) / mass
                st = setDer(comp, a_vr, 1, order1, der_val)
                if st > 1:
                    raise FMICallException("fmi2SetRealInputDerivatives", st)
            st = doStep(comp, t, h, 1)
            if st > 1:
                raise FMICallException(f"fmi2DoStep at t = {t}", st)
            st = getReal(comp, out_vr, 4, out_val)
            if st > 1:
                raise FMICallException("fmi2GetReal", st)
            if extrapolate:
                # the liquid force over the step: its value and rate at t_k, extrapolated
                F0, F1, Fm = F, F + h * dF, F + 0.5 * h * dF
                F = out_val[0]
            else:
                # the step's mean liquid force (impulse / h), held
                F, Fm = out_val[0], out_val[1]
                F0 = F1 = Fm
            # structure over [t, t + h] by RK4
            k1x, k1v = V, acc(t, X, V, F0)
            k2x, k2v = V + 0.5 * h * k1v, acc(t + 0.5 * h, X + 0.5 * h * k1x, V + 0.5 * h * k1v, Fm)
            k3x, k3v = V + 0.5 * h * k2v, acc(t + 0.5 * h, X + 0.5 * h * k2x, V + 0.5 * h * k2v, Fm)
            k4x, k4v = V + h * k3v, acc(t + h, X + h * k3x, V + h * k3v, F1)
            X += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
            V += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
            if not math.isfinite(X):
                raise RuntimeError(f"structure diverged at t = {t}")
            if record:
                rec[k + 1] = (X, V, out_val[3])
            if k >= k_window:
                peak = max(peak, abs(X))
                est.append(out_val[2])
            elif k >= k_half:
                peak_prev = max(peak_prev, abs(X))
        fmu.terminate()
    finally:
        fmu.freeInstance()
    out = {"peak": peak, "peak_prev": peak_prev, "A_e": float(np.mean(est)) if est else math.nan}
    if record:
        out.update(t=h * np.arange(n + 1), X=rec[:, 0], V=rec[:, 1], x=rec[:, 2])
    return out


def run_one(job):
    """One frequency of the sweep (runs in a worker process)."""
    unzipdir, w, A_g, h, t_end, t_window = job
    r = cosimulate(unzipdir, w, A_g, h, t_end, t_window=t_window)
    return {"w": w, "with": r["peak"], "settle": abs(r["peak"] - r["peak_prev"]) / r["peak"],
            "A_e": r["A_e"], "without": bare_structure_peak(w, A_g), "warnings": fmulog.REPORT.drain()}
