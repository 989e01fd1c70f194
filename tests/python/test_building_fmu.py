"""Building.fmu (the reference structure for TLD.fmu) through fmpy, against references computed here independently of
its Rust code: the matrices and Rayleigh coefficients are rebuilt from the parameters with
scipy, and

- the exact step: whole histories under held and ramped (input derivatives) inputs against
  scipy's DOP853 (rtol 1e-12) integrating the same piecewise input step by step, at a step so
  large that any integration of the FMU's own would show;
- a 1-storey harmonic steady state against its closed form, a 3-storey one against the complex
  frequency response (modal superposition), after the transient has died out;
- the built-in ground motion (ground.amplitude, ground.omega): exact at any step, the limit of
  the same motion through ground.a with derivatives (third order), the absolute outputs the
  ground's whole motion; a 1-storey steady state against the closed-form transmissibility;
- the declared modes and damping against scipy's generalised eigenproblem;
- fmpy's validate_fmu (the compliance checkers run on both FMUs in test_compliance.py).
"""
from __future__ import annotations

import shutil
import tempfile

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp

THREE = dict(masses=[60.0, 60.0, 50.0], stiffnesses=[9600.0, 8230.0, 6860.0], zeta=0.05,
             tld_mass=0.35)


@pytest.fixture(scope="module")
def building(building_path):
    from fmpy import extract, read_model_description
    md = read_model_description(str(building_path))
    d = tempfile.mkdtemp(prefix="building_fmu_")
    extract(str(building_path), d)
    yield md, d, {v.name: v.valueReference for v in md.modelVariables}
    shutil.rmtree(d, ignore_errors=True)


class Run:
    """One initialised Building.fmu instance."""

    def __init__(self, building, masses, stiffnesses, zeta, tld_mass=0.0, floor=0, ground=(0.0, 0.0)):
        """ground: (ground.amplitude, ground.omega), the built-in motion."""
        from fmpy.fmi2 import FMU2Slave
        md, d, self.vr = building
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier="Building",
                             instanceName="building")
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        n = len(masses)
        self.fmu.setInteger([self.vr["storeys"], self.vr["tld.floor"]], [n, floor])
        names = [f"storey[{i + 1}].mass" for i in range(n)] + \
                [f"storey[{i + 1}].stiffness" for i in range(n)] + ["damping.zeta", "tld.mass"]
        names += ["ground.amplitude", "ground.omega"]
        self.fmu.setReal([self.vr[k] for k in names],
                         list(masses) + list(stiffnesses) + [zeta, tld_mass] + list(ground))
        self.fmu.exitInitializationMode()
        self.n, self.t = n, 0.0

    def get(self, *names):
        return self.fmu.getReal([self.vr[k] for k in names])

    def step(self, h, inputs, rates=None, rates2=None):
        """inputs/rates/rates2: {name: value}; rates, rates2 are order-1 and order-2 input
        derivatives over the step."""
        self.fmu.setReal([self.vr[k] for k in inputs], list(inputs.values()))
        for order, r in ((1, rates), (2, rates2)):
            if r:
                names = list(r)
                self.fmu.setRealInputDerivatives([self.vr[k] for k in names], [order] * len(names),
                                                 list(r.values()))
        self.fmu.doStep(self.t, h)
        self.t += h

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def matrices(masses, stiffnesses, zeta, tld_mass=0.0, floor=None):
    """M, C, K and the circular frequencies, rebuilt here (scipy), Rayleigh at modes 1 and 2."""
    n = len(masses)
    m = np.array(masses, float)
    m[(floor or n) - 1] += tld_mass
    k = np.array(stiffnesses, float)
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] = k[i] + (k[i + 1] if i + 1 < n else 0.0)
        if i + 1 < n:
            K[i, i + 1] = K[i + 1, i] = -k[i + 1]
    M = np.diag(m)
    w = np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True))
    if n == 1:
        alpha, beta = zeta * w[0], zeta / w[0]
    else:
        # zeta = alpha/(2 w) + beta w/2 at w1 and w2
        alpha, beta = np.linalg.solve([[1 / (2 * w[0]), w[0] / 2], [1 / (2 * w[1]), w[1] / 2]],
                                      [zeta, zeta])
    return M, alpha * M + beta * K, K, w, (alpha, beta)


def test_validate_fmu(building_path):
    from fmpy.validation import validate_fmu
    problems = validate_fmu(str(building_path))
    assert problems == [], "\n".join(problems)


def test_modes_and_rayleigh_coefficients(building):
    M, C, K, w, (alpha, beta) = matrices(**THREE)
    run = Run(building, **THREE)
    got = run.get("mode[1].omega", "mode[2].omega", "damping.alpha", "damping.beta")
    run.close()
    np.testing.assert_allclose(got, [w[0], w[1], alpha, beta], rtol=1e-10)


def reference_history(M, C, K, h, steps, ground, force, floor, ramp):
    """z = [u, u', x_g, v_g] at every communication point by DOP853 (rtol 1e-12), each step
    integrated on its own with the input the FMU gets: held at its value at the step's start,
    or (ramp) its value plus its slope times the time into the step."""
    n = len(M)
    Minv = np.linalg.inv(M)
    z = np.zeros(2 * n + 2)
    out = [z.copy()]
    for j in range(steps):
        t0 = j * h

        def inputs(s):
            ag, fd = ground(t0), force(t0)
            if ramp:
                eps = 1e-7
                ag += s * (ground(t0 + eps) - ground(t0 - eps)) / (2 * eps)
                fd += s * (force(t0 + eps) - force(t0 - eps)) / (2 * eps)
            return ag, fd

        def rhs(s, y):
            u, v = y[:n], y[n:2 * n]
            ag, fd = inputs(s)
            f = np.zeros(n)
            f[floor - 1] = fd
            acc = Minv @ (f - C @ v - K @ u) - ag
            return np.concatenate([v, acc, [y[2 * n + 1], ag]])

        sol = solve_ivp(rhs, (0.0, h), z, method="DOP853", rtol=1e-12, atol=1e-15)
        assert sol.success
        z = sol.y[:, -1]
        out.append(z.copy())
    return np.array(out)


@pytest.mark.parametrize("ramp", [False, True], ids=["held", "ramped"])
@pytest.mark.parametrize("storeys", [1, 3])
def test_exact_step_against_dop853(building, storeys, ramp):
    p = THREE if storeys == 3 else dict(masses=[168.0], stiffnesses=[5342.0], zeta=0.02, tld_mass=0.5)
    M, C, K, w, _ = matrices(**p)
    n, floor = len(M), len(M)
    h = 0.5 * 2 * np.pi / w[-1]   # half the shortest period: far beyond any integrator's step
    steps = 40
    ground = lambda t: 0.7 * np.sin(3.1 * t) + 0.2 * np.cos(7.3 * t)
    force = lambda t: 3.0 * np.sin(5.0 * t + 0.3)
    ref = reference_history(M, C, K, h, steps, ground, force, floor, ramp)
    run = Run(building, **p)
    names = [f"floor[{i + 1}].x" for i in range(n)]
    got = [run.get(*names) + run.get("tld.x")]
    eps = 1e-7
    for j in range(steps):
        t = j * h
        rates = None
        if ramp:
            rates = {"ground.a": (ground(t + eps) - ground(t - eps)) / (2 * eps),
                     "tld.force": (force(t + eps) - force(t - eps)) / (2 * eps)}
        run.step(h, {"ground.a": ground(t), "tld.force": force(t)}, rates)
        got.append(run.get(*names) + run.get("tld.x"))
    run.close()
    got = np.array(got)
    want = np.column_stack([ref[:, :n], ref[:, 2 * n] + ref[:, floor - 1]])
    # each output against its own largest value (the absolute tld.x carries the ground's drift)
    scale = np.abs(want).max(axis=0)
    err = (np.abs(got - want).max(axis=0) / scale).max()
    print(f"{storeys} storeys, {'ramped' if ramp else 'held'}: h = {h:.4f} s, "
          f"largest error {err:.2e} of each output's largest value")
    assert err < 1e-9


def test_one_storey_harmonic_steady_state_is_the_closed_form(building):
    m, k, zeta, A, wf = 168.0, 5342.0, 0.05, 0.3, 4.0
    run = Run(building, [m], [k], zeta)
    h, T = 0.002, 80.0
    steps = int(T / h)
    xs = []
    for j in range(steps):
        t = j * h
        run.step(h, {"ground.a": A * np.sin(wf * t)},
                 {"ground.a": A * wf * np.cos(wf * t)})
        if run.t > T - 2 * np.pi / wf:
            xs.append(run.get("floor[1].x")[0])
    run.close()
    # u'' + 2 zeta w u' + w^2 u = -A sin(wf t): amplitude A / sqrt((w^2 - wf^2)^2 + (2 zeta w wf)^2)
    w = np.sqrt(k / m)
    want = A / np.sqrt((w ** 2 - wf ** 2) ** 2 + (2 * zeta * w * wf) ** 2)
    got = 0.5 * (max(xs) - min(xs))
    assert abs(got - want) / want < 1e-4, (got, want)


BUILT_IN = ["floor[1].x", "floor[2].x", "roof.x", "base_shear", "tld.a", "floor[1].a", "tld.v", "tld.x"]


def built_in_history(building, h, t_end, ground, through_input):
    """THREE under the ground displacement A sin(w t), ground = (A, w): built in, or (through_input)
    as ground.a = -A w^2 sin(w t) with its first and second derivatives at each step's start.
    The outputs BUILT_IN at every time t_end / 20."""
    A, w = ground
    run = Run(building, **THREE, ground=(0.0, 0.0) if through_input else ground)
    every = int(round(t_end / h / 20))
    rows = []
    for j in range(int(round(t_end / h))):
        t = j * h
        if through_input:
            run.step(h, {"ground.a": -A * w * w * np.sin(w * t)}, {"ground.a": -A * w ** 3 * np.cos(w * t)},
                     {"ground.a": A * w ** 4 * np.sin(w * t)})
        else:
            run.step(h, {})
        if (j + 1) % every == 0:
            rows.append(run.get(*BUILT_IN))
    run.close()
    return np.array(rows), np.arange(1, len(rows) + 1) * every * h


def test_built_in_ground_motion_is_exact_and_what_ground_a_converges_to(building):
    """The built-in motion is exact at any step (h and h/5 agree to round-off), and the same
    motion fed through ground.a with derivatives (a quadratic over each step, where the sine
    is not one) converges to it at third order. The relative motion and the absolute
    accelerations agree; the absolute velocity and displacement differ by the ground's start:
    the built-in ground moves at A w from t = 0, ground.a's ground starts at rest (tld.v differs
    by A w, tld.x by A w t)."""
    _, _, _, w, _ = matrices(**THREE)
    ground = (2e-3, 0.93 * w[0])
    A, wg = ground
    t_end = 4.0
    exact = {h: built_in_history(building, h, t_end, ground, False) for h in (0.05, 0.01)}
    (b1, t), (b2, _) = exact[0.05], exact[0.01]
    scale = np.abs(b1).max(axis=0)
    assert np.all(scale > 0)
    step_free = (np.abs(b1 - b2).max(axis=0) / scale).max()
    assert step_free < 1e-12, f"the built-in motion depends on the step: {step_free:.2e}"
    err = {}
    for h in (0.05, 0.025):
        g, _ = built_in_history(building, h, t_end, ground, True)
        g[:, BUILT_IN.index("tld.v")] += A * wg
        g[:, BUILT_IN.index("tld.x")] += A * wg * t
        err[h] = (np.abs(g - b1).max(axis=0) / scale).max()
    ratio = err[0.05] / err[0.025]
    print(f"\nbuilt-in vs ground.a with derivatives: {err[0.05]:.2e} at h = 0.05, {err[0.025]:.2e} at "
          f"0.025 (ratio {ratio:.2f}); built-in at h = 0.05 vs 0.01: {step_free:.1e}")
    assert 7.0 < ratio < 9.0, f"third order expected (8), got {ratio:.2f}"
    assert err[0.05] < (wg * 0.05) ** 3


def test_one_storey_built_in_steady_state_is_the_transmissibility(building):
    """One storey under the built-in x_g = A sin(w t): after the transient, the absolute
    displacement tld.x has the amplitude A sqrt((k^2 + (c w)^2) / ((k - m w^2)^2 + (c w)^2))
    and the relative one A m w^2 / sqrt((k - m w^2)^2 + (c w)^2)."""
    m, k, zeta, A, wf = 168.0, 5342.0, 0.05, 1e-3, 4.0
    run = Run(building, [m], [k], zeta, ground=(A, wf))
    h, T = 0.01, 80.0
    rows = []
    for _ in range(int(T / h)):
        run.step(h, {})
        if run.t > T - 2 * np.pi / wf:
            rows.append(run.get("tld.x", "floor[1].x"))
    run.close()
    rows = np.array(rows)
    c = 2 * zeta * np.sqrt(k * m)
    d = np.sqrt((k - m * wf ** 2) ** 2 + (c * wf) ** 2)
    want = [A * np.sqrt(k ** 2 + (c * wf) ** 2) / d, A * m * wf ** 2 / d]
    got = 0.5 * (rows.max(axis=0) - rows.min(axis=0))
    np.testing.assert_allclose(got, want, rtol=1e-4)


def test_three_storey_harmonic_steady_state_is_the_frequency_response(building):
    M, C, K, w, _ = matrices(**THREE)
    A, wf = 0.2, 0.95 * w[0]
    run = Run(building, **THREE)
    h, T = 0.002, 90.0
    steps = int(T / h)
    names = ["floor[1].x", "floor[2].x", "floor[3].x", "tld.a"]
    rows = []
    for j in range(steps):
        t = j * h
        run.step(h, {"ground.a": A * np.sin(wf * t)}, {"ground.a": A * wf * np.cos(wf * t)})
        if run.t > T - 2 * np.pi / wf:
            rows.append([run.t] + run.get(*names))
    run.close()
    rows = np.array(rows)
    # complex amplitude U of u = Im(U e^{i wf t}): (K - wf^2 M + i wf C) U = -M 1 A
    U = np.linalg.solve(K - wf ** 2 * M + 1j * wf * C, -M @ np.ones(3) * A)
    t = rows[:, 0]
    for i in range(3):
        want = np.imag(U[i] * np.exp(1j * wf * t))
        assert np.abs(rows[:, 1 + i] - want).max() < 1e-4 * np.abs(U[i]), i
    # absolute roof acceleration: -wf^2 u_3 + a_g
    want_a = np.imag((-wf ** 2 * U[2] + A) * np.exp(1j * wf * t))
    assert np.abs(rows[:, 4] - want_a).max() < 1e-4 * np.abs(-wf ** 2 * U[2] + A)


def test_bad_input_is_refused_and_the_instance_goes_on(building):
    from fmpy.fmi1 import FMICallException
    run = Run(building, **THREE)
    run.step(0.01, {"ground.a": 0.1})
    before = run.get("roof.x", "tld.a")
    with pytest.raises(FMICallException):
        run.fmu.setReal([run.vr["ground.a"]], [float("nan")])
    with pytest.raises(FMICallException):
        run.fmu.doStep(run.t, -0.01)
    assert run.get("roof.x", "tld.a") == before
    run.step(0.01, {"ground.a": 0.1})
    run.close()


def test_capabilities_and_model_structure(building_path):
    """The declared feedthrough is the equations': absolute accelerations depend on the forces
    (tld.a on tld.force and every floor force, floor[i].a on its own force and tld.force) and
    not on ground.a; displacements, velocities and the base shear on the state only."""
    from fmpy import read_model_description
    md = read_model_description(str(building_path))
    cs = md.coSimulation
    assert cs.modelIdentifier == "Building" and cs.canHandleVariableCommunicationStepSize
    assert cs.canInterpolateInputs and cs.maxOutputDerivativeOrder >= 1
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate and not cs.needsExecutionTool
    all_deps = {u.variable.name: {d.name for d in (u.dependencies or [])} for u in md.outputs}
    inputs = {v.name for v in md.modelVariables if v.causality == "input"}
    # on inputs (Co-Simulation's feedthrough); the rest are Model Exchange's continuous states
    deps = {n: d & inputs for n, d in all_deps.items()}
    states = {d.variable.derivative.name for d in md.derivatives}
    assert len(states) == 44 and all(d - inputs <= states for d in all_deps.values())
    assert all_deps["roof.x"] == {f"floor[{i}].x" for i in range(1, 21)}
    floors = {f"floor[{i}].force" for i in range(1, 21)}
    assert deps["tld.a"] == {"tld.force"} | floors
    for i in range(1, 21):
        assert deps[f"floor[{i}].a"] == {"tld.force", f"floor[{i}].force"}
        assert deps[f"floor[{i}].x"] == set()
    for n in ("tld.v", "tld.x", "roof.x", "base_shear"):
        assert deps[n] == set(), n
    assert all("ground.a" not in d for d in deps.values())


def test_libcosim_runs_it_as_fmpy_does(building, building_path):
    """libcosim (fixed step in integer nanoseconds, override manipulator, last-value observer,
    a worker thread) and fmpy on libcosim's time grid give the same roof history to round-off
    (the step sizes may differ in their last bits): the host adds nothing."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave
    log_output_level(CosimLogLevel.WARNING)
    _, _, vr = building
    ns, n = 10_000_000, 300
    ground = [0.3 * np.sin(0.05 * k) for k in range(n)]
    ex = CosimExecution.from_step_size(ns)
    i = ex.add_local_slave(CosimLocalSlave(fmu_path=str(building_path), instance_name="building"))
    assert i >= 0
    assert ex.integer_initial_value(i, vr["storeys"], 3)
    man, obs = CosimManipulator.create_override(), CosimObserver.create_last_value()
    assert ex.add_manipulator(man) and ex.add_observer(obs)
    cosim = []
    for k in range(n):
        assert man.slave_real_values(i, [vr["ground.a"]], [ground[k]])
        assert ex.step(1)
        cosim.append(obs.last_real_values(i, [vr["roof.x"]])[0])
    del ex
    run = Run(building, [168.0] * 3, [5342.0] * 3, 0.02)
    direct = []
    for k in range(n):
        t0, t1 = k * ns * 1e-9, (k + 1) * ns * 1e-9
        run.fmu.setReal([vr["ground.a"]], [ground[k]])
        run.fmu.doStep(t0, t1 - t0)
        direct.append(run.get("roof.x")[0])
    run.close()
    assert np.abs(direct).max() > 1e-4
    np.testing.assert_allclose(cosim, direct, rtol=1e-12, atol=1e-15)


def test_fmpy_simulate_fmu_with_interpolated_inputs_is_exact(building_path):
    """fmpy's own master (simulate_fmu) with a ground acceleration table, linearly interpolated
    and passed on with fmi2SetRealInputDerivatives (set_input_derivatives=True): the input over
    every communication step is then linear, value and slope as fmpy computes them at the
    step's start (at a knot fmpy takes the slope of the segment before it, and 0 at t = 0), so
    the whole history matches DOP853 on that same input to round-off."""
    from fmpy import simulate_fmu
    p = THREE
    M, C, K, w, _ = matrices(**p)
    n, h = len(M), 0.01
    knots = np.arange(0.0, 5.0 + 1e-9, 0.05)
    values = 0.5 * np.sin(2.3 * knots) + 0.3 * np.cos(7.0 * knots)
    # fmpy (0.3.x, simulation.py, Input) sizes its buffer of input derivatives for exactly nine
    # inputs ((value_type * 9)()): the table gives nine, the eight forces zero
    forces = ["tld.force"] + [f"floor[{i}].force" for i in range(1, 8)]
    zeros = [0.0] * len(forces)
    signal = np.array([(t, v, *zeros) for t, v in zip(knots, values)],
                      dtype=[("time", np.float64), ("ground.a", np.float64)]
                      + [(f, np.float64) for f in forces])
    start = {"storeys": 3, "damping.zeta": p["zeta"], "tld.mass": p["tld_mass"]}
    for i in range(n):
        start[f"storey[{i + 1}].mass"] = p["masses"][i]
        start[f"storey[{i + 1}].stiffness"] = p["stiffnesses"][i]
    res = simulate_fmu(str(building_path), stop_time=5.0, output_interval=h, input=signal,
                       start_values=start, output=["roof.x"], set_input_derivatives=True)
    Minv = np.linalg.inv(M)
    slopes = np.diff(values) / np.diff(knots)

    def host_input(t):
        """Value and slope fmpy sets at the start t of a step."""
        k = int(np.searchsorted(knots, t))
        return np.interp(t, knots, values), (0.0 if k == 0 else slopes[k - 1])

    y, want = np.zeros(2 * n), [0.0]
    times = res["time"]
    for t0, t1 in zip(times[:-1], times[1:]):
        a0, da = host_input(t0)

        def rhs(s, y):
            u, v = y[:n], y[n:]
            return np.concatenate([v, Minv @ (-C @ v - K @ u) - (a0 + da * s)])

        y = solve_ivp(rhs, (0.0, t1 - t0), y, method="DOP853", rtol=1e-12, atol=1e-15).y[:, -1]
        want.append(y[n - 1])
    want = np.array(want)
    assert np.abs(want).max() > 1e-4
    err = np.abs(res["roof.x"] - want).max() / np.abs(want).max()
    print(f"simulate_fmu with input derivatives: largest roof error {err:.2e}")
    assert err < 1e-9
