"""model = SloshingSlamming (S^2, MODEL.md section 3) against an independent event-driven
reference written here: the sloshing mode (mass Omega m_1 at omega_1 / sqrt(Omega)) by the exact
held-input solution, the impact mass in parabolic flight between the walls with impact times
from the quadratic formula and the restitution law applied to the relative velocity."""
import math

import numpy as np
import pytest

from tld_fmu import reference as R

S2 = 3
E, D, RATIO = 0.4, 0.1, 0.01


def reference_impacts(a, dt, z0=0.0, v0=0.0):
    """Impact mass relative to the tank under held base acceleration: (z, count, impulse per
    step per unit mass) after each step. Resting on a wall is not modelled: the scene keeps
    rebounds well above the rest speed."""
    half = D / 2
    z, v, count = z0, v0, 0
    zs, counts, impulses = [z], [0], []
    for ak in a:
        s, imp = 0.0, 0.0
        while True:
            # z(t) = z + v t - ak t^2 / 2 ; first t in (0, dt - s] with |z(t)| = d/2
            best = None
            for wall in (1.0, -1.0):
                A_, B_, C_ = -ak / 2, v, z - wall * half
                if A_ == 0.0:
                    roots = [-C_ / B_] if B_ != 0 else []
                else:
                    disc = B_ * B_ - 4 * A_ * C_
                    roots = [] if disc < 0 else [(-B_ + sg * math.sqrt(disc)) / (2 * A_) for sg in (1, -1)]
                for r in roots:
                    if 1e-13 < r <= dt - s and (best is None or r < best[0]):
                        vel = v - ak * r
                        if vel * wall > 0:
                            best = (r, wall, vel)
            if best is None:
                tau = dt - s
                z, v = z + v * tau - ak * tau * tau / 2, v - ak * tau
                break
            r, wall, vel = best
            s += r
            imp += (1 + E) * vel
            z, v, count = wall * half, -E * vel, count + 1
        zs.append(z)
        counts.append(count)
        impulses.append(imp)
    return np.array(zs), np.array(counts), np.array(impulses)


@pytest.mark.parametrize("omega", [1.0, 0.9])
def test_s2_against_an_event_driven_reference(slave_factory, omega):
    p = R.TLD(damping=R.DAMPING_CONSTANT, zeta=0.02)
    dt, n = 0.01, 3000
    w = 1.0 * p.omega_f
    _, _, a = R.harmonic_base(w, 0.02, dt * np.arange(n))
    s = slave_factory(quiet=True)
    s.initialize({**p.fmu_parameters(), "model": S2, "slamming.Omega": omega,
                  "slamming.restitution": E, "slamming.clearance": D, "slamming.mass_ratio": RATIO})
    out = s.run(dt, {"base.a": a}, ["slosh.x", "impact.z", "force.mean", "energy.input",
                                    "energy.stored", "energy.dissipated", "mass.slosh"])
    impacts = s.fmu.getInteger([s.vr("impacts")])[0]
    # The sloshing mode: exact held-input solution at omega_1 / sqrt(Omega).
    ratio1, w1 = R.mode(1)
    m1 = ratio1 * p.geo["mass.liquid"]
    ws = w1 / math.sqrt(omega)
    x, v = R.linear_zoh(ws, 0.02, dt, a)
    assert R.rel_err(out["slosh.x"], x) < 1e-10
    z, counts, imp = reference_impacts(a, dt)
    print(f"Omega {omega}: {impacts} impacts (reference {counts[-1]}), "
          f"impact.z error {np.max(np.abs(out['impact.z'] - z)):.2e} m")
    assert impacts == counts[-1] and impacts > 20
    assert np.max(np.abs(out["impact.z"] - z)) < 1e-9
    # force.mean carries both the sloshing and the impact impulses.
    m2 = (RATIO + 1 - omega) * m1
    f_slosh = omega * m1 * (-(np.diff(v)) - a * dt) / dt
    f_ref = f_slosh + m2 * imp / dt
    assert R.rel_err(out["force.mean"][1:], f_ref) < 1e-8
    assert out["mass.slosh"][0] == pytest.approx((1 + RATIO) * m1, rel=1e-12)
    # Energy: input = stored + dissipated, dissipation (damping and impacts) never decreases.
    bal = np.max(np.abs(out["energy.input"] - out["energy.stored"] - out["energy.dissipated"]))
    assert bal < 1e-10 * np.max(np.abs(out["energy.input"]))
    assert np.all(np.diff(out["energy.dissipated"]) >= -1e-15)


def test_chattering_under_steady_push_ends_at_rest(slave_factory):
    """A constant base acceleration presses the impact mass onto a wall: the bounces die out,
    the count stays finite, and while it rests the mass moves with the tank (its push shows in
    force.mean as -m2 a_b)."""
    p = R.TLD(damping=R.DAMPING_CONSTANT, zeta=0.02)
    s = slave_factory(quiet=True)
    s.initialize({**p.fmu_parameters(), "model": S2, "slamming.Omega": 0.8})
    out = s.run(0.01, {"base.a": np.full(300, -2.0)}, ["impact.z", "force.mean", "energy.dissipated"])
    n1 = s.fmu.getInteger([s.vr("impacts")])[0]
    s.run(0.01, {"base.a": np.full(100, -2.0)}, ["impact.z"])
    n2 = s.fmu.getInteger([s.vr("impacts")])[0]
    assert 3 < n1 < 200 and n2 == n1, (n1, n2)
    assert out["impact.z"][-1] == pytest.approx(0.05)


def nsd_kappa(lam):
    """Frequency hardening ratio of the NSD fit (MODEL.md), written out here."""
    return 1.075 * lam ** 0.007 if lam < 0.03 else 2.52 * lam ** 0.25


def test_default_mass_exchange_follows_the_nsd_law(slave_factory):
    """slamming.Omega left at its default (0): Omega = 1/kappa(Lambda)^2 at Lambda = A_e/a, so the
    free sloshing mode (no base motion, so the impact mass stays at rest) runs at
    omega_1 / sqrt(Omega) = kappa omega_1, about 4.6 % above omega_1 at the default A_e = 5 mm;
    with Omega = 1 it would run at omega_1."""
    p = R.TLD(damping=R.DAMPING_CONSTANT, zeta=0.0, x0=1e-3)
    params = {**p.fmu_parameters(), "model": S2}
    assert "slamming.Omega" not in params
    s = slave_factory(quiet=True)
    s.initialize(params)
    dt, n = 0.01, 1000
    out = s.run(dt, {"base.a": np.zeros(n)}, ["slosh.x"])
    kappa = nsd_kappa(min(max(p.A_e / p.a, p.lambda_min), p.lambda_max))
    assert kappa > 1.04
    t = dt * np.arange(n + 1)
    want = p.x0 * np.cos(kappa * p.omega_f * t)
    err = np.max(np.abs(out["slosh.x"] - want))
    print(f"\nkappa {kappa:.5f}, Omega {1 / kappa ** 2:.5f}: max error {err:.2e} m")
    assert err < 1e-9, err
    assert s.fmu.getInteger([s.vr("impacts")])[0] == 0
