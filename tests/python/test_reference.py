"""Self-tests of the independent reference solutions (reference.py). These do not use the FMU:
they establish that the yardsticks the FMU is measured against are themselves right, by
checking them against each other (three independent methods) and against the spec's numbers."""
import math

import numpy as np
import pytest

from tld_fmu import reference as R


def test_geometry_check_values_of_model_md():
    # MODEL.md section 1, Table 2.1 tank: quoted to 4 significant digits there.
    g = R.geometry()
    assert g["mass.liquid"] == pytest.approx(1.68, rel=1e-12)
    assert g["mass.slosh"] / g["mass.liquid"] == pytest.approx(0.7923, abs=5e-5)
    assert g["omega_f"] == pytest.approx(5.6389, abs=5e-5)
    assert g["omega_f"] / (2 * math.pi) == pytest.approx(0.8975, abs=5e-5)
    r2, w2 = R.mode(2)
    r3, w3 = R.mode(3)
    assert r2 == pytest.approx(0.075, abs=5e-4) and w2 == pytest.approx(15.62, abs=5e-3)
    assert r3 == pytest.approx(0.021, abs=5e-4) and w3 == pytest.approx(23.11, abs=5e-3)
    total = sum(R.mode(n)[0] for n in range(1, 2000))
    assert total == pytest.approx(0.909, abs=5e-4)
    g3 = R.geometry(tanks=3)
    for k in ("mass.liquid", "mass.slosh", "mass.inactive"):
        assert g3[k] == pytest.approx(3 * g[k], rel=1e-15)
    assert g3["omega_f"] == g["omega_f"]


def test_potential_is_integral_of_restoring_force():
    for eta, phi in [(1.0, 0.0), (2.0, 1.0), (3.5, 0.7), (1.5, 2.0)]:
        p = R.TLD(eta=eta, phi=phi)
        x = np.linspace(-0.2, 0.2, 4001)
        dU = np.gradient(p.U(x), x, edge_order=2)
        assert np.max(np.abs(dU - p.Phi(x))[5:-5]) / np.max(np.abs(p.Phi(x))) < 1e-5
        assert p.U(0.0) == 0.0
        # the wall force is (1 + phi) times the linear one for every eta (MODEL.md 2)
        assert p.Phi(p.a / 2) == pytest.approx(p.omega_f ** 2 * (1 + phi) * p.a / 2, rel=1e-14)


def test_nsd_damping_law():
    p = R.TLD()
    assert p.zeta_of(0.005) == pytest.approx(0.5 * (0.005 / 0.25) ** 0.35, rel=1e-15)
    assert p.zeta_of(0.0) == pytest.approx(0.5 * 1e-3 ** 0.35, rel=1e-15)     # clamp below
    assert p.zeta_of(1.0) == pytest.approx(0.5 * 0.1 ** 0.35, rel=1e-15)      # clamp above
    assert R.TLD(damping=R.DAMPING_CONSTANT, zeta=0.03).zeta_of(0.005) == 0.03


def test_closed_forms_satisfy_their_odes():
    w0, z = 5.6, 0.02
    t = np.linspace(0, 10, 200001)
    dt = t[1] - t[0]
    x, v = R.linear_free_decay(w0, z, t, 0.02, 0.03)
    assert x[0] == pytest.approx(0.02, abs=1e-16) and v[0] == pytest.approx(0.03, abs=1e-16)
    acc = np.gradient(v, dt, edge_order=2)
    assert np.max(np.abs(np.gradient(x, dt, edge_order=2) - v)) < 1e-7
    assert np.max(np.abs(acc + 2 * z * w0 * v + w0 ** 2 * x)) < 1e-5
    w, A = 0.9 * w0, 0.005
    x, v = R.linear_harmonic_exact(w0, z, w, A, t)
    assert abs(x[0]) < 1e-16 and abs(v[0]) < 1e-15
    acc = np.gradient(v, dt, edge_order=2)
    assert np.max(np.abs(np.gradient(x, dt, edge_order=2) - v)) < 1e-7
    assert np.max(np.abs(acc + 2 * z * w0 * v + w0 ** 2 * x - w ** 2 * A * np.sin(w * t))) < 1e-5


def test_rk8_matches_exact_linear_held_solution():
    # eta = 1, phi = 0 is linear: the exact sample-and-hold solution (matrix exponential) must
    # agree with the RK8 reference to round-off over a long run.
    p = R.TLD(eta=1.0, phi=0.0, damping=R.DAMPING_CONSTANT, zeta=0.02, x0=0.01, v0=-0.02)
    dt, n = 1e-3, 20000
    t = dt * np.arange(n)
    a = R.harmonic_base(1.1 * p.omega_f, 0.005, t)[2]
    r = R.simulate_held(p, dt, a)
    xz, vz = R.linear_zoh(p.omega_f, 0.02, dt, a, p.x0, p.v0)
    assert R.rel_err(r.x, xz) < 1e-11
    assert R.rel_err(r.v, vz) < 1e-11


def test_zoh_converges_to_continuous_at_first_order():
    # the hold error is first order in the step: halving the step halves it
    w0, z, w, A = R.geometry()["omega_f"], 0.02, 0.9 * R.geometry()["omega_f"], 0.005
    errs = []
    for dt in (2e-3, 1e-3):
        n = int(round(20 / dt))
        t = dt * np.arange(n + 1)
        a = R.harmonic_base(w, A, t[:-1])[2]
        xz, _ = R.linear_zoh(w0, z, dt, a)
        xe, _ = R.linear_harmonic_exact(w0, z, w, A, t)
        errs.append(R.rel_err(xz, xe))
    assert errs[0] / errs[1] == pytest.approx(2.0, rel=0.05)


@pytest.mark.parametrize("eta,phi,damping,zeta,A,wr", [
    (2.0, 1.0, R.DAMPING_NSD, 0.01, 0.005, 1.05),
    (3.5, 1.0, R.DAMPING_CONSTANT, 0.005, 0.002, 1.0),
])
def test_rk8_matches_scipy_dop853(eta, phi, damping, zeta, A, wr):
    # the fast reference against scipy's adaptive DOP853 at rtol 1e-12, both restarted on
    # every held interval, over the first 2 s (scipy is slow)
    p = R.TLD(eta=eta, phi=phi, damping=damping, zeta=zeta, x0=0.03)
    dt, n = 1e-3, 2000
    a = R.harmonic_base(wr * p.omega_f, A, dt * np.arange(n))[2]
    r = R.simulate_held(p, dt, a)
    _, xs, vs = R.simulate_held_scipy(p, dt, a)
    assert R.rel_err(r.x, xs) < 1e-10
    assert R.rel_err(r.v, vs) < 1e-10


@pytest.mark.parametrize("dt,sub", [(1e-3, 1), (0.02, 4)])
def test_rk8_step_refinement(dt, sub):
    # Richardson-style check: doubling the substeps changes nothing above round-off, so the
    # substep counts used by the FMU tests are converged.
    p = R.TLD(eta=3.5, damping=R.DAMPING_CONSTANT, zeta=0.005)
    n = int(round(30 / dt))
    a = R.harmonic_base(p.omega_f, 0.002, dt * np.arange(n))[2]
    r1 = R.simulate_held(p, dt, a, substeps=sub)
    r2 = R.simulate_held(p, dt, a, substeps=2 * sub)
    assert R.rel_err(r1.x, r2.x) < 1e-10
    assert R.rel_err(r1.v, r2.v) < 1e-10


def test_reference_energy_balance_and_force_mean():
    p = R.TLD()
    dt, n = 1e-3, 20000
    a = R.harmonic_base(1.05 * p.omega_f, 0.005, dt * np.arange(n))[2]
    r = R.simulate_held(p, dt, a)
    bal = r.energy_input - r.energy_stored - r.energy_dissipated
    assert np.max(np.abs(bal)) / np.max(np.abs(r.energy_input)) < 1e-12
    assert np.all(np.diff(r.energy_dissipated) >= 0)
    # force.mean is the interval average of force: trapezoid of the end values agrees to O(dt^2)
    trap = 0.5 * (r.force[1:] + r.force[:-1])
    assert R.rel_err(r.force_mean[1:], trap) < 1e-4
