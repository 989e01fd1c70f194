"""The scene of issue 27's impact impulses in Model Exchange, shared by
tests/python/test_me_impulse.py and scripts/me-impulse.py: Building.fmu (one storey or three)
under its built-in harmonic ground motion at its first mode's frequency, TLD.fmu's S^2 on the
roof, both in Model Exchange in one DOP853 (python/tld_fmu/me_master.py), and the monolithic
reference of the same equations (python/tld_fmu/impacts.py)."""
from __future__ import annotations

import numpy as np

from tld_fmu import impacts as I
from tld_fmu import reference as R
from tld_fmu.contract import item
from tld_fmu.me_master import MeFmu, coupled_with_events
from tld_fmu.paths import BUILDING_FMU, FMU

MAX_STOREYS = 20                 # Building.fmu's padded state layout (floor[i].v at 20 + i - 1)
OMEGA, E, RATIO, D, ZETA = 0.7, 0.4, 0.01, 0.02, 0.02
T_END, DT = 15.0, 0.01
RTOL = 1e-10

# (storeys, storey mass, storey stiffness, damping.zeta, ground amplitude): amplitudes where the
# impact mass never comes to rest on a wall (slowest impact 1.8e-2 and 9e-3 m/s, 0.18 and 0.15 s
# at least between impacts; with 2 mm on three storeys it chatters to rest after 56 impacts,
# and a resting mass's inertia is in base_shear, not in force: docs/MODEL_EXCHANGE.md).
SCENES = {"1 storey": (1, 168.0, 5342.0, 0.0032, 8e-4),
          "3 storeys": (3, 168.0, 3 * 5342.0, 0.02, 1.5e-3)}


def tld_start():
    p = R.TLD(damping=R.DAMPING_CONSTANT, zeta=ZETA)
    return {**p.fmu_parameters(), "model": item("model", "SloshingSlamming"),
            "amplitude": item("amplitude", "Fixed"), "slamming.Omega": OMEGA,
            "slamming.restitution": E, "slamming.clearance": D, "slamming.mass_ratio": RATIO}


def run(scene, fmu_path=FMU, transfer=True, rtol=RTOL):
    """The ME coupling of `scene` (ground motion at the first mode's frequency) and its
    monolithic reference; the total momentum before and after every event, and the impulse
    the TLD reported at each."""
    n, m, k, zeta_b, A_g = SCENES[scene]
    m_s, w_s, m_i, m_0 = I.s2_masses(Omega=OMEGA, ratio=RATIO)
    masses = np.full(n, m)
    masses[-1] += m_0                                   # the inactive liquid on the roof
    M, K = np.diag(masses), I.shear_stiffness(np.full(n, k))
    w_g = float(np.sqrt(np.min(np.linalg.eigvals(np.linalg.solve(M, K)).real)))
    tld = MeFmu(fmu_path, tld_start(), "tld")
    building = MeFmu(BUILDING_FMU, {
        "storeys": n, **{f"storey[{i}].mass": m for i in range(1, n + 1)},
        **{f"storey[{i}].stiffness": k for i in range(1, n + 1)}, "damping.zeta": zeta_b,
        "tld.mass": tld.get("mass.inactive"), "ground.amplitude": A_g, "ground.omega": w_g},
        "building")
    nb = building.nx

    def momentum(y):
        vg = y[2 * MAX_STOREYS + 1]                     # ground.v: continuous across an event
        floors = vg + y[MAX_STOREYS:MAX_STOREYS + n]
        return masses @ floors + m_s * (floors[-1] + y[nb + 1]) + m_i * (floors[-1] + y[nb + 5])

    events = []

    def on_event(te, before, after):
        events.append((momentum(before), momentum(after), tld.get("impact.impulse")))

    try:
        assert abs(tld.get("mass.inactive") - m_0) < 1e-12 * m_0
        alpha, beta = building.get("damping.alpha"), building.get("damping.beta")
        t = np.linspace(0.0, T_END, int(round(T_END / DT)) + 1)
        names = ["roof.x", "floor[1].x", "slosh.x", "impact.z", "impacts"]
        me = coupled_with_events(building, tld, t, rtol=rtol, transfer=transfer, outputs=names,
                                 on_event=on_event)
    finally:
        tld.close()
        building.close()
    ref = I.building_s2(M, alpha * M + beta * K, K, n - 1, m_s, w_s, ZETA, m_i, D, E, A_g, w_g,
                        t, transfer=transfer)
    return me, ref, np.array(events)


def errors(me, ref):
    """Largest differences over the whole history as fractions of the reference's peaks."""
    return {"roof.x": R.rel_err(me["roof.x"], ref["u"][-1]),
            "floor[1].x": R.rel_err(me["floor[1].x"], ref["u"][0]),
            "slosh.x": R.rel_err(me["slosh.x"], ref["x"]),
            "impact.z": R.rel_err(me["impact.z"], ref["z"])}
