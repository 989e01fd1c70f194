"""TLD.fmu's directional derivatives in Model Exchange through fmpy (FMU2Model's
fmi2GetDirectionalDerivative), as an implicit solver's host uses them:
- the Jacobian of Eq 2.11's right-hand side against its closed form written here from the
  reference's Phi (tld_fmu.reference): d der(slosh.v)/d slosh.x = -Phi'(x),
  d der(slosh.v)/d slosh.v = -2 zeta omega_f, d force/d slosh.x = m Phi'(x), for integer and
  non-integer eta, x = 0 included;
- scipy's implicit Radau given the FMU's Jacobian integrates a free decay that starts deep in
  the hardening, against DOP853 at rtol 1e-12 on the reference's equations (whole history)."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tld_fmu import reference as R
from tld_fmu.contract import item
from tld_fmu.me_master import MeFmu

ZETA = 0.02
STATES = ["slosh.x", "slosh.v", "energy.input", "energy.dissipated"]
DERIVATIVES = [f"der({s})" for s in STATES]


def open_tld(fmu_path, model, eta, x0=0.0):
    return MeFmu(fmu_path, {"model": item("model", model), "amplitude": item("amplitude", "Fixed"),
                            "damping": R.DAMPING_CONSTANT, "zeta": ZETA, "eta": eta,
                            "slosh.x0": x0}, f"jac-{model}-{eta}")


def jacobian(tld, unknowns, knowns):
    """J's rows `unknowns` by columns `knowns`, one fmi2GetDirectionalDerivative per column."""
    u = [tld.vr[n] for n in unknowns]
    cols = [tld.fmu.getDirectionalDerivative(u, [tld.vr[k]], [1.0]) for k in knowns]
    return np.array(cols).T


def phi_slope(p, x):
    """Phi'(x) of the reference's Phi = w^2 x (1 + q |x|^(2 eta - 2)), differentiated by hand."""
    return p.omega_f ** 2 * (1.0 + (2 * p.eta - 1) * p._q() * np.abs(x) ** (2 * p.eta - 2))


@pytest.mark.parametrize("model", ["Nonlinear", "Auto"])
@pytest.mark.parametrize("eta", [2.0, 1.25, 2.7])
def test_jacobian_against_the_closed_form(fmu_path, model, eta):
    p = R.TLD().with_(damping=R.DAMPING_CONSTANT, zeta=ZETA, eta=eta)
    tld = open_tld(fmu_path, model, eta)
    try:
        c = 2 * ZETA * p.omega_f
        for x, v in [(0.0, 0.0), (1e-6, 0.02), (0.05, -0.3), (-0.11, 0.6)]:
            # The other states (S^2's impact mass, Linear's higher modes) at 0.
            tld.set_states(0.0, np.concatenate([[x, v, 0.0, 0.0], np.zeros(tld.nx - 4)]))
            J = jacobian(tld, DERIVATIVES + ["force"], STATES[:2])
            want = np.array([[0.0, 1.0],
                             [-phi_slope(p, x), -c],
                             [0.0, -tld.get("base.a") * p.m],
                             [0.0, 2 * p.m * c * v],
                             [p.m * phi_slope(p, x), p.m * c]])
            err = np.max(np.abs(J - want) / np.maximum(np.abs(want), 1e-12))
            assert err < 1e-10, (x, v, J, want)
    finally:
        tld.close()


def test_radau_with_the_fmus_jacobian_matches_dop853(fmu_path):
    """Free decay from x0 = 0.1 m (hardening phi |2x/a|^2 = 2.6 at eta = 2) over 10 s."""
    eta, x0, t_end = 2.0, 0.1, 10.0
    p = R.TLD().with_(damping=R.DAMPING_CONSTANT, zeta=ZETA, eta=eta)
    c = 2 * ZETA * p.omega_f
    t = np.linspace(0.0, t_end, 1001)
    ref = solve_ivp(lambda s, y: [y[1], -c * y[1] - p.Phi(y[0])], (0, t_end), [x0, 0.0],
                    t_eval=t, method="DOP853", rtol=1e-12, atol=1e-15)
    tld = open_tld(fmu_path, "Nonlinear", eta, x0)
    try:
        def rhs(s, y):
            tld.set_states(s, y)
            return tld.derivatives()

        # Every continuous state of the model description (those the model does not use have
        # derivative 0 and zero columns).
        states = [u.variable.derivative.name for u in tld.md.derivatives]

        def jac(s, y):
            tld.set_states(s, y)
            return jacobian(tld, [f"der({n})" for n in states], states)

        y0 = tld.states()
        runs = {}
        for name, j in [("exact J", jac), ("differenced J", None)]:
            sol = solve_ivp(rhs, (0, t_end), y0, t_eval=t, method="Radau", rtol=1e-10,
                            atol=1e-14, jac=j)
            assert sol.success, sol.message
            runs[name] = sol
        for name, sol in runs.items():
            ex = R.rel_err(sol.y[0], ref.y[0])
            print(f"Radau rtol 1e-10 with the {name}: slosh.x error {ex:.2e} of peak, "
                  f"{sol.nfev} derivative evaluations, {sol.njev} Jacobians")
            assert ex < 1e-7, name
    finally:
        tld.close()
