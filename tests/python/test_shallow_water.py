"""model = ShallowWater (MODEL.md 7) through the packaged FMU in fmpy: the balances that hold
for the resolved liquid whatever the scheme's accuracy, checked from the outputs alone.

- momentum: the whole liquid is resolved, so per step
  h force.mean = -M_l integral(a_b) dt - Delta(rho b integral q dx), and rho b integral q dx is
  m_1 slosh.v (its definition: slosh.v = rho b integral q dx / m_1) — to round-off;
- energy: energy.input = energy.stored + energy.dissipated, dissipated never decreasing;
- mass: mass.inactive = 0 and base_shear = force (no rigidly moving liquid); the surface at the
  walls is where the liquid is (never below the bed).
The scene: the lab tank near resonance at 6 mm of base motion (bores), boundary-layer damping,
the input's derivatives passed (a quadratic polynomial over each step, whose mean over each
substep the scheme integrates exactly)."""
import numpy as np

SHALLOW_WATER = 5
BOUNDARY_LAYER = 3


def test_shallow_water_balances_through_the_outputs(slave_factory, variables):
    s = slave_factory()
    s.initialize({"model": SHALLOW_WATER, "damping": BOUNDARY_LAYER, "swe.cells": 60,
                  "tanks": 2})
    m_l, m_inactive, w1 = s.get("mass.liquid", "mass.inactive", "omega_f")
    assert m_inactive == 0.0
    # m_1 of Eq 2.1, all tanks: mass.slosh is the whole liquid here, so from the geometry
    a, h_still = 0.25, 0.021
    r = h_still / a
    m1 = m_l * 8 * np.tanh(np.pi * r) / (np.pi ** 3 * r)
    dt, n, amp = 0.01, 800, 0.006
    t = np.arange(n) * dt
    acc = -w1 ** 2 * amp * np.sin(w1 * t)
    d1 = -w1 ** 3 * amp * np.cos(w1 * t)
    d2 = w1 ** 4 * amp * np.sin(w1 * t)
    out = s.run(dt, {"base.a": acc},
                ["force", "force.mean", "base_shear", "slosh.v", "energy.input",
                 "energy.stored", "energy.dissipated", "surface.left", "surface.right"],
                derivatives={("base.a", 1): d1, ("base.a", 2): d2})
    # momentum, step by step: integral of a_b over a step of its Taylor polynomial
    integral = dt * (acc + dt * (d1 / 2 + dt * d2 / 6))
    momentum = m1 * out["slosh.v"]
    residual = dt * out["force.mean"][1:] + m_l * integral + np.diff(momentum)
    impulse = np.abs(dt * out["force.mean"][1:]).max()
    assert np.abs(residual).max() < 1e-12 * impulse, np.abs(residual).max() / impulse
    # energy
    e_in, e_st, e_dis = out["energy.input"], out["energy.stored"], out["energy.dissipated"]
    assert np.allclose(e_in, e_st + e_dis, rtol=0, atol=1e-14 * np.abs(e_in).max())
    assert np.all(np.diff(e_dis) >= 0.0)
    assert e_dis[-1] > 0.5 * e_in[-1]
    # the resolved liquid
    assert np.array_equal(out["base_shear"], out["force"])
    assert np.all(out["surface.left"] >= -h_still) and np.all(out["surface.right"] >= -h_still)
    # and it sloshes: the wave at the walls reaches a good part of the depth
    assert np.abs(out["surface.left"]).max() > 0.2 * h_still
