"""The work-precision benchmark's scenes, reference solutions and the FMU's interface as its
hosts see it: shared by bench/python/bench.py (the benchmark) and scripts/models.py (every model
on the same scenes).

Scenes: base.a histories held over each communication step (harmonic, band-limited random, a
synthetic earthquake) and a coupled Table 2.1 structure. References: tld_fmu.reference's
fixed-step 8th-order Runge-Kutta with held inputs at the same steps and inputs, computed in a
process pool and cached under target/bench/cache keyed by the reference's source. FmuInfo: a
packed FMU's variables, enumerations and the job-file tokens of the native host (bench/native).
"""
from __future__ import annotations

import concurrent.futures as cf
import hashlib
import math
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import reference as R
from .contract import Contract
from .paths import REPO

CACHE = REPO / "target" / "bench" / "cache"
# the native benchmark host (a workspace member; scripts/bench builds it)
NATIVE_BIN = REPO / "target" / "release" / "tld-bench"

TOLS = [1e-6, 1e-8, 1e-10, 1e-12]
TOLS_HIGH_ORDER = [1e-13, 1e-14]
H_MIN_RK4 = 1e-4        # RK4 substep sweep: dt/n for n = 1, 2, 4, ... while dt/n >= this
N_MAX_RK4 = 256


# ------------------------------------------------------------------------------------------------
# Scenes
# ------------------------------------------------------------------------------------------------
@dataclass
class Scene:
    key: str
    title: str
    p: R.TLD
    T: float
    dts: list
    h_ref: float                      # reference substep bound
    describe: str
    kind: str = "open"                # "open" or "coupled"
    fmu_physics: bool = True          # set p's parameters on the FMU (False: FMU defaults)
    fmu_params: dict = field(default_factory=dict)   # {FMU name: value} set on top of those
    make_input: object = None         # dt, n -> base.a held over each step
    coupled: dict = field(default_factory=dict)


def harmonic_input(w, A):
    def make(dt, n):
        return -w * w * A * np.sin(w * dt * np.arange(n))
    return make


def sampled_input(fine, fine_dt=1e-3):
    """base.a sampled from a record on a 1 ms grid at the communication points."""
    def make(dt, n):
        stride = dt / fine_dt
        s = int(round(stride))
        if abs(stride - s) > 1e-9 or s < 1:
            raise ValueError(f"dt {dt} is not a multiple of the record's 1 ms grid")
        return np.ascontiguousarray(fine()[::s][:n])
    return make


_records: dict = {}
_stats: dict = {}


def random_record(T, sigma=0.12, seed=20250601):
    """White noise band-limited to 0.1-3 Hz (4th-order Butterworth, zero phase), rms sigma."""
    key = ("random", T, sigma, seed)
    if key not in _records:
        from scipy.signal import butter, sosfiltfilt
        n = int(round(T / 1e-3)) + 1
        w = np.random.default_rng(seed).standard_normal(n)
        sos = butter(4, [0.1, 3.0], btype="bandpass", fs=1000.0, output="sos")
        a = sosfiltfilt(sos, w)
        _records[key] = a * (sigma / np.std(a))
    return _records[key]


def earthquake_record(T=40.0, pga=3.0, seed=19400518, wg=15.6, zg=0.6, t1=2.0, t2=10.0, c=0.25):
    """Kanai-Tajimi filtered white noise (ground frequency wg, damping zg) under a Jennings
    envelope ((t/t1)^2, 1 up to t2, exp(-c (t - t2))), scaled to peak |a| = pga."""
    key = ("eq", T, pga, seed)
    if key not in _records:
        from scipy.signal import lsim
        dt = 1e-3
        n = int(round(T / dt)) + 1
        t = dt * np.arange(n)
        w = np.random.default_rng(seed).standard_normal(n) / math.sqrt(dt)
        num = [2 * zg * wg, wg * wg]
        den = [1.0, 2 * zg * wg, wg * wg]
        _, a, _ = lsim((num, den), w, t)
        env = np.where(t < t1, (t / t1) ** 2, np.where(t <= t2, 1.0, np.exp(-c * (t - t2))))
        a = a * env
        _records[key] = a * (pga / np.max(np.abs(a)))
    return _records[key]


def make_scenes(quick: bool):
    p0 = R.TLD(eta=2.0, phi=1.0, damping=R.DAMPING_CONSTANT, zeta=0.02, A_e=0.005)
    wf = p0.omega_f
    quarter = round(0.25 * 2 * math.pi / wf, 6)      # a quarter of the sloshing period
    steps = [1e-3, 5e-3, 1e-2, 5e-2]
    qsteps = [1e-3, 5e-2]
    sc = []
    # 1. harmonic at resonance, eta = 2, Lambda = 0.02
    sc.append(Scene(
        "s1_harmonic_eta2", "1: harmonic, eta = 2, Lambda = 0.02", p0,
        10.0 if quick else 60.0, qsteps if quick else steps + [quarter], 1e-3,
        "base.x = A_e sin(w t), A_e = 5 mm (Lambda = A_e/a = 0.02), w = omega_f; eta = 2, "
        "phi = 1, damping = Constant, zeta = 0.02; from rest",
        make_input=harmonic_input(wf, 0.005)))
    # 2. harmonic near the walls, eta = 5
    p2 = p0.with_(eta=5.0)
    A2 = 0.0132     # calibrated: max |2x/a| of the reference ~ 1.0 (reported in the scene table)
    sc.append(Scene(
        "s2_harmonic_eta5_walls", "2: harmonic near the walls, eta = 5", p2,
        10.0 if quick else 60.0, qsteps if quick else steps + [quarter], 1e-3,
        f"base.x = A sin(w t), A = {A2 * 1e3:g} mm, w = omega_f; eta = 5, phi = 1, damping = "
        "Constant, zeta = 0.02; amplitude chosen so that max |2x/a| reaches about 1",
        make_input=harmonic_input(wf, A2)))
    # 3. band-limited random, 3600 s
    T3 = 30.0 if quick else 3600.0
    sc.append(Scene(
        "s3_random_3600s", f"3: band-limited random, {T3:g} s", p0, T3,
        qsteps if quick else steps, 2.5e-3,
        "base.a = white noise (seed 20250601) filtered to 0.1-3 Hz (4th-order Butterworth, "
        "zero phase) on a 1 ms grid, rms 0.12 m/s^2, sampled at the communication points; "
        "eta = 2, phi = 1, zeta = 0.02",
        make_input=sampled_input(lambda: random_record(T3))))
    # 4. synthetic earthquake, 40 s
    sc.append(Scene(
        "s4_earthquake_40s", "4: synthetic earthquake, 40 s, PGA 3 m/s^2", p0, 40.0,
        qsteps if quick else steps, 1e-3,
        "Kanai-Tajimi filtered white noise (w_g = 15.6 rad/s, zeta_g = 0.6, seed 19400518) "
        "under a Jennings envelope (t/2)^2 | 1 to 10 s | exp(-0.25 (t-10)), peak 3 m/s^2, "
        "1 ms grid sampled at the communication points; eta = 2, phi = 1, zeta = 0.02",
        make_input=sampled_input(lambda: earthquake_record())))
    # 5. coupled Table 2.1 structure + one default tank
    p5 = R.TLD()     # FMU defaults: NSD damping at A_e = 5 mm, held fixed -> constant zeta
    M, zs, ws = 168.0, 0.0032, 5.636
    Ag = 0.001
    sc.append(Scene(
        "s5_coupled_table21", "5: coupled Table 2.1 structure + 1 default tank", p5,
        10.0 if quick else 60.0, qsteps if quick else steps, 1e-3,
        f"structure M = 168 kg, damping 0.32 %, w_s = 5.636 rad/s; ground x_g = {Ag * 1e3:g} mm "
        "sin(w_s t); one tank with the FMU's defaults but amplitude = Fixed (NSD damping at the "
        f"fixed A_e = 5 mm, zeta = {p5.zeta_fixed:.4f}; eta = 2, phi = 1: the reference's "
        "constant zeta; the default Tracked amplitude would move the damping with the motion); "
        "master in the native host",
        kind="coupled", fmu_physics=False, fmu_params={"amplitude": "Fixed"},
        coupled=dict(M=M, C=2 * zs * ws * M, K=M * ws * ws, Ag=Ag, wg=ws, sub=4)))
    return sc


# A scene whose most accurate TLD.fmu run stays this far above its reference's own error
# estimate (the reference against itself at twice the substeps) does not simulate what its
# reference does: the benchmark refuses it. Errors at the references' floor are 1-10x the check;
# below ABS_FLOOR any scene passes (a check of 1e-15 would make 1e-11 a failure otherwise).
CHECK_FACTOR = 1e4
CHECK_FLOOR = 1e-9


def check_scenes(refs, rows):
    """[message] for every (scene, dt) whose best TLD.fmu error (over every setting, full
    history) exceeds max(CHECK_FACTOR x its reference's check, CHECK_FLOOR), or where no
    TLD.fmu run succeeded; empty when all pass."""
    out = []
    for (key, dt), ref in sorted(refs.items(), key=lambda kv: (kv[0][0], kv[0][1])):
        errs = [r["err"] for r in rows if r["scene"] == key and r["dt"] == dt
                and r["impl"] == "TLD.fmu" and r["status"] == "ok" and not r["window"]]
        limit = max(CHECK_FACTOR * ref["check"], CHECK_FLOOR)
        if not errs:
            out.append(f"{key} dt = {dt:g} s: no TLD.fmu run succeeded")
        elif min(errs) > limit:
            out.append(f"{key} dt = {dt:g} s: best TLD.fmu error {min(errs):.2e} against the "
                       f"reference's own check {ref['check']:.2e} (limit {limit:.1e}): the FMU "
                       f"and the reference do not simulate the same scene")
    return out


def n_steps(scene, dt):
    return int(round(scene.T / dt))


def ref_substeps(scene, dt):
    return max(1, math.ceil(dt / scene.h_ref - 1e-9))


# ------------------------------------------------------------------------------------------------
# The coupled master (Python twin of run_coupled in bench/native/src/main.rs: same operations)
# ------------------------------------------------------------------------------------------------
def coupled_master(damper, c, dt, n, m0):
    mass = c["M"] + m0
    C, K, Ag, wg, sub = c["C"], c["K"], c["Ag"], c["wg"], int(c["sub"])
    w2a = wg * wg * Ag
    xs = np.zeros(n + 1)
    Xs = np.zeros(n + 1)
    o = damper.outputs()
    xs[0] = o[0]
    force = o[2]
    x = v = 0.0
    h = dt / sub
    sin = math.sin

    def acc(t, x, v, f):
        return (f - C * v - K * x) / mass + w2a * sin(wg * t)

    for k in range(n):
        t = k * dt
        a_tank = (force - C * v - K * x) / mass
        o = damper.step(t, dt, a_tank)
        for j in range(sub):
            tj = t + j * h
            k1x = v
            k1v = acc(tj, x, v, force)
            k2x = v + 0.5 * h * k1v
            k2v = acc(tj + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v, force)
            k3x = v + 0.5 * h * k2v
            k3v = acc(tj + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v, force)
            k4x = v + h * k3v
            k4v = acc(tj + h, x + h * k3x, v + h * k3v, force)
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x)
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
        force = o[2]
        xs[k + 1] = o[0]
        Xs[k + 1] = x
    return xs, Xs


class RefDamper:
    """reference.simulate_held over one communication step at a time."""

    def __init__(self, p, substeps):
        self.p, self.s = p, substeps
        self.x, self.v = float(p.x0), float(p.v0)

    def outputs(self):
        return (self.x, self.v, float(self.p.force(self.x, self.v)))

    def step(self, t, dt, ab):
        r = R.simulate_held(self.p.with_(x0=self.x, v0=self.v), dt, [ab], substeps=self.s)
        self.x, self.v = float(r.x[1]), float(r.v[1])
        return (self.x, self.v, float(r.force[1]))


class FmpyDamper:
    """An FMU through fmpy's FMU2Slave (tld_fmu.slave.Slave): set base.a, doStep, get outputs."""

    def __init__(self, slave, a_name, out_names):
        self.s = slave
        f = slave.fmu
        self.vr_a = [slave.vr(a_name)]
        self.vr_out = [slave.vr(n) for n in out_names]
        self.f = f

    def outputs(self):
        return tuple(self.f.getReal(self.vr_out))

    def step(self, t, dt, ab):
        self.f.setReal(self.vr_a, [ab])
        self.f.doStep(t, dt)
        return tuple(self.f.getReal(self.vr_out))


# ------------------------------------------------------------------------------------------------
# References (process pool, cached)
# ------------------------------------------------------------------------------------------------
def _ref_source_hash():
    return hashlib.sha256(Path(R.__file__).read_bytes()).hexdigest()[:16]


def ref_job(scene_key, p, kind, coupled, dt, n, substeps, a_bytes, window):
    """Runs in a worker. Returns x (and X for coupled) over n steps, or over `window` steps."""
    nn = n if window is None else min(n, window)
    if kind == "coupled":
        x, X = coupled_master(RefDamper(p, substeps), coupled, dt, nn, p.m0)
        return x, X
    a = np.frombuffer(a_bytes, dtype=np.float64)[:nn]
    r = R.simulate_held(p, dt, a, substeps=substeps)
    return r.x, None


def ref_key(scene, dt, n, substeps, a, window):
    h = hashlib.sha256()
    h.update(_ref_source_hash().encode())
    h.update(repr((scene.key, scene.p, scene.kind, sorted(scene.coupled.items()), dt, n, substeps,
                   window)).encode())
    if a is not None:
        h.update(a.tobytes())
    return h.hexdigest()[:24]


def compute_references(scenes, inputs, quick, tqdm):
    """Returns {(key, dt): dict(x, X, substeps, check)}: check = max |x_s - x_2s| / max |x_2s|
    over the first min(T, 60 s) (the reference's own error estimate)."""
    CACHE.mkdir(parents=True, exist_ok=True)
    jobs = []
    for sc in scenes:
        for dt in sc.dts:
            n = n_steps(sc, dt)
            a = inputs.get((sc.key, dt))
            s = ref_substeps(sc, dt)
            win = min(n, int(round(min(sc.T, 10.0 if quick else 60.0) / dt)))
            for tag, subs, window in (("ref", s, None), ("chk", 2 * s, win), ("chkbase", s, win)):
                if tag == "chkbase" and win == n:
                    continue      # the full reference is the base of the check
                jobs.append((sc, dt, n, tag, subs, window, a))
    out = {}
    todo = []
    for job in jobs:
        sc, dt, n, tag, subs, window, a = job
        f = CACHE / f"{sc.key}_{dt:g}_{tag}_{ref_key(sc, dt, n, subs, a, window)}.npz"
        if f.exists():
            d = np.load(f, allow_pickle=False)
            out[(sc.key, dt, tag)] = (d["x"], d["X"] if "X" in d.files else None)
        else:
            todo.append((job, f))
    _stats["ref_computed"] = len(todo)
    # longest first so that the two workers finish together
    todo.sort(key=lambda jf: -(jf[0][4] * (jf[0][5] or jf[0][2])))
    if todo:
        with cf.ProcessPoolExecutor(max_workers=2) as ex:
            futs = {}
            for job, f in todo:
                sc, dt, n, tag, subs, window, a = job
                futs[ex.submit(ref_job, sc.key, sc.p, sc.kind, sc.coupled, dt, n, subs,
                               None if a is None else a.tobytes(), window)] = (job, f)
            for fut in tqdm(cf.as_completed(futs), total=len(futs), desc="references (RK8)",
                            unit="run", disable=None):
                job, f = futs[fut]
                sc, dt, n, tag, subs, window, a = job
                x, X = fut.result()
                if X is None:
                    np.savez(f, x=x)
                else:
                    np.savez(f, x=x, X=X)
                out[(sc.key, dt, tag)] = (x, X)
    refs = {}
    for sc in scenes:
        for dt in sc.dts:
            x, X = out[(sc.key, dt, "ref")]
            xc, _ = out[(sc.key, dt, "chk")]
            base = out.get((sc.key, dt, "chkbase"), (x, None))[0][:len(xc)]
            check = float(np.max(np.abs(base - xc)) / np.max(np.abs(xc)))
            refs[(sc.key, dt)] = dict(x=x, X=X, substeps=ref_substeps(sc, dt), check=check,
                                      check_window=(len(xc) - 1) * dt)
    return refs


# ------------------------------------------------------------------------------------------------
# The FMU's interface, read generically from its modelDescription
# ------------------------------------------------------------------------------------------------
class FmuInfo:
    """A packed FMU, unpacked once: its library for the native host and its contract (value
    references, enumeration items) read from its own modelDescription."""

    def __init__(self, fmu_path: Path):
        import fmpy
        self.path = fmu_path
        self.contract = Contract(fmu_path)
        self.md = self.contract.md
        self.vars = self.contract.variables
        self.unzip = Path(tempfile.mkdtemp(prefix="tld_bench_"))
        fmpy.extract(str(fmu_path), str(self.unzip))
        self.lib = self.unzip / "binaries" / "linux64" / f"{self.md.coSimulation.modelIdentifier}.so"
        self.sha256 = hashlib.sha256(fmu_path.read_bytes()).hexdigest()

    def vr(self, name):
        return self.contract.vr(name)

    def items(self, name):
        """[(item name, integer value, description)] of an Enumeration variable."""
        return self.contract.items(name)

    def enum_value(self, var, item):
        return self.contract.item(var, item)

    def token(self, name, value):
        """A job-file parameter token (R:vr=value or I:vr=value); an Enumeration's item by name
        or value."""
        v = self.vars[name]
        value = self.contract.value(name, value)
        if v.type == "Real":
            return f"R:{v.valueReference}={float(value)!r}"
        if v.type in ("Integer", "Enumeration"):
            return f"I:{v.valueReference}={int(value)}"
        raise TypeError(f"{name}: {v.type}")

    def vrs_line(self):
        """The job file's `vrs` line: the value references the native host's loop uses."""
        return (f"vrs base_a={self.vr('base.a')} x={self.vr('slosh.x')} v={self.vr('slosh.v')} "
                f"force={self.vr('force')} mass_inactive={self.vr('mass.inactive')}")

    def physics_params(self, p: R.TLD):
        """{FMU name: value} of the scene's physical parameters; enumeration values looked up
        by item name in the modelDescription."""
        params = p.fmu_parameters()
        params["damping"] = self.enum_value(
            "damping", "Constant" if p.damping == R.DAMPING_CONSTANT else "NSD")
        params["amplitude"] = self.enum_value("amplitude", "Fixed")
        return params

    def physics_tokens(self, p: R.TLD):
        return [self.token(k, v) for k, v in self.physics_params(p).items()]

    def scene_params(self, sc: Scene):
        """{FMU name: value} a scene sets: its physics (unless it runs the FMU's defaults) and
        its own FMU parameters."""
        return {**(self.physics_params(sc.p) if sc.fmu_physics else {}), **sc.fmu_params}

    def scene_tokens(self, sc: Scene):
        return [self.token(k, v) for k, v in self.scene_params(sc).items()]

    def solver_settings(self, dt, quick, omega_f):
        """[(method label, setting label, tokens)] for every item of the `solver` enumeration:
        fixed-step items sweep solver.fixed_step = dt/n (n down to where the formula of the
        item's order, RK<order>, reaches round-off), the others solver.tolerance."""
        out = [("default", "defaults", [])]
        for name, val, desc in self.items("solver"):
            fixed = "fixed" in desc.lower() and "tolerance" not in desc.lower()
            sel = self.token("solver", val)
            if fixed:
                m = re.search(r"RK(\d+)$", name)  # RK4, RK5, RK8, ExpRK4
                order = int(m.group(1)) if m else 4
                for n in substep_counts(dt, quick, h_min=round_off_step(order, omega_f)):
                    out.append((name, f"n={n}", [sel, self.token("solver.fixed_step", dt / n)]))
            else:
                tols = TOLS if not quick else [1e-6, 1e-10]
                if name == "DormandPrince853" and not quick:
                    # the eighth-order pair is the one that reaches round-off cheaply: down to
                    # solver.tolerance's minimum, so its front covers the tightest baselines
                    tols = tols + TOLS_HIGH_ORDER
                for tol in tols:
                    out.append((name, f"tol={tol:g}",
                                [sel, self.token("solver.tolerance", tol)]))
        return out


def round_off_step(order, omega_f):
    """The substep below which a formula of this order has nothing left to gain: omega_f h =
    1e-14^(1/order) (its local error ~ (omega_f h)^order at round-off), at least H_MIN_RK4."""
    return max(H_MIN_RK4, 1e-14 ** (1.0 / order) / omega_f)


def substep_counts(dt, quick, cap=N_MAX_RK4, h_min=H_MIN_RK4):
    """n = 1, 2, 4, ... while dt/n >= h_min (n = 1 always)."""
    ns, n = [], 1
    while (n == 1 or dt / n >= h_min * (1 - 1e-9)) and n <= (4 if quick else cap):
        ns.append(n)
        n *= 2
    return ns


def rel_err(x, xref):
    k = min(len(x), len(xref))
    return float(np.max(np.abs(x[:k] - xref[:k])) / np.max(np.abs(xref[:k])))
