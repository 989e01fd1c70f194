"""Model Exchange: TLD.fmu and Building.fmu integrated by the host's own solver (fmpy's CVode,
rtol 1e-10), over whole histories, against independent references that see the same input as
the FMU. fmpy's CVode does not interpolate inputs inside its right-hand side: it sets them at
its output points only, while CVode has already stepped past them (so the input the FMU sees
depends on CVode's internal steps). The tests therefore give the input as a staircase (each
sample time twice): every step is an input event, where fmpy stops, sets the new value and
restarts CVode, and the FMU sees exactly the held samples:
- Linear (one mode): the exact solution for held samples (Van Loan matrix exponential, no time
  stepping, tld_fmu.reference.linear_zoh);
- Nonlinear (Eq 2.11, amplitude Fixed): scipy's DOP853 at rtol 1e-12 on every held interval
  (tld_fmu.reference.simulate_held_scipy);
- Building (one storey, its built-in harmonic ground motion): DOP853 on the storey's equation.
And the models Model Exchange does not offer are refused at fmi2ExitInitializationMode with
the reason."""
import numpy as np
import pytest
from fmpy import simulate_fmu
from scipy.integrate import solve_ivp

from tld_fmu import reference as R
from tld_fmu.contract import item
from tld_fmu.paths import BUILDING_FMU

DT, T_END = 0.01, 20.0
W, AMP = 5.5, 0.004                 # near resonance of the default tank (5.64 rad/s)
ZETA = 0.02
CVODE = dict(fmi_type="ModelExchange", solver="CVode", relative_tolerance=1e-10,
             output_interval=DT, stop_time=T_END)


def base_input():
    """Sample times t, samples a (each held until the next sample time) and fmpy's staircase."""
    t = DT * np.arange(int(round(T_END / DT)) + 1)
    a = -W ** 2 * AMP * np.sin(W * t)
    return t, a, R.staircase(t, a)


# CVode's global error over the 2000 restarts, as a fraction of the peak, at each tolerance
# (measured: Linear 2.1e-7 at 1e-10, 3.9e-9 at 1e-12): it falls with the tolerance, so it is the
# solver's, not the model's; a wrong equation would leave an error that does not.
# With 24 states (S^2's and the modes' 20, frozen at 0 here) measured: Linear 3.2e-7 at 1e-10,
# 1.0e-8 at 1e-12; Nonlinear and Auto 5.2e-7, 9.0e-9.
BOUND = {1e-10: 1e-6, 1e-12: 3e-8}
# Building, without restarts: CVode's BDF accumulates phase error on the lightly damped storey
# and the undamped built-in ground oscillator over 18 periods (measured 8.5e-7 at 1e-10,
# 1.2e-7 at 1e-12, 8e-9 at 1e-13, growing with time): the solver's, falling with its tolerance.
BUILDING_BOUND = {1e-10: 3e-6, 1e-12: 4e-7}


def run_tld(fmu_path, model, extra=None, rtol=1e-10):
    _, _, signal = base_input()
    start = {"model": model, "amplitude": item("amplitude", "Fixed"),
             "damping": R.DAMPING_CONSTANT, "zeta": ZETA, **(extra or {})}
    return simulate_fmu(str(fmu_path), input=signal, start_values=start,
                        output=["slosh.x", "slosh.v", "force", "energy.input",
                                "energy.dissipated", "energy.stored"],
                        **{**CVODE, "relative_tolerance": rtol})


def at(result, t):
    """The result's rows at the sample times (fmpy records each output point once)."""
    idx = np.searchsorted(result["time"], t - 1e-9)
    assert np.allclose(result["time"][idx], t, atol=1e-9)
    return result[idx]


@pytest.mark.parametrize("rtol", sorted(BOUND))
def test_linear_one_mode_against_its_exact_solution(fmu_path, rtol):
    t, a, _ = base_input()
    res = at(run_tld(fmu_path, item("model", "Linear"), {"modes": 1}, rtol), t)
    omega = R.mode(1)[1]
    x, v = R.linear_zoh(omega, ZETA, DT, a[:-1])
    ex, ev = R.rel_err(res["slosh.x"], x), R.rel_err(res["slosh.v"], v)
    print(f"Linear in ME (CVode {rtol:g}): slosh.x error {ex:.2e}, slosh.v {ev:.2e} of peak")
    assert ex < BOUND[rtol] and ev < BOUND[rtol]
    # The energy states balance as in Co-Simulation.
    bal = res["energy.input"] - res["energy.stored"] - res["energy.dissipated"]
    assert np.max(np.abs(bal)) < 1e-6 * np.max(np.abs(res["energy.input"]))


@pytest.mark.parametrize("model", ["Nonlinear", "Auto"])
@pytest.mark.parametrize("rtol", sorted(BOUND))
def test_nonlinear_against_dop853(fmu_path, rtol, model):
    """Auto in ME is the Nonlinear equations (its exact-linear shortcut steps Co-Simulation)."""
    t, a, _ = base_input()
    res = at(run_tld(fmu_path, item("model", model), rtol=rtol), t)
    p = R.TLD().with_(damping=R.DAMPING_CONSTANT, zeta=ZETA)
    _, xs, vs = R.simulate_held_scipy(p, DT, a[:-1], rtol=1e-12, zeta=ZETA)
    ex, ev = R.rel_err(res["slosh.x"], np.array(xs)), R.rel_err(res["slosh.v"], np.array(vs))
    ef = R.rel_err(res["force"], p.force(np.array(xs), np.array(vs), zeta=ZETA))
    print(f"{model} in ME (CVode {rtol:g}): slosh.x {ex:.2e}, slosh.v {ev:.2e}, force {ef:.2e} of peak")
    assert ex < BOUND[rtol] and ev < BOUND[rtol] and ef < BOUND[rtol]


@pytest.mark.parametrize("rtol", sorted(BUILDING_BOUND))
def test_building_against_dop853(rtol):
    m, k, zeta, A, w = 168.0, 5342.0, 0.02, 0.01, 5.0
    res = simulate_fmu(str(BUILDING_FMU), start_values={"ground.amplitude": A, "ground.omega": w},
                       output=["roof.x", "tld.x"], **{**CVODE, "relative_tolerance": rtol})
    omega = np.sqrt(k / m)
    t = DT * np.arange(int(round(T_END / DT)) + 1)
    res = at(res, t)
    # u'' + 2 zeta omega u' + omega^2 u = -a_g, a_g = -A w^2 sin(w t), from rest
    sol = solve_ivp(lambda s, y: [y[1], A * w * w * np.sin(w * s) - 2 * zeta * omega * y[1]
                                  - omega ** 2 * y[0]], (0, T_END), [0.0, 0.0], t_eval=t,
                    method="DOP853", rtol=1e-12, atol=1e-15)
    eu = R.rel_err(res["roof.x"], sol.y[0])
    ex = R.rel_err(res["tld.x"], A * np.sin(w * t) + sol.y[0])
    print(f"Building in ME (CVode {rtol:g}): roof.x error {eu:.2e}, tld.x {ex:.2e} of peak")
    assert eu < BUILDING_BOUND[rtol] and ex < BUILDING_BOUND[rtol]


@pytest.mark.parametrize("start, why", [
    ({"model": item("model", "ShallowWater")}, "use Co-Simulation"),
    ({"model": item("model", "Linear"), "modes": 11}, "modes <= 10"),
])
def test_models_not_offered_say_why(fmu_path, start, why):
    messages = []
    with pytest.raises(Exception):
        simulate_fmu(str(fmu_path), start_values=start, stop_time=0.1,
                     logger=lambda *args: messages.append(str(args[-1])), **{
                         k: v for k, v in CVODE.items() if k != "stop_time"})
    assert any(why in m for m in messages), messages


def test_coupled_in_one_solver_has_no_coupling_error(fmu_path):
    """Issue 27, item 4: Building.fmu and TLD.fmu in ME, one ODE system, one solver (DOP853 at
    rtol 1e-10), against the monolithic solution of the same equations (the case of
    test_cosim.py: Table 2.1's structure at resonance, Nonlinear TLD with A_e = 2 mm Fixed),
    where the co-simulations' errors are O(h) (a few 1e-2 at 1 ms held) and O(h^2)."""
    from tld_fmu import sdof as demo
    from tld_fmu.me_master import MeFmu, coupled

    p = R.TLD(A_e=0.002)
    w, A_g, t_end = demo.W_S, 1e-4, 20.0
    tld = MeFmu(fmu_path, {"amplitude": item("amplitude", "Fixed"), "A_e": p.A_e}, "tld")
    building = MeFmu(BUILDING_FMU, {
        "storey[1].mass": demo.M_S, "storey[1].stiffness": demo.K_S, "damping.zeta": demo.ZETA_S,
        "tld.mass": tld.get("mass.inactive"), "ground.amplitude": A_g, "ground.omega": w}, "building")
    try:
        # Building's Rayleigh damping of its one mode, with the damper's inactive mass on it
        C = building.get("damping.alpha") * (demo.M_S + p.m0) + building.get("damping.beta") * demo.K_S
        t = np.linspace(0.0, t_end, 2001)
        r = coupled(building, tld, t, rtol=1e-10)
    finally:
        tld.close()
        building.close()
    X, V, x, v = R.coupled_monolithic(p, demo.M_S, C, demo.K_S, w, A_g, t, rtol=1e-12)
    eX, ex = R.rel_err(r["X"], X), R.rel_err(r["x"], x)
    print(f"ME coupled in one solver (DOP853 rtol 1e-10) vs monolithic: structure {eX:.2e}, "
          f"sloshing {ex:.2e} of peak (peak X {1e3 * np.max(np.abs(X)):.3f} mm, "
          f"peak x {1e3 * np.max(np.abs(x)):.3f} mm)")
    assert eX < 1e-7 and ex < 1e-7


def test_fmpy_validates_both_fmus_with_model_exchange(fmu_path):
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    # TLD: 4 states of every oscillator model, S^2's impact mass (2), Linear's modes 2-10 (18),
    # the amplitude estimator's 7 (31); S^2's two walls as
    # event indicators.
    for path, states, indicators in [(fmu_path, 31, 2), (BUILDING_FMU, 44, 0)]:
        assert validate_fmu(str(path)) == [], path
        md = read_model_description(str(path))
        assert md.modelExchange is not None and md.coSimulation is not None
        assert md.numberOfContinuousStates == states
        assert md.numberOfEventIndicators == indicators


# slosh.x of ME against CS under the sampled input, by rtol (see the test's docstring).
SAMPLED_BOUND = {1e-6: 0.25, 1e-8: 5e-2}


@pytest.mark.parametrize("rtol", sorted(SAMPLED_BOUND))
def test_defaults_run_in_me_under_a_sampled_input(fmu_path, rtol):
    """What a host does first: the default parameters (amplitude = Tracked) and an input sampled
    every 10 ms (not a staircase: fmpy sets it at its output points and, interpolated, in its
    root function at every internal CVode step), through fmpy's CVode. The run must go through
    (no refusal, no Discard of a solver's trial state) and track the 4 mm excitation; the motion
    follows Co-Simulation's at 10 ms, whose estimator filters samples held over each step (first
    order in the step: tests/model_exchange_tracked.rs measures slosh.x 5.5e-3 at 2 ms, 2.7e-3
    at 1 ms against ME) and whose held input differs from what CVode sees (the input at CVode's
    own step ends, which the tolerance sets): measured 1.0e-1 and 2.4e-2 of the peak at rtol
    1e-6 and 1e-8, so bounds 0.25 and 5e-2 (the estimators' and the input's difference, not the
    model's; accuracy against references is the staircase tests', test_me_tracked.py's and
    model_exchange_tracked.rs's job). The bound at 1e-6 was 5e-2 and is loosened: amplitude =
    Fixed under the same input measures 1.6e-1 (long steps at 1e-6, the input seen late);
    Tracked measured 1.5e-2 only while its rebuilt velocity's nominal was 25 times smaller than
    slosh.v's, which forced short steps (and stopped CVode at rtol 1e-10:
    docs/MODEL_EXCHANGE.md). rtol 1e-10 under this input: test_me_tracked.py (20 s of it take
    2 min)."""
    t = DT * np.arange(int(round(T_END / DT)) + 1)
    signal = np.zeros(len(t), dtype=[("time", np.float64), ("base.a", np.float64)])
    signal["time"], signal["base.a"] = t, -W ** 2 * AMP * np.sin(W * t)
    out = ["slosh.x", "A_e.estimate"]
    me = simulate_fmu(str(fmu_path), input=signal, output=out, fmi_type="ModelExchange",
                      solver="CVode", relative_tolerance=rtol, output_interval=DT,
                      stop_time=T_END)
    cs = simulate_fmu(str(fmu_path), input=signal, output=out, output_interval=DT,
                      stop_time=T_END)
    me = at(me, t)
    ex = R.rel_err(me["slosh.x"], cs["slosh.x"])
    print(f"defaults in ME (CVode {rtol:g}), sampled input: slosh.x vs CS {ex:.1e} of peak, "
          f"A_e.estimate {me['A_e.estimate'][-1] * 1e3:.3f} mm")
    assert abs(me["A_e.estimate"][-1] - AMP) < 0.05 * AMP
    assert ex < SAMPLED_BOUND[rtol]
