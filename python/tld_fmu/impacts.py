"""Monolithic reference for a shear building carrying an S^2 damper (MODEL.md section 3),
written from the equations, independent of both FMUs: the structure, the sloshing mode and the
impact mass as one ODE system, the impacts located as events of that system and handled
exactly, the impulse applied to both bodies.

u: floor displacements relative to the ground (x_g = A sin(w t)); floor f carries the tank;
its absolute acceleration A_f = a_g + u_f''. Between impacts
    M u'' + C u' + K u = -M 1 a_g + e_f F,   F = m_s (2 zeta w_s x' + w_s^2 x)
    x'' = -A_f - 2 zeta w_s x' - w_s^2 x           (sloshing mode, relative to the tank)
    z'' = -A_f                                     (impact mass, relative to the tank)
(M with the inactive liquid on floor f). An impact where |z| reaches d/2 moving into that
wall, with the tank as the infinitely heavy partner of the collision law (restitution e on the
relative velocity v): the impact mass gives the tank the impulse P = m_i (1 + e) v;
transferred (the default) the floors' velocities jump by M^-1 e_f P and the impact mass's
absolute velocity by -P/m_i, the sloshing mass's absolute velocity stays: relative to the tank
x' and z' drop by the floor's jump. Total momentum is conserved at every impact.
`transfer=False`: the impulse is dropped (what an ME coupling through `force` alone does)."""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from .building import shear_stiffness  # noqa: F401  (the structure's K, for the callers)


def s2_masses(a=0.25, b=0.32, h=0.021, rho=1000.0, g=9.81, tanks=1, Omega=0.9, ratio=0.01):
    """(m_s, w_s, m_i, m_inactive) of the S^2 model from the tank (Eqs 2.1, 2.2, 2.7)."""
    M_l = rho * a * b * h * tanks
    r = h / a
    m1 = 8.0 * math.tanh(math.pi * r) / (math.pi ** 3 * r) * M_l
    w1 = math.sqrt(g * math.pi * math.tanh(math.pi * r) / a)
    return Omega * m1, w1 / math.sqrt(Omega), (ratio + 1.0 - Omega) * m1, M_l - (1.0 + ratio) * m1


def building_s2(M, C, K, floor, m_s, w_s, zeta, m_i, d, e, A_g, w_g, t_eval, transfer=True,
                rtol=1e-12, atol=1e-15):
    """The history at t_eval from rest (ground velocity A_g w_g at t = 0, the building at rest
    relative to it). M: mass matrix with the inactive liquid; floor: 0-based. Returns
    {"u": (n, len(t)), "x", "z", "events": times, "impulses": P per impact}."""
    n = len(M)
    Minv = np.linalg.inv(M)
    jump = Minv[:, floor]                       # floors' velocity change per unit impulse
    c = 2 * zeta * w_s

    def rhs(t, y):
        u, du, x, dx, z, dz = y[:n], y[n:2 * n], y[2 * n], y[2 * n + 1], y[2 * n + 2], y[2 * n + 3]
        a_g = -A_g * w_g * w_g * math.sin(w_g * t)
        f = np.zeros(n)
        f[floor] = m_s * (c * dx + w_s * w_s * x)
        ddu = Minv @ (f - C @ du - K @ u) - a_g
        A_f = a_g + ddu[floor]
        return np.concatenate([du, ddu, [dx, -A_f - c * dx - w_s * w_s * x, dz, -A_f]])

    def wall(sign):
        def g(t, y):
            return 0.5 * d - sign * y[2 * n + 2]
        g.terminal, g.direction = True, -1
        return g

    t, y = t_eval[0], np.zeros(2 * n + 4)
    out = np.full((2 * n + 4, len(t_eval)), np.nan)
    events, impulses, done = [], [], 0
    while True:
        sol = solve_ivp(rhs, (t, t_eval[-1]), y, method="DOP853", rtol=rtol, atol=atol,
                        events=[wall(1.0), wall(-1.0)], dense_output=True)
        assert sol.status >= 0, sol.message
        while done < len(t_eval) and t_eval[done] <= sol.t[-1]:
            out[:, done] = sol.sol(t_eval[done])
            done += 1
        if sol.status != 1:
            break
        t, y = sol.t[-1], sol.y[:, -1].copy()
        sign = 1.0 if y[2 * n + 2] > 0 else -1.0
        v = y[2 * n + 3]
        if v * sign <= 0:
            raise ValueError(f"at t = {t}: the impact mass is on a wall without moving into it "
                             "(coming to rest there, which this reference does not model)")
        P = m_i * (1.0 + e) * v
        y[2 * n + 2] = sign * 0.5 * d
        y[2 * n + 3] = -e * v
        if transfer:
            dV = jump * P
            y[n:2 * n] += dV
            y[2 * n + 1] -= dV[floor]
            y[2 * n + 3] -= dV[floor]
        events.append(t)
        impulses.append(P)
    return {"u": out[:n], "x": out[2 * n], "z": out[2 * n + 2], "events": np.asarray(events),
            "impulses": np.asarray(impulses)}
