"""A structural master for TLD.fmu: an N-storey shear building (storey masses, stiffnesses and
Rayleigh damping) with TLD FMU instances on chosen floors, under ground motion and/or floor
forces, coupled by a fixed-step explicit scheme (scripts/building.py runs it from a TOML file,
tld_fmu.study runs design studies on it).

Each communication step: read every damper's `force` (state only: no algebraic loop), integrate
the building over the step with those forces held (RK4), then hand each damper floor's absolute
acceleration, velocity and displacement to its FMU (`base.a`, `base.v`, `base.x`) and `fmi2DoStep`.
The liquid that moves rigidly with a tank (`mass.inactive`) is added to its floor's mass."""
import ctypes
import math

import numpy as np

from . import fmulog
from .contract import Contract


def shear_stiffness(k):
    """Stiffness matrix of a shear building with storey stiffnesses k (storey 1 to the ground)."""
    n = len(k)
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += k[i]
        if i + 1 < n:
            K[i, i] += k[i + 1]
            K[i, i + 1] = K[i + 1, i] = -k[i + 1]
    return K


class Building:
    """M X'' + C X' + K X = -M 1 a_g + F, X relative to the ground (floors 0..N-1)."""

    def __init__(self, masses, stiffnesses, rayleigh, extra_mass=None):
        m = np.array(masses, float) + (0 if extra_mass is None else np.asarray(extra_mass, float))
        k = np.array(stiffnesses, float)
        n = len(m)
        K = shear_stiffness(k)
        self.M, self.K, self.n = np.diag(m), K, n
        w2, _ = np_eig(K, m)
        w = np.sqrt(w2[:2] if n > 1 else np.array([w2[0], w2[0]]))
        z1, z2 = rayleigh
        # Rayleigh: zeta_i = a0 / (2 w_i) + a1 w_i / 2 for modes 1 and 2
        A = np.array([[1 / (2 * w[0]), w[0] / 2], [1 / (2 * w[1]), w[1] / 2]])
        a0, a1 = np.linalg.solve(A, [z1, z2]) if n > 1 else (0.0, 2 * z1 / w[0])
        self.rayleigh_coefficients = (float(a0), float(a1))   # C = a0 M + a1 K
        self.C = a0 * self.M + a1 * K
        self.minv = 1.0 / m
        self.omega1 = w[0]

    def steady_amplitudes(self, w, ground_amplitude):
        """Steady-state displacement amplitudes of the floors (relative to the ground) under
        x_g = ground_amplitude sin(w t), in closed form: (K - w^2 M + i w C) X = w^2 A_g M 1."""
        Z = self.K - w * w * self.M + 1j * w * self.C
        return np.abs(np.linalg.solve(Z, w * w * ground_amplitude * np.diag(self.M)))

    def accel(self, X, V, F, ag):
        return self.minv * (F - self.C @ V - self.K @ X) - ag


def monolithic(bld, dampers, ground, t_eval, floor_forces=None, rtol=1e-11, atol=1e-14):
    """The reference for a co-simulation with linear dampers (model = Linear, modes = 1, damping
    Constant): building and sloshing modes as one ODE system, integrated by scipy's DOP853.

        M X'' + C X' + K X = -M 1 a_g + sum_d e_d m_d (c_d x_d' + w_d^2 x_d) + f(t)
        x_d'' + c_d x_d' + w_d^2 x_d = -(a_g + X_floor(d)'')

    bld: the Building with the dampers' inactive masses in M; dampers: [(floor index from 0,
    slosh mass m_d, w_d, zeta_d)]; ground(t) -> (a_g, ...); floor_forces(t) -> f (or None).
    Returns the floors' displacements relative to the ground at t_eval, shape (len, n)."""
    from scipy.integrate import solve_ivp
    n, nd = bld.n, len(dampers)
    floor = [d[0] for d in dampers]
    m_d = np.array([d[1] for d in dampers], float)
    w_d = np.array([d[2] for d in dampers], float)
    c_d = 2 * np.array([d[3] for d in dampers], float) * w_d

    def rhs(t, y):
        X, V, x, v = y[:n], y[n:2 * n], y[2 * n:2 * n + nd], y[2 * n + nd:]
        F = np.zeros(n) if floor_forces is None else np.array(floor_forces(t), float)
        np.add.at(F, floor, m_d * (c_d * v + w_d ** 2 * x))
        ag = ground(t)[0]
        A = bld.accel(X, V, F, ag)
        return np.concatenate([V, A, v, -(ag + A[floor]) - c_d * v - w_d ** 2 * x])

    ref = solve_ivp(rhs, (t_eval[0], t_eval[-1]), np.zeros(2 * (n + nd)), method="DOP853", rtol=rtol,
                    atol=atol, t_eval=t_eval)
    if not ref.success:
        raise RuntimeError(f"monolithic reference: {ref.message}")
    return ref.y[:n].T


def wind_forces(n_floors, dt, n, force_rms, band, corner, coherence, seed):
    """Band-limited wind-like random forces on the floors at t = 0, dt, ..., n dt.

    Each floor's force is a zero-mean Gaussian process with the one-sided spectrum
    S(f) ~ (1 + (f / corner)^2)^(-5/6) (the von Karman/Kaimal high-frequency roll-off of
    along-wind turbulence) inside band = [f_lo, f_hi] Hz (0 < f_lo; the mean wind's static part
    is not in it) and nothing outside, scaled to the floor's rms force [N]. Floors share a
    common part with weight `coherence` in [0, 1] (0: independent, 1: fully correlated). Built by
    the spectral representation on the FFT grid of period n dt (random phases; the spectrum's
    shape is exact for each unit process, and for the floors when coherence is 0 or 1), each
    floor scaled so that its rms over the period is exact; the sample at n dt repeats t = 0.
    Returns (t, F) with F of shape (n + 1, n_floors)."""
    f_lo, f_hi = band
    if not 0 < f_lo < f_hi:
        raise ValueError(f"wind band {band} Hz: need 0 < f_lo < f_hi")
    if not 0 <= coherence <= 1:
        raise ValueError(f"wind coherence {coherence}: need 0 <= coherence <= 1")
    rng = np.random.default_rng(seed)
    nfft = max(int(n), 2)
    f = np.fft.rfftfreq(nfft, dt)
    shape = np.where((f >= f_lo) & (f <= f_hi), (1 + (f / corner) ** 2) ** (-5 / 6), 0.0)
    if nfft % 2 == 0:
        shape[-1] = 0.0   # the Nyquist bin is real in irfft: a random phase would change its power
    if not np.any(shape > 0):
        raise ValueError(f"wind band {band} Hz holds no frequency of the {nfft * dt:.4g} s grid")

    def unit_process():
        spec = np.sqrt(shape) * np.exp(2j * np.pi * rng.random(len(f)))
        g = np.fft.irfft(spec, nfft)
        return g / np.sqrt(np.mean(g ** 2))

    common = unit_process()
    rms = np.broadcast_to(np.asarray(force_rms, float), (n_floors,))
    F = np.empty((nfft + 1, n_floors))
    for i in range(n_floors):
        g = math.sqrt(coherence) * common + math.sqrt(1 - coherence) * unit_process()
        F[:nfft, i] = rms[i] * g / np.sqrt(np.mean(g ** 2))
    F[nfft] = F[0]
    return np.arange(nfft + 1) * dt, F


def record_ground(tt, aa):
    """A ground-acceleration record (times tt, accelerations aa) as ground(t) -> (a_g, v_g, x_g):
    velocity and displacement by the trapezoidal rule from rest, all linear between samples."""
    tt, aa = np.asarray(tt, float), np.asarray(aa, float)
    vv = np.concatenate([[0], np.cumsum((aa[1:] + aa[:-1]) / 2 * np.diff(tt))])
    xx = np.concatenate([[0], np.cumsum((vv[1:] + vv[:-1]) / 2 * np.diff(tt))])
    return lambda t: (np.interp(t, tt, aa), np.interp(t, tt, vv), np.interp(t, tt, xx))


def harmonic_ground(w, amplitude):
    """Ground motion x_g = amplitude sin(w t) as ground(t) -> (a_g, v_g, x_g)."""
    return lambda t: (-w * w * amplitude * math.sin(w * t), w * amplitude * math.cos(w * t),
                      amplitude * math.sin(w * t))


def np_eig(K, m):
    """Eigenvalues of M^-1 K (ascending) for diagonal M."""
    s = 1 / np.sqrt(m)
    w2, vec = np.linalg.eigh(s[:, None] * K * s[None, :])
    return w2, vec


class Damper:
    """One TLD.fmu instance through fmpy's raw entry points."""

    def __init__(self, unzipdir, md, floor, tanks, params, name):
        from fmpy.fmi2 import FMU2Slave
        self.contract = Contract(md)
        self.var = self.contract.variables
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self._callbacks = fmulog.callbacks()   # its warnings reach fmulog.REPORT, on their own lines
        self.fmu.instantiate(callbacks=self._callbacks)
        vr = lambda n: self.var[n].valueReference  # noqa: E731
        f = self.fmu._functions
        self._set, self._get, self._step = f["fmi2SetReal"], f["fmi2GetReal"], f["fmi2DoStep"]
        self._set_der, self._get_der = f["fmi2SetRealInputDerivatives"], f["fmi2GetRealOutputDerivatives"]
        self._a_vr, self._f_vr = (ctypes.c_uint * 1)(vr("base.a")), (ctypes.c_uint * 1)(vr("force"))
        self._order1, self._der = (ctypes.c_int * 1)(1), (ctypes.c_double * 1)()
        self._in = (ctypes.c_uint * 3)(vr("base.a"), vr("base.v"), vr("base.x"))
        self._out = (ctypes.c_uint * 4)(vr("force"), vr("force.mean"), vr("energy.dissipated"), vr("slosh.x"))
        self._iv, self._ov = (ctypes.c_double * 3)(), (ctypes.c_double * 4)()
        self.configure(floor, tanks, params, fresh=True)

    def configure(self, floor, tanks, params, fresh=False):
        """Set the parameters ({name: value}, an Enumeration's item by name or value) and
        initialise; on an instance already used, fmi2Reset first (so one instance serves many
        runs of a study)."""
        if not fresh:
            self.fmu.reset()
        self.contract.initialise(self.fmu, {"tanks": tanks, **params})
        self.floor = floor - 1
        self.inactive = self.fmu.getReal([self.var["mass.inactive"].valueReference])[0]
        self.read()

    def read(self):
        if self._get(self.fmu.component, self._out, 4, self._ov) > 1:
            raise RuntimeError("fmi2GetReal failed")
        self.force, self.force_mean, self.dissipated, self.x = self._ov[:]

    def set_inputs(self, t, a, v, x):
        """The floor's absolute acceleration, velocity and displacement (base.a, base.v, base.x)."""
        self._iv[:] = (a, v, x)
        if self._set(self.fmu.component, self._in, 3, self._iv) > 1:
            raise RuntimeError(f"the damper refused its inputs at t = {t}")

    def step(self, t, h, a, v, x):
        """fmi2DoStep from t by h with these inputs held over the step."""
        self.set_inputs(t, a, v, x)
        self.step_with_rate(t, h, None)

    def step_with_rate(self, t, h, a_rate):
        """fmi2DoStep from t by h with the inputs already set; a_rate, if given, is d(base.a)/dt
        at t (fmi2SetRealInputDerivatives, order 1)."""
        c = self.fmu.component
        if a_rate is not None:
            self._der[0] = a_rate
            if self._set_der(c, self._a_vr, 1, self._order1, self._der) > 1:
                raise RuntimeError(f"the damper refused the input derivative at t = {t}")
        if self._step(c, t, h, 1) > 1:
            raise RuntimeError(f"the damper refused a step at t = {t}")
        self.read()

    def force_rate(self):
        """d(force)/dt now, exact from the model (fmi2GetRealOutputDerivatives, order 1)."""
        if self._get_der(self.fmu.component, self._f_vr, 1, self._order1, self._der) > 1:
            raise RuntimeError("fmi2GetRealOutputDerivatives failed")
        return self._der[0]

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


class DamperPool:
    """FMU instances kept across runs: the k-th damper of a run reuses the k-th instance through
    fmi2Reset instead of loading and instantiating a new one."""

    def __init__(self, unzipdir, md):
        self.unzipdir, self.md, self.dampers = unzipdir, md, []

    def get(self, k, floor, tanks, params):
        if k < len(self.dampers):
            self.dampers[k].configure(floor, tanks, params)
        else:
            self.dampers.append(Damper(self.unzipdir, self.md, floor, tanks, params, f"tld{k}"))
        return self.dampers[k]

    def close(self):
        for d in self.dampers:
            d.close()
        self.dampers = []


def structure(cfg, inactive) -> Building:
    """The building of cfg with the dampers' inactive liquid on their floors: inactive is
    [(0-based floor, mass.inactive)], one per damper (simulate's, and tld_fmu.study's native
    engine's, which hands the matrices to the compiled master)."""
    b = cfg["building"]
    extra = np.zeros(len(b["masses"]))
    for floor, m in inactive:
        extra[floor] += m
    return Building(b["masses"], b["stiffnesses"], b["rayleigh"], extra)


def simulate(cfg, unzipdir, md, ground, h, duration, with_dampers=True, floor_forces=None, pool=None,
             derivatives=False):
    """Co-simulate; ground(t) -> (a_g, v_g, x_g). floor_forces, if given, is an array of external
    forces on the floors [N] sampled every h/2 from t = 0 (the RK4 stage times). pool, if given,
    a DamperPool that provides (and keeps) the FMU instances. Returns the time series.

    derivatives=False: Gauss-Seidel, first order: the building steps with each damper's
    force.mean held, then each damper steps with its floor's motion at the step's end held.
    derivatives=True: Jacobi with derivatives, second order: each damper gets its floor's motion
    at the step's start and d(base.a)/dt = (F' - C A - K V)_floor / m_floor (F' from the
    dampers' force rates and the external forces' slope over the step), and the building steps
    with every damper's force extrapolated from its value and exact rate at the step's start."""
    n = len(cfg["building"]["masses"])
    dampers = []
    if with_dampers:
        for k, d in enumerate(cfg.get("dampers", [])):
            args = (d["floor"], d.get("tanks", 1), d.get("params", {}))
            dp = pool.get(k, *args) if pool is not None else Damper(unzipdir, md, *args, f"tld{k}")
            dampers.append(dp)
    bld = structure(cfg, [(dp.floor, dp.inactive) for dp in dampers])
    steps = int(round(duration / h))
    X, V = np.zeros(n), np.zeros(n)
    out = {"t": np.arange(steps + 1) * h, "X": np.zeros((steps + 1, n)), "A": np.zeros((steps + 1, n)),
           "F": np.zeros((steps + 1, len(dampers))), "E": np.zeros((steps + 1, len(dampers)))}
    ext = (lambda i: floor_forces[i]) if floor_forces is not None else (lambda i: 0.0)  # noqa: E731

    def on_floors(values):
        """Per-damper values summed onto the dampers' floors."""
        F = np.zeros(n)
        for dp, v in zip(dampers, values):
            F[dp.floor] += v
        return F

    for k in range(steps):
        t = k * h
        F = on_floors(dp.force if (derivatives or not k) else dp.force_mean for dp in dampers)
        dF = np.zeros(n)
        if derivatives and dampers:
            ag, vg, xg = ground(t)
            A0 = bld.accel(X, V, F + ext(2 * k), ag)
            # the force rates depend on base.a: read them with this step's inputs set
            for dp in dampers:
                i = dp.floor
                dp.set_inputs(t, ag + A0[i], vg + V[i], xg + X[i])
            dF = on_floors(dp.force_rate() for dp in dampers)
            dext = (ext(2 * k + 2) - ext(2 * k)) / h
            a_rate = bld.minv * (dF + dext - bld.C @ A0 - bld.K @ V)
            for dp in dampers:
                dp.step_with_rate(t, h, a_rate[dp.floor])

        # the floor forces at the RK4 stage times t, t + h/2, t + h (dampers' forces extrapolated
        # with their rates in derivative mode, held otherwise)
        if derivatives:
            Fs = [F + dF * (0.5 * h * j) + ext(2 * k + j) for j in range(3)]
        elif floor_forces is not None:
            Fs = [F + floor_forces[2 * k + j] for j in range(3)]
        else:
            Fs = [F, F, F]

        def rhs(tt, X_, V_, stage):
            return V_, bld.accel(X_, V_, Fs[stage], ground(tt)[0])
        # RK4 over the step
        k1 = rhs(t, X, V, 0)
        k2 = rhs(t + h / 2, X + h / 2 * k1[0], V + h / 2 * k1[1], 1)
        k3 = rhs(t + h / 2, X + h / 2 * k2[0], V + h / 2 * k2[1], 1)
        k4 = rhs(t + h, X + h * k3[0], V + h * k3[1], 2)
        X = X + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        V = V + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        ag, vg, xg = ground(t + h)
        if derivatives:
            F = on_floors(dp.force for dp in dampers)
        A_rel = bld.accel(X, V, F + ext(2 * k + 2), ag)
        for j, dp in enumerate(dampers):
            if not derivatives:
                i = dp.floor
                dp.step(t, h, ag + A_rel[i], vg + V[i], xg + X[i])
            out["F"][k + 1, j], out["E"][k + 1, j] = dp.force, dp.dissipated
        out["X"][k + 1], out["A"][k + 1] = X, ag + A_rel
    if pool is None:
        for dp in dampers:
            dp.close()
    out["omega1"] = bld.omega1
    return out


def check_plausible(cfg, unzipdir, md, force=False, prog="scripts/building.py"):
    """Refuse (SystemExit, unless force) a building whose dampers' water is more than
    fmulog.MASS_RATIO_MAX of the modal mass, and flag (fmulog.REPORT) dampers whose sloshing
    frequency is outside fmulog.TUNING_BAND of the structure's nearest mode. Each damper is
    instantiated once here, so its configuration warnings reach fmulog.REPORT before any run."""
    b, found = cfg["building"], []
    for k, d in enumerate(cfg.get("dampers", [])):
        dp = Damper(unzipdir, md, d["floor"], d.get("tanks", 1), d.get("params", {}), f"tld{k}")
        w_f, m = dp.fmu.getReal([dp.var[n].valueReference for n in ("omega_f", "mass.liquid")])
        dp.close()
        found.append((d["floor"], m, w_f))
    refuse, flag = fmulog.plausible_dampers(b["masses"], b["stiffnesses"], found)
    for f in flag:
        fmulog.REPORT.add("implausible configuration", f)
    if refuse and not force:
        lines = "\n".join(f"  {r}" for r in refuse + flag)
        raise SystemExit(f"{prog}: refused, an implausible configuration:\n{lines}\n"
                         f"(--force runs it anyway; its results are then flagged)")
    for r in refuse:
        fmulog.REPORT.add("implausible configuration (run with --force)", r)
