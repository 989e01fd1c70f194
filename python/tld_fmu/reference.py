"""Independent reference solutions for the TLD.fmu tests.

Written from the equations in docs/MODEL.md and the FMU contract (modelDescription.xml,
whose enumeration values it reads through tld_fmu.contract), sharing no code with the Rust FMU.
Nothing here loads the FMU.

Model (per tank, totals = `tanks` times):
    M_l = rho a b h,  r = h/a
    m   = M_l 8 tanh(pi r) / (pi^3 r)           sloshing mass of mode 1
    w_f = sqrt(g pi tanh(pi r) / a)
    x'' + 2 zeta w_f x' + Phi(x) = -a_b(t)
    Phi(x) = w_f^2 x [1 + phi |2x/a|^(2 eta - 2)]
    U(x)   = w_f^2 [x^2/2 + phi (2/a)^(2eta-2) |x|^(2eta) / (2 eta)]      (U' = Phi)
    force  = m (2 zeta w_f v + Phi(x))
    energy.stored = m v^2/2 + m U(x); energy.dissipated = int m 2 zeta w_f v^2 dt
    energy.input  = energy.stored(0) + int -m a_b v dt

Co-simulation semantics reproduced here: the input a_b is HELD CONSTANT over each communication
interval at the value the FMU was given before the step (sample and hold). The references
therefore integrate interval by interval with the held value and restart at every boundary, so
the comparison with the FMU measures only the FMU's solver error, never the hold error.

Three independent solvers:
  * `simulate_held`      - fixed-step 8th-order Runge-Kutta (the 12-stage 8th-order solution
                           of the Dormand-Prince 8(5,3) pair, tableau from scipy), restarted on
                           every interval, with `substeps` equal substeps per interval. Fast
                           enough (pure-float Python) for 60 s histories at 1 ms steps.
  * `simulate_held_scipy`- scipy.integrate.solve_ivp(DOP853, rtol=1e-12) restarted on every
                           interval: slow, used to validate `simulate_held` on short windows.
  * `linear_zoh`         - the exact solution of the LINEAR model with held inputs (matrix
                           exponential), and `linear_harmonic_exact` / `linear_free_decay` -
                           closed forms with continuous inputs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .contract import item

# the enumeration values the parameters below use, by item name from the contract
DAMPING_CONSTANT, DAMPING_NSD = item("damping", "Constant"), item("damping", "NSD")
AMPLITUDE_FIXED, AMPLITUDE_TRACKED = item("amplitude", "Fixed"), item("amplitude", "Tracked")
SOLVER_DP45, SOLVER_RK4 = item("solver", "DormandPrince45"), item("solver", "RK4")
SOLVER_RK5, SOLVER_RK8, SOLVER_EXPRK4 = item("solver", "RK5"), item("solver", "RK8"), item("solver", "ExpRK4")
MODEL_NONLINEAR = item("model", "Nonlinear")


def geometry(a=0.25, b=0.32, h=0.021, rho=1000.0, g=9.81, tanks=1):
    """Eqs 2.1/2.2 for the fundamental mode; masses are totals over `tanks` tanks."""
    M_l = rho * a * b * h
    r = h / a
    m_1 = M_l * 8.0 * math.tanh(math.pi * r) / (math.pi ** 3 * r)
    omega_f = math.sqrt(g * math.pi * math.tanh(math.pi * r) / a)
    return {
        "omega_f": omega_f,
        "mass.liquid": tanks * M_l,
        "mass.slosh": tanks * m_1,
        "mass.inactive": tanks * (M_l - m_1),
    }


def mode(n, a=0.25, b=0.32, h=0.021, rho=1000.0, g=9.81):
    """Mode n (1, 2, ...) of Eqs 2.1/2.2, per tank: (m_n / M_l, omega_n)."""
    r = h / a
    k = 2 * n - 1
    ratio = 8.0 * math.tanh(k * math.pi * r) / (math.pi ** 3 * r * k ** 3)
    omega = math.sqrt(g * k * math.pi * math.tanh(k * math.pi * r) / a)
    return ratio, omega


@dataclass(frozen=True)
class TLD:
    """Parameters of the FMU's Nonlinear model (names follow the FMU's variables)."""
    a: float = 0.25            # tank.length
    b: float = 0.32            # tank.breadth
    h: float = 0.021           # tank.depth
    rho: float = 1000.0        # liquid.density
    g: float = 9.81            # g
    tanks: int = 1
    eta: float = 2.0
    phi: float = 1.0
    damping: int = DAMPING_NSD
    zeta: float = 0.01
    nsd_c: float = 0.5
    nsd_p: float = 0.35
    lambda_min: float = 1e-3
    lambda_max: float = 0.1
    A_e: float = 0.005         # Fixed amplitude
    x0: float = 0.0
    v0: float = 0.0

    def with_(self, **kw) -> "TLD":
        return replace(self, **kw)

    # -- derived quantities -------------------------------------------------------------------
    @property
    def geo(self):
        return geometry(self.a, self.b, self.h, self.rho, self.g, self.tanks)

    @property
    def omega_f(self):
        return self.geo["omega_f"]

    @property
    def m(self):
        return self.geo["mass.slosh"]

    @property
    def m0(self):
        return self.geo["mass.inactive"]

    def zeta_of(self, A_e):
        """Damping ratio in use for excitation amplitude A_e."""
        if self.damping == DAMPING_CONSTANT:
            return self.zeta
        lam = min(max(A_e / self.a, self.lambda_min), self.lambda_max)
        return self.nsd_c * lam ** self.nsd_p

    @property
    def zeta_fixed(self):
        return self.zeta_of(self.A_e)

    def fmu_parameters(self):
        """{FMU variable name: value} for every parameter this dataclass carries."""
        return {
            "tank.length": self.a, "tank.breadth": self.b, "tank.depth": self.h,
            "liquid.density": self.rho, "g": self.g, "tanks": self.tanks,
            "eta": self.eta, "phi": self.phi, "damping": self.damping, "zeta": self.zeta,
            "nsd.c": self.nsd_c, "nsd.p": self.nsd_p, "lambda.min": self.lambda_min,
            "lambda.max": self.lambda_max, "amplitude": AMPLITUDE_FIXED, "A_e": self.A_e,
            "slosh.x0": self.x0, "slosh.v0": self.v0,
        }

    # -- the model functions (vectorised over numpy arrays) -------------------------------------
    def _q(self):
        return self.phi * (2.0 / self.a) ** (2 * self.eta - 2)

    def Phi(self, x):
        x = np.asarray(x, dtype=float)
        return self.omega_f ** 2 * x * (1.0 + self._q() * np.abs(x) ** (2 * self.eta - 2))

    def U(self, x):
        x = np.asarray(x, dtype=float)
        e2 = 2 * self.eta
        return self.omega_f ** 2 * (x ** 2 / 2 + self._q() * np.abs(x) ** e2 / e2)

    def force(self, x, v, zeta=None):
        zeta = self.zeta_fixed if zeta is None else zeta
        return self.m * (2 * zeta * self.omega_f * np.asarray(v) + self.Phi(x))

    def stored(self, x, v):
        return self.m * (0.5 * np.asarray(v) ** 2 + self.U(x))


# ------------------------------------------------------------------------------------------------
# Fixed-step 8th-order Runge-Kutta on held inputs (the fast reference)
# ------------------------------------------------------------------------------------------------
def _rk8_tableau():
    from scipy.integrate._ivp import dop853_coefficients as dc  # the published DOP853 tableau
    s = dc.N_STAGES
    A = [[float(dc.A[i, j]) for j in range(i)] for i in range(s)]
    B = [float(v) for v in dc.B]
    C = [float(v) for v in dc.C[:s]]
    assert abs(sum(B) - 1.0) < 1e-14
    return A, B, C


_A8, _B8, _C8 = _rk8_tableau()


@dataclass
class Result:
    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    energy_input: np.ndarray
    energy_dissipated: np.ndarray
    energy_stored: np.ndarray
    force: np.ndarray
    force_mean: np.ndarray      # impulse over the interval ending at t[k] / length (k >= 1)


def simulate_held(p: TLD, dt, a_held, substeps=1, zeta=None) -> Result:
    """Integrate the model with base.a = a_held[k] held on [t_k, t_k + dt), k = 0..N-1.

    Returns values at the N+1 communication points t_k = k dt. The energy integrals and the
    force impulse are integrated as extra components of the same Runge-Kutta step (their
    right-hand sides do not depend on themselves, so this is the RK quadrature with the
    method's weights, of the same order as the state)."""
    a_held = np.asarray(a_held, dtype=float)
    N = len(a_held)
    zeta = p.zeta_fixed if zeta is None else zeta
    w2 = p.omega_f ** 2
    c = 2.0 * zeta * p.omega_f
    q = p._q()
    pw = 2.0 * p.eta - 2.0
    m = p.m
    A, B, C = _A8, _B8, _C8
    s = len(B)
    hs = dt / substeps

    xs = np.empty(N + 1); vs = np.empty(N + 1)
    Win = np.empty(N + 1); Ed = np.empty(N + 1); Imp = np.zeros(N + 1)
    x, v = float(p.x0), float(p.v0)
    E0 = float(p.stored(x, v))
    xs[0], vs[0], Win[0], Ed[0] = x, v, E0, 0.0
    win, ed = E0, 0.0
    fabs = math.fabs
    kx = [0.0] * s
    kv = [0.0] * s
    for k in range(N):
        ab = float(a_held[k])
        imp = 0.0
        for _ in range(substeps):
            # stages: kx = v, kv = -ab - c v - Phi(x); integrands evaluated at the stage states
            sd = si = sf = 0.0
            for i in range(s):
                xi, vi = x, v
                Ai = A[i]
                for j in range(i):
                    aij = Ai[j]
                    xi += hs * aij * kx[j]
                    vi += hs * aij * kv[j]
                phix = w2 * xi * (1.0 + q * fabs(xi) ** pw)
                kx[i] = vi
                kv[i] = -ab - c * vi - phix
                bi = B[i]
                sd += bi * vi * vi
                si += bi * vi
                sf += bi * (c * vi + phix)
            dx = dv = 0.0
            for i in range(s):
                dx += B[i] * kx[i]
                dv += B[i] * kv[i]
            x += hs * dx
            v += hs * dv
            ed += hs * m * c * sd
            win += -hs * m * ab * si
            imp += hs * m * sf
        xs[k + 1], vs[k + 1], Win[k + 1], Ed[k + 1], Imp[k + 1] = x, v, win, ed, imp
    t = dt * np.arange(N + 1)
    fm = np.empty(N + 1)
    fm[1:] = Imp[1:] / dt
    fm[0] = np.nan
    return Result(t, xs, vs, Win, Ed, p.stored(xs, vs), p.force(xs, vs, zeta), fm)


def simulate_held_scipy(p: TLD, dt, a_held, rtol=1e-12, zeta=None):
    """Slow cross-check of `simulate_held`: solve_ivp(DOP853) restarted on every interval.
    Returns (t, x, v)."""
    from scipy.integrate import solve_ivp
    zeta = p.zeta_fixed if zeta is None else zeta
    c = 2.0 * zeta * p.omega_f
    N = len(a_held)
    y = np.array([p.x0, p.v0], dtype=float)
    xs = [y[0]]; vs = [y[1]]
    atol = np.array([1e-16 * p.a, 1e-16 * p.a * p.omega_f])
    for k in range(N):
        ab = float(a_held[k])
        sol = solve_ivp(lambda t, y: [y[1], -ab - c * y[1] - p.Phi(y[0])],
                        (k * dt, (k + 1) * dt), y, method="DOP853", rtol=rtol, atol=atol)
        assert sol.success, sol.message
        y = sol.y[:, -1]
        xs.append(y[0]); vs.append(y[1])
    return dt * np.arange(N + 1), np.array(xs), np.array(vs)


# The weight of the prior in Model Exchange's amplitude estimate (docs/MODEL_EXCHANGE.md, "the
# estimator as states"): the prior's mean squares count as this much filtered data.
PRIOR_WEIGHT = 1e-6


def simulate_tracked_held_scipy(p: TLD, dt, a_held, tau=0.0, rtol=1e-12):
    """Eq 2.11 with amplitude = Tracked as Model Exchange integrates it, solved by
    solve_ivp(DOP853) restarted on every held interval: the damping ratio is p.zeta_of(A_e) at
    the estimate A_e of the estimator's ODEs (docs/MODEL.md 2, docs/MODEL_EXCHANGE.md), the
    velocity rebuilt from base.a (base.v never set):
        r' = a - w_c r,  w_c = w_f/20
        f1' = (s - f1)/tau,  f2' = (f1 - f2)/tau   for s = r^2, a^2 and 1 (the weight)
        <v^2> = (f2[r^2] + e V0)/(f2[1] + e),  <a^2> = (f2[a^2] + e A0)/(f2[1] + e)
        A_e = sqrt(2) <a^2>^(1/2) / (<a^2>/<v^2> - w_c^2)    (the prior where that fails)
    with e = PRIOR_WEIGHT and the prior's mean squares A0 = (A_p w_f^2)^2/2,
    V0 = A0/(w_f^2 + w_c^2) (harmonic base motion of the prior amplitude A_p = p.A_e at w_f, its
    velocity through the leak's gain). tau 0: two sloshing periods. Returns (t, x, v, A_e)
    at the interval ends, from the state at rest with every filter at 0."""
    from scipy.integrate import solve_ivp
    w_f = p.omega_f
    wc = 0.05 * w_f
    tau = tau if tau > 0 else 2.0 * (2.0 * math.pi / w_f)
    A0 = 0.5 * (p.A_e * w_f ** 2) ** 2
    V0 = A0 / (w_f ** 2 + wc ** 2)

    def estimate(y):
        weight = y[8] + PRIOR_WEIGHT
        v2 = (y[4] + PRIOR_WEIGHT * V0) / weight
        a2 = (y[6] + PRIOR_WEIGHT * A0) / weight
        if not (weight > 0 and v2 > 0 and a2 > 0):
            return p.A_e
        w2 = a2 / v2 - wc ** 2
        return math.sqrt(2.0) * math.sqrt(a2) / w2 if w2 > 0 else p.A_e

    def rhs(_, y, ab):
        x, v, r = y[0], y[1], y[2]
        c = 2.0 * p.zeta_of(estimate(y)) * w_f
        return [v, -ab - c * v - float(p.Phi(x)), ab - wc * r,
                (r * r - y[3]) / tau, (y[3] - y[4]) / tau,
                (ab * ab - y[5]) / tau, (y[5] - y[6]) / tau,
                (1.0 - y[7]) / tau, (y[7] - y[8]) / tau]

    y = np.array([p.x0, p.v0] + [0.0] * 7)
    scale = [p.a, p.a * w_f, p.A_e * w_f, (p.A_e * w_f) ** 2, (p.A_e * w_f) ** 2,
             (p.A_e * w_f ** 2) ** 2, (p.A_e * w_f ** 2) ** 2, 1.0, 1.0]
    atol = 1e-16 * np.array(scale)
    xs, vs, es = [y[0]], [y[1]], [estimate(y)]
    for k, ab in enumerate(np.asarray(a_held, dtype=float)):
        sol = solve_ivp(rhs, (k * dt, (k + 1) * dt), y, method="DOP853", rtol=rtol, atol=atol,
                        args=(float(ab),))
        assert sol.success, sol.message
        y = sol.y[:, -1]
        xs.append(y[0]); vs.append(y[1]); es.append(estimate(y))
    return dt * np.arange(len(a_held) + 1), np.array(xs), np.array(vs), np.array(es)


# ------------------------------------------------------------------------------------------------
# Linear model: exact solutions
# ------------------------------------------------------------------------------------------------
def linear_zoh(omega, zeta, dt, a_held, x0=0.0, v0=0.0):
    """Exact solution of x'' + 2 zeta omega x' + omega^2 x = -a_held[k] on [k dt, (k+1) dt).

    Discretisation of the linear system with zero-order-hold input through the matrix
    exponential of the augmented matrix [[F, G], [0, 0]] (Van Loan). Returns (x, v) at the
    N+1 communication points."""
    from scipy.linalg import expm
    F = np.array([[0.0, 1.0], [-omega ** 2, -2.0 * zeta * omega]])
    G = np.array([0.0, -1.0])
    Mx = np.zeros((3, 3))
    Mx[:2, :2] = F * dt
    Mx[:2, 2] = G * dt
    E = expm(Mx)
    Phi, Gam = E[:2, :2], E[:2, 2]
    N = len(a_held)
    out = np.empty((N + 1, 2))
    y = np.array([x0, v0], dtype=float)
    out[0] = y
    for k in range(N):
        y = Phi @ y + Gam * a_held[k]
        out[k + 1] = y
    return out[:, 0], out[:, 1]


def linear_free_decay(omega, zeta, t, x0, v0=0.0):
    """Closed-form free vibration of x'' + 2 zeta omega x' + omega^2 x = 0 (zeta < 1)."""
    t = np.asarray(t, dtype=float)
    wd = omega * math.sqrt(1.0 - zeta ** 2)
    s = zeta * omega
    e = np.exp(-s * t)
    C1, C2 = x0, (v0 + s * x0) / wd
    x = e * (C1 * np.cos(wd * t) + C2 * np.sin(wd * t))
    v = e * ((-s * C1 + wd * C2) * np.cos(wd * t) + (-s * C2 - wd * C1) * np.sin(wd * t))
    return x, v


def linear_harmonic_exact(omega, zeta, w, A, t):
    """Closed-form response from rest of x'' + 2 zeta omega x' + omega^2 x = w^2 A sin(w t),
    i.e. base motion base.x = A sin(w t), base.a = -w^2 A sin(w t), continuous (not held).

    Particular (steady-state) part: x_p = Im[H e^{iwt}], H = w^2 A / (omega^2 - w^2 + 2i zeta
    omega w); plus the homogeneous part that cancels x_p(0), x_p'(0)."""
    t = np.asarray(t, dtype=float)
    H = w ** 2 * A / complex(omega ** 2 - w ** 2, 2.0 * zeta * omega * w)
    e = np.exp(1j * w * t)
    xp = (H * e).imag
    vp = (1j * w * H * e).imag
    xp0, vp0 = H.imag, (1j * w * H).imag
    xh, vh = linear_free_decay(omega, zeta, t, -xp0, -vp0)
    return xp + xh, vp + vh


def harmonic_base(w, A, t):
    """Base motion x = A sin(w t): returns (x, v, a) at times t."""
    t = np.asarray(t, dtype=float)
    return A * np.sin(w * t), A * w * np.cos(w * t), -A * w ** 2 * np.sin(w * t)


def staircase(t, a, name="base.a"):
    """fmpy's input signal for the samples a at the times t, each held until the next: every
    time after the first twice (the old value, then the new), so that every sample is an input
    event where fmpy restarts its solver and the FMU sees exactly the held samples."""
    signal = np.zeros(2 * len(t) - 1, dtype=[("time", np.float64), (name, np.float64)])
    signal["time"][0::2], signal[name][0::2] = t, a
    signal["time"][1::2], signal[name][1::2] = t[1:], a[:-1]
    return signal


def rel_err(a, b, scale=None):
    """max |a - b| / scale (scale defaults to max |b|)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    s = np.max(np.abs(b)) if scale is None else scale
    return float(np.max(np.abs(a - b)) / s)


def coupled_monolithic(p: TLD, M, C, K, w, A_g, t, rtol=1e-11):
    """Monolithic solution of structure + TLD under ground motion x_g = A_g sin(w t), from rest.

    X: structure displacement relative to the ground, a_tank = a_g + X'' (absolute):
        (M + m_0) a_tank = force - C X' - K X,   force = m (2 zeta w_f v + Phi(x))
        x'' = -a_tank - 2 zeta w_f x' - Phi(x)
    (the inactive liquid mass m_0 moves with the tank). Continuous coupling, no hold: the limit
    that a co-simulation must approach as its communication step shrinks. Returns X, V, x, v."""
    from scipy.integrate import solve_ivp
    zeta = p.zeta_fixed
    c, m, mass = 2 * zeta * p.omega_f, p.m, M + p.m0

    def rhs(t, y):
        X, V, x, v = y
        phi = p.Phi(x)
        a_tank = (m * (c * v + phi) - C * V - K * X) / mass
        a_g = -w * w * A_g * math.sin(w * t)
        return [V, a_tank - a_g, v, -a_tank - c * v - phi]

    sol = solve_ivp(rhs, (t[0], t[-1]), [0.0, 0.0, p.x0, p.v0], method="DOP853", t_eval=t,
                    rtol=rtol, atol=1e-16)
    assert sol.success, sol.message
    return sol.y
