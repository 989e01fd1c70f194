"""scripts/building.py (tld_fmu.building) against the monolithic solution of the same coupled equations (issue:
'a comparison with the monolithic solution of the same coupled equations for the linear case
(error order vs communication step)'). With model = Linear (one mode) the building + dampers are
one linear system, integrated by scipy's DOP853 at rtol 1e-11 (building.monolithic):

    M_eff X'' + C X' + K X = -M_eff 1 a_g + sum_d e_d m_d (c_d x_d' + w_d^2 x_d)
    x_d'' + c_d x_d' + w_d^2 x_d = -(a_g + X_floor(d)'')

The co-simulation holds each damper's force over a step (force.mean after the first): first
order in the communication step."""
import math
import tempfile
import tomllib

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tld_fmu import building
from tld_fmu.paths import REPO

CFG = tomllib.loads((REPO / "scripts" / "examples" / "building.toml").read_text())
ZETA = 0.02


@pytest.mark.parametrize("derivatives", [False, True], ids=["held", "derivatives"])
@pytest.mark.parametrize("load", ["ground", "floor_forces"])
def test_cosimulation_converges_to_the_monolithic_solution(fmu_path, model_description, unzipdir, load,
                                                           derivatives):
    """load = ground: harmonic ground motion; floor_forces: forces on every floor (the path the
    wind loading takes), here a smooth known function so that the monolithic solver sees the
    same load at every instant. held: first order; derivatives (force rates out, base.a rates
    in): second order."""
    cfg = {**CFG, "dampers": [{**d, "params": {"model": "Linear", "modes": 1, "damping": "Constant", "zeta": ZETA}}
                              for d in CFG["dampers"]]}
    b = cfg["building"]
    w = 0.97 * building.Building(b["masses"], b["stiffnesses"], b["rayleigh"]).omega1
    Ag = 2e-4
    n_floors = len(b["masses"])
    if load == "ground":
        ground = building.harmonic_ground(w, Ag)
        wind = lambda t: np.zeros(n_floors)  # noqa: E731
    else:
        ground = lambda t: (0.0, 0.0, 0.0)  # noqa: E731
        # floor i: (0.5 + 0.25 i) N at w, plus a slower component, different phase per floor
        wind = lambda t: np.array([(0.5 + 0.25 * i) * math.sin(w * t + i) + 0.3 * math.cos(0.4 * w * t)  # noqa: E731
                                   for i in range(n_floors)])
    T = 20.0
    # the dampers' masses and frequency, as the FMU reports them
    from fmpy.fmi2 import FMU2Slave  # noqa: F401  (the Damper class uses it)
    probe = building.Damper(unzipdir, model_description, cfg["dampers"][0]["floor"],
                            cfg["dampers"][0]["tanks"], cfg["dampers"][0]["params"], "probe")
    var = probe.var
    m_d, w_d = probe.fmu.getReal([var["mass.slosh"].valueReference, var["omega_f"].valueReference])
    inactive, floor = probe.inactive, probe.floor
    probe.close()
    extra = np.zeros(len(b["masses"]))
    extra[floor] = inactive
    bld = building.Building(b["masses"], b["stiffnesses"], b["rayleigh"], extra)

    dts = [4e-3, 2e-3, 1e-3]
    errors = []
    for dt in dts:
        forces = None if load == "ground" else np.array([wind(t) for t in np.arange(2 * int(round(T / dt)) + 1) * dt / 2])
        s = building.simulate(cfg, unzipdir, model_description, ground, dt, T, floor_forces=forces,
                              derivatives=derivatives)
        roof = building.monolithic(bld, [(floor, m_d, w_d, ZETA)], ground, s["t"],
                                   floor_forces=None if load == "ground" else wind)[:, -1]
        errors.append(np.max(np.abs(s["X"][:, -1] - roof)) / np.max(np.abs(roof)))
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    print(f"\nroof displacement vs monolithic ({'derivatives' if derivatives else 'held'}): errors "
          f"{['%.2e' % e for e in errors]}, ratios {['%.2f' % r for r in ratios]}")
    if derivatives:
        # second order: halving the step quarters the error
        assert errors[-1] < 1e-4
        for r in ratios:
            assert abs(r - 4.0) < 0.5, ratios
    else:
        # first order: halving the step halves the error (within 15 %)
        assert errors[-1] < 1e-2
        for r in ratios:
            assert abs(r - 2.0) < 0.3, ratios


def test_floor_forces_enter_at_the_rk4_stage_times(model_description, unzipdir):
    """Without dampers the master is plain RK4 on the building, fourth order when the floor
    forces are sampled at the right stage times (t, t + h/2, t + h): a force held over the step,
    or taken one sample off, would fall back to first or second order. (With dampers the
    first-order coupling hides that.)"""
    b = CFG["building"]
    n = len(b["masses"])
    bld = building.Building(b["masses"], b["stiffnesses"], b["rayleigh"])
    w = 0.97 * bld.omega1
    wind = lambda t: np.array([(0.5 + 0.25 * i) * math.sin(w * t + i) + 0.3 * math.cos(0.4 * w * t)  # noqa: E731
                               for i in range(n)])
    ground = lambda t: (0.0, 0.0, 0.0)  # noqa: E731
    T = 10.0

    def rhs(t, y):
        return np.concatenate([y[n:], bld.accel(y[:n], y[n:], wind(t), 0.0)])

    errors = []
    for dt in (4e-3, 2e-3, 1e-3):
        forces = np.array([wind(t) for t in np.arange(2 * int(round(T / dt)) + 1) * dt / 2])
        s = building.simulate(CFG, unzipdir, model_description, ground, dt, T, with_dampers=False,
                              floor_forces=forces)
        ref = solve_ivp(rhs, (0, T), np.zeros(2 * n), method="DOP853", rtol=1e-12, atol=1e-15, t_eval=s["t"])
        errors.append(np.max(np.abs(s["X"][:, -1] - ref.y[n - 1])) / np.max(np.abs(ref.y[n - 1])))
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    print(f"\nbuilding alone under floor forces: errors {['%.2e' % e for e in errors]}, ratios {ratios}")
    assert errors[-1] < 1e-6
    assert all(r > 12 for r in ratios), ratios


@pytest.mark.parametrize("coherence", [0.0, 0.5, 1.0])
def test_wind_forces_have_the_requested_rms_band_and_spectrum(coherence):
    """The wind generator: exact rms per floor, no power outside the band, the von Karman
    roll-off inside it, and the requested correlation between floors."""
    dt, T, band, corner = 5e-3, 600.0, (0.05, 2.0), 0.3
    rms = [1.0, 2.0, 3.0]
    t, F = building.wind_forces(3, dt, int(round(T / dt)), rms, band, corner, coherence, seed=7)
    assert F.shape == (len(t), 3) and abs(t[-1] - T) < 1e-9
    assert np.allclose(np.sqrt(np.mean(F[:-1] ** 2, axis=0)), rms, rtol=1e-12) and np.array_equal(F[0], F[-1])
    for i in range(3):
        P = np.abs(np.fft.rfft(F[:-1, i])) ** 2
        f = np.fft.rfftfreq(len(F) - 1, dt)
        inside = (f >= band[0]) & (f <= band[1])
        assert P[~inside].sum() < 1e-20 * P[inside].sum()
        if coherence == 1.0:
            # one process per floor, deterministic amplitudes: the periodogram is the shape itself
            shape = (1 + (f[inside] / corner) ** 2) ** (-5 / 6)
            ratio = P[inside] / shape
            assert np.ptp(ratio) < 1e-6 * ratio.mean()
    c = np.corrcoef(F.T)
    off = c[np.triu_indices(3, 1)]
    print(f"\ncoherence {coherence}: floor correlations {np.round(off, 3)}")
    # independent processes of ~1000 random phases: the sample correlation scatters by ~0.05
    assert np.all(np.abs(off - coherence) < 0.1), off


@pytest.mark.parametrize("band, coherence", [((0.0, 2.0), 0.5), ((2.0, 1.0), 0.5), ((0.05, 2.0), 1.5)])
def test_wind_forces_refuse_a_band_with_the_mean_or_a_bad_coherence(band, coherence):
    with pytest.raises(ValueError):
        building.wind_forces(2, 0.01, 1000, [1.0, 1.0], band, 0.3, coherence, seed=1)


def test_pooled_instances_forget_the_previous_runs_parameters(model_description, unzipdir):
    """DamperPool reuses an instance through fmi2Reset: a run that sets fewer parameters than the
    one before must match a fresh instance (the earlier values must not leak)."""
    b = {"building": CFG["building"]}
    a = lambda t: (-2e-3 * math.sin(5.6 * t), 2e-3 / 5.6 * math.cos(5.6 * t), 2e-3 / 31.36 * math.sin(5.6 * t))  # noqa: E731
    heavy = {**b, "dampers": [{"floor": 3, "tanks": 3, "params": {"damping": "Constant", "zeta": 0.2, "tank.depth": 0.03}}]}
    plain = {**b, "dampers": [{"floor": 3}]}
    pool = building.DamperPool(unzipdir, model_description)
    try:
        first = building.simulate(heavy, unzipdir, model_description, a, 5e-3, 5.0, pool=pool)
        reused = building.simulate(plain, unzipdir, model_description, a, 5e-3, 5.0, pool=pool)
        assert len(pool.dampers) == 1
    finally:
        pool.close()
    fresh = building.simulate(plain, unzipdir, model_description, a, 5e-3, 5.0)
    assert np.array_equal(reused["X"], fresh["X"]) and np.array_equal(reused["F"], fresh["F"])
    assert not np.allclose(first["F"], fresh["F"], rtol=1e-3)   # the first run was different
