"""Model Exchange of model = ShallowWater (its cells as continuous states) and of amplitude =
Tracked (the estimator's filters as states), integrated by fmpy's CVode (BDF, its own
difference-quotient Jacobian), over whole histories:
- ShallowWater free decay of a small fundamental-mode slosh against the linear mode of
  Eqs 2.1/2.2 in closed form (1 % of the peak, as the Co-Simulation tests: the scheme's
  dispersion and the waves' nonlinearity), and against the Co-Simulation model (its fully
  discrete scheme, SSPRK(10,4) at its CFL substeps) whose time-stepping error is far smaller;
- ShallowWater under resonant base motion, the input a staircase (every 10 ms sample an input
  event, as in test_model_exchange.py), against Co-Simulation at 10 ms steps seeing the same
  held samples, at two CVode tolerances: the difference falls with the tolerance to the
  Co-Simulation scheme's own time-stepping error;
- the liquid's volume (sum of swe.h) conserved to round-off.
"""
import numpy as np
import pytest
from fmpy import simulate_fmu

from tld_fmu import reference as R
from tld_fmu.contract import item

DT = 0.01
CELLS = 60
BASE = {"model": item("model", "ShallowWater"), "amplitude": item("amplitude", "Fixed"),
        "damping": R.DAMPING_CONSTANT, "swe.cells": CELLS}
OUTPUTS = ["slosh.x", "slosh.v", "force"] + [f"swe.h[{i}]" for i in range(1, CELLS + 1)]


def me(fmu_path, start, t_end, rtol, signal=None):
    return simulate_fmu(str(fmu_path), fmi_type="ModelExchange", solver="CVode",
                        relative_tolerance=rtol, output_interval=DT, stop_time=t_end,
                        start_values={**BASE, **start}, input=signal, output=OUTPUTS)


def cs(fmu_path, start, t_end, signal=None):
    return simulate_fmu(str(fmu_path), fmi_type="CoSimulation", output_interval=DT,
                        stop_time=t_end, start_values={**BASE, **start}, input=signal,
                        output=["slosh.x", "slosh.v", "force"])


def at(result, t):
    idx = np.searchsorted(result["time"], t - 1e-9)
    assert np.allclose(result["time"][idx], t, atol=1e-9)
    return result[idx]


def volume_drift(res):
    v = sum(res[f"swe.h[{i}]"] for i in range(1, CELLS + 1))
    return float(np.max(np.abs(v - v[0])) / v[0])


def test_shallow_water_free_decay_is_the_linear_mode(fmu_path):
    zeta, x0, v0, t_end = 0.03, 0.0005, 0.002, 3.0
    start = {"zeta": zeta, "slosh.x0": x0, "slosh.v0": v0}
    res = me(fmu_path, start, t_end, 1e-8)
    t = res["time"]
    w = R.mode(1)[1]
    wd = w * np.sqrt(1 - zeta ** 2)
    b = (v0 + zeta * w * x0) / wd
    x = np.exp(-zeta * w * t) * (x0 * np.cos(wd * t) + b * np.sin(wd * t))
    e_mode = R.rel_err(res["slosh.x"], x)
    ref = cs(fmu_path, start, t_end)
    tt = ref["time"]
    ex = R.rel_err(at(res, tt)["slosh.x"], ref["slosh.x"])
    ef = R.rel_err(at(res, tt)["force"], ref["force"])
    drift = volume_drift(res)
    print(f"ShallowWater ME ({CELLS} cells, CVode 1e-8), free decay: slosh.x vs linear mode "
          f"{e_mode:.2e}; vs Co-Simulation slosh.x {ex:.2e}, force {ef:.2e}; volume {drift:.1e}")
    assert e_mode < 0.01
    assert ex < 1e-4 and ef < 1e-3
    assert drift < 1e-12


def staircase(t_end, w, amplitude):
    t = DT * np.arange(int(round(t_end / DT)) + 1)
    a = -w ** 2 * amplitude * np.sin(w * t)
    signal = np.zeros(2 * len(t) - 1, dtype=[("time", np.float64), ("base.a", np.float64)])
    signal["time"][0::2], signal["base.a"][0::2] = t, a
    signal["time"][1::2], signal["base.a"][1::2] = t[1:], a[:-1]
    return t, signal


def test_shallow_water_resonant_forcing_against_co_simulation(fmu_path):
    t_end = 3.0
    w = R.mode(1)[1]
    t, signal = staircase(t_end, w, 0.002)
    start = {"zeta": 0.01}
    ref = cs(fmu_path, start, t_end, signal)
    errors = {}
    for rtol in (1e-6, 1e-8):
        res = at(me(fmu_path, start, t_end, rtol, signal), t)
        errors[rtol] = (R.rel_err(res["slosh.x"], at(ref, t)["slosh.x"]),
                        R.rel_err(res["force"], at(ref, t)["force"]))
        print(f"ShallowWater ME ({CELLS} cells, CVode {rtol:g}) vs Co-Simulation 10 ms, resonant "
              f"2 mm: slosh.x {errors[rtol][0]:.2e}, force {errors[rtol][1]:.2e}; volume "
              f"{volume_drift(res):.1e}")
        assert volume_drift(res) < 1e-10
    assert errors[1e-8][0] < 1e-4 and errors[1e-8][1] < 2e-3
    assert errors[1e-8][0] <= errors[1e-6][0]
