"""model = Linear (Eqs 2.1/2.2): `modes` damped oscillators advanced by their exact solution.

Each mode is checked separately against the reference's matrix-exponential (Van Loan) solution
of the same held-input problem, which shares no code with the FMU, at communication steps up to
a quarter of the fundamental period: an exact propagator has no step-size error."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tld_fmu import reference as R
from tld_fmu.contract import item

ZETA = 0.02
LINEAR = item("model", "Linear")


def run(slave_factory, dt, a, modes, outputs, extra=None):
    s = slave_factory(quiet=True)
    s.initialize({"model": LINEAR, "modes": modes, "damping": R.DAMPING_CONSTANT, "zeta": ZETA,
                  **(extra or {})})
    return s, s.run(dt, {"base.a": a}, outputs)


@pytest.mark.parametrize("dt", [1e-3, 0.05, 0.2785])
def test_each_mode_against_the_exact_held_solution(slave_factory, dt):
    n = int(round(30.0 / dt))
    t = dt * np.arange(n)
    rng = np.random.default_rng(7)
    a = np.sin(5.0 * t) + 0.5 * rng.standard_normal(n)   # resonant part plus broadband part
    modes = 3
    s, out = run(slave_factory, dt, a, modes, ["slosh.x", "slosh.v", "force", "mass.slosh"])
    geo = R.TLD().geo
    force = np.zeros(n + 1)
    total_mass = 0.0
    for k in range(1, modes + 1):
        ratio, omega = R.mode(k)
        mass = ratio * geo["mass.liquid"]
        x, v = R.linear_zoh(omega, ZETA, dt, a)
        if k == 1:
            # slosh.x / slosh.v show the fundamental mode
            assert R.rel_err(out["slosh.x"], x) < 1e-10, R.rel_err(out["slosh.x"], x)
            assert R.rel_err(out["slosh.v"], v) < 1e-10
        force += mass * (2 * ZETA * omega * v + omega ** 2 * x)
        total_mass += mass
    err = R.rel_err(out["force"], force)
    print(f"dt {dt}: force error {err:.2e} of its peak (3 modes)")
    assert err < 1e-10
    assert out["mass.slosh"][0] == pytest.approx(total_mass, rel=1e-12)
    assert s.get("mass.inactive") == pytest.approx(geo["mass.liquid"] - total_mass, rel=1e-12)


def test_energies_balance_and_dissipation_grows(slave_factory):
    dt, n = 0.01, 6000
    t = dt * np.arange(n)
    a = -(5.5 ** 2) * 0.004 * np.sin(5.5 * t)
    _, out = run(slave_factory, dt, a, 5, ["energy.input", "energy.stored", "energy.dissipated"],
                 extra={"slosh.x0": 0.01})
    bal = np.max(np.abs(out["energy.input"] - out["energy.stored"] - out["energy.dissipated"]))
    assert bal < 1e-12 * np.max(np.abs(out["energy.input"]))
    assert np.all(np.diff(out["energy.dissipated"]) >= 0)
    assert out["energy.dissipated"][-1] > 0


def test_interpolated_input_is_followed_exactly(slave_factory):
    """With input derivatives the propagator is exact for a quadratic input: against scipy's
    DOP853 at rtol 1e-12 on the continuous (piecewise-quadratic) input, at 0.1 s steps."""
    dt, n = 0.1, 100
    t = dt * np.arange(n)
    a0, a1, a2 = np.cos(3.0 * t), -3.0 * np.sin(3.0 * t), -9.0 * np.cos(3.0 * t)
    s = slave_factory(quiet=True)
    s.initialize({"model": LINEAR, "modes": 1, "damping": R.DAMPING_CONSTANT, "zeta": ZETA})
    out = s.run(dt, {"base.a": a0}, ["slosh.x"],
                derivatives={("base.a", 1): a1, ("base.a", 2): a2})
    _, omega = R.mode(1)

    def f(tt, y):
        k = min(int(tt / dt + 1e-9), n - 1)
        s_ = tt - k * dt
        ab = a0[k] + a1[k] * s_ + 0.5 * a2[k] * s_ ** 2
        return [y[1], -ab - 2 * ZETA * omega * y[1] - omega ** 2 * y[0]]

    x = [0.0]
    y = [0.0, 0.0]
    for k in range(n):
        sol = solve_ivp(f, (k * dt, (k + 1) * dt), y, method="DOP853", rtol=1e-12, atol=1e-15)
        y = sol.y[:, -1]
        x.append(y[0])
    assert R.rel_err(out["slosh.x"], np.array(x)) < 1e-9
