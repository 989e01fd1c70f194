"""Linear limit (eta = 1, phi = 0, constant damping) against closed-form solutions (VERIFY.md 2).

The FMU holds base.a constant over each communication step, so against the closed form for a
CONTINUOUS harmonic input it carries a first-order hold error; that error is bounded, shown to
halve when the step halves (so it is the hold, not the solver), and the same run is compared
with the exact solution for the HELD input (matrix exponential), which must agree to the solver's
accuracy. The free decay has no input and hence no hold error."""
import math

import numpy as np
import pytest

from tld_fmu import reference as R

ZETA = 0.02
LINEAR = R.TLD(eta=1.0, phi=0.0, damping=R.DAMPING_CONSTANT, zeta=ZETA)
A_BASE = 0.005
T_END = 60.0


def run_harmonic(slave_factory, wr, dt):
    p = LINEAR
    w = wr * p.omega_f
    n = int(round(T_END / dt))
    t = dt * np.arange(n + 1)
    bx, bv, ba = R.harmonic_base(w, A_BASE, t[:-1])
    s = slave_factory(quiet=True)
    s.initialize(p.fmu_parameters())
    out = s.run(dt, {"base.x": bx, "base.v": bv, "base.a": ba}, ["slosh.x", "slosh.v"])
    xe, ve = R.linear_harmonic_exact(p.omega_f, ZETA, w, A_BASE, t)
    xz, vz = R.linear_zoh(p.omega_f, ZETA, dt, ba)
    return out, (xe, ve), (xz, vz)


@pytest.mark.parametrize("wr", [0.9, 1.1])
def test_linear_harmonic_against_closed_form(slave_factory, wr):
    errs = {}
    for dt in (1e-3, 5e-4):
        out, (xe, ve), (xz, vz) = run_harmonic(slave_factory, wr, dt)
        # 1) exact solution for the held input: only the FMU's solver error remains. 1e-6 of
        #    the peak is the product's accuracy requirement at default solver settings.
        e_held = R.rel_err(out["slosh.x"], xz)
        e_held_v = R.rel_err(out["slosh.v"], vz)
        assert e_held < 1e-6, f"dt={dt}: |x - x_held| / peak = {e_held:.3e}"
        assert e_held_v < 1e-6, f"dt={dt}: |v - v_held| / peak = {e_held_v:.3e}"
        # 2) continuous closed form over the whole 60 s history (transient + steady state).
        #    Holding a(t_k) over [t_k, t_k + dt) delays the input by dt/2 on average: the
        #    relative error is about w dt / 2 = 2.5e-3 (wr 0.9) to 3.1e-3 (wr 1.1) at dt = 1 ms.
        #    1e-2 bounds it with margin; a wrong omega_f, zeta or sign gives errors of order 1.
        errs[dt] = R.rel_err(out["slosh.x"], xe)
        assert errs[dt] < 1e-2 * (dt / 1e-3), f"dt={dt}: |x - x_exact| / peak = {errs[dt]:.3e}"
        print(f"wr={wr} dt={dt}: held-input error {e_held:.2e} (v {e_held_v:.2e}), "
              f"vs continuous {errs[dt]:.2e}")
    # 3) halving the step halves the error: first order, i.e. the residual is the hold error
    ratio = errs[1e-3] / errs[5e-4]
    assert ratio == pytest.approx(2.0, abs=0.1), f"error ratio {ratio:.3f}"


@pytest.mark.parametrize("dt,t_end,tol", [
    # dt = 1 ms limits the internal steps so hard that the solver's own error is near round-off:
    # 1e-8 of the initial displacement over 20 s (20 000 steps) allows ~5e-13 per step.
    (1e-3, 20.0, 1e-8),
    # coarse steps let DormandPrince45's error control choose the internal steps at the
    # default tolerance (1e-10 per step): 1e-6 is the product's accuracy requirement.
    (0.05, 60.0, 1e-6),
])
def test_free_decay(slave_factory, dt, t_end, tol):
    x0, v0 = 0.02, 0.05
    p = LINEAR.with_(x0=x0, v0=v0)
    s = slave_factory(quiet=True)
    s.initialize(p.fmu_parameters())
    n = int(round(t_end / dt))
    out = s.run(dt, {}, ["slosh.x", "slosh.v"], n_steps=n)
    t = dt * np.arange(n + 1)
    xe, ve = R.linear_free_decay(p.omega_f, ZETA, t, x0, v0)
    amp = math.hypot(x0, v0 / p.omega_f)   # initial amplitude
    ex = R.rel_err(out["slosh.x"], xe, scale=amp)
    ev = R.rel_err(out["slosh.v"], ve, scale=amp * p.omega_f)
    print(f"free decay dt={dt}: x error {ex:.2e}, v error {ev:.2e} (of initial amplitude)")
    assert out["slosh.x"][0] == x0 and out["slosh.v"][0] == v0
    assert ex < tol and ev < tol


def test_input_derivatives_raise_the_order_of_accuracy(slave_factory):
    """canInterpolateInputs: with the derivatives of base.a passed through
    fmi2SetRealInputDerivatives the input is followed inside the step, so the error against the
    CONTINUOUS closed form falls as dt^2 with the first derivative and dt^3 with the second
    (held input: dt^1). Measured over a whole 20 s history near resonance."""
    p = LINEAR
    w = 1.05 * p.omega_f
    t_end = 20.0
    errors = {}
    for order in (0, 1, 2):
        for dt in (4e-3, 2e-3):
            n = int(round(t_end / dt))
            t = dt * np.arange(n + 1)
            ba = -w * w * A_BASE * np.sin(w * t[:-1])
            derivs = {}
            if order >= 1:
                derivs[("base.a", 1)] = -w ** 3 * A_BASE * np.cos(w * t[:-1])
            if order >= 2:
                derivs[("base.a", 2)] = w ** 4 * A_BASE * np.sin(w * t[:-1])
            s = slave_factory(quiet=True)
            s.initialize(p.fmu_parameters())
            out = s.run(dt, {"base.a": ba}, ["slosh.x"], derivatives=derivs)
            xe, _ = R.linear_harmonic_exact(p.omega_f, ZETA, w, A_BASE, t)
            errors[(order, dt)] = R.rel_err(out["slosh.x"], xe)
    for order in (0, 1, 2):
        ratio = errors[(order, 4e-3)] / errors[(order, 2e-3)]
        print(f"order {order}: errors {errors[(order, 4e-3)]:.3e} -> {errors[(order, 2e-3)]:.3e}, ratio {ratio:.2f}")
        # halving dt divides the error by 2^(order+1); 15 % slack for pre-asymptotic terms
        assert ratio == pytest.approx(2.0 ** (order + 1), rel=0.15), (order, ratio)
    # and each order is much more accurate than the one below at the same step
    assert errors[(1, 2e-3)] < 0.05 * errors[(0, 2e-3)]
    assert errors[(2, 2e-3)] < 0.05 * errors[(1, 2e-3)]
