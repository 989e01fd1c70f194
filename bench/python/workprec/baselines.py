"""Python baselines, on a window at the start of each scene (they cost 10^4-10^5 times more per
step than the native runs): scipy solve_ivp restarted on every communication interval, the
pythonfmu peer (bench/python/tld_py.py) and TLD.fmu, both through fmpy."""
from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tld_fmu.scenes import TOLS, FmpyDamper, coupled_master, n_steps, rel_err, substep_counts

HERE = Path(__file__).resolve().parent.parent   # bench/python, where tld_py.py is
PY_REPEATS = 3          # Python baselines: median of this many runs over the window


class ScipyDamper:
    """solve_ivp restarted on every communication interval with the held base.a: the simplest
    correct thing for held inputs (one run with t_eval would integrate across the jumps)."""

    def __init__(self, p, method, rtol):
        from scipy.integrate import solve_ivp
        self.solve_ivp = solve_ivp
        self.method, self.rtol = method, rtol
        self.atol = [rtol * p.a / 2, rtol * p.a / 2 * p.omega_f]   # the FMU's error scales
        self.c = 2 * p.zeta_fixed * p.omega_f
        self.w2 = p.omega_f ** 2
        self.q = p.phi * (2 / p.a) ** (2 * p.eta - 2)
        self.pw = 2 * p.eta - 2
        self.m = p.m
        self.y = [float(p.x0), float(p.v0)]

    def outputs(self):
        x, v = self.y
        return (x, v, self.m * (self.c * v + self.w2 * x * (1 + self.q * abs(x) ** self.pw)))

    def step(self, t, dt, ab):
        c, w2, q, pw = self.c, self.w2, self.q, self.pw

        def rhs(t, y):
            x, v = y
            return [v, -ab - c * v - w2 * x * (1.0 + q * abs(x) ** pw)]

        sol = self.solve_ivp(rhs, (t, t + dt), self.y, method=self.method, rtol=self.rtol,
                             atol=self.atol)
        if not sol.success:
            raise RuntimeError(sol.message)
        self.y = [float(sol.y[0, -1]), float(sol.y[1, -1])]
        return self.outputs()


def open_loop(damper, a, dt, n):
    xs = np.zeros(n + 1)
    xs[0] = damper.outputs()[0]
    for k in range(n):
        xs[k + 1] = damper.step(k * dt, dt, float(a[k]))[0]
    return xs


def slave_for(path: Path):
    import fmpy
    from tld_fmu.slave import Slave
    md = fmpy.read_model_description(str(path))
    d = tempfile.mkdtemp(prefix="tld_bench_py_")
    fmpy.extract(str(path), d)
    variables = {v.name: v for v in md.modelVariables}
    return lambda: Slave(md, d, variables, logging_on=False), d


def build_pythonfmu(work: Path):
    """pythonfmu build -f bench/python/tld_py.py -> work/pythonfmu/TLDPy.fmu (or None, reason)."""
    out = work / "pythonfmu"
    out.mkdir(parents=True, exist_ok=True)
    exe = Path(sys.executable).parent / "pythonfmu"
    cmd = [str(exe), "build", "-f", str(HERE / "tld_py.py"), "-d", str(out)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    fmu = out / "TLDPy.fmu"
    if r.returncode != 0 or not fmu.exists():
        return None, f"`{' '.join(cmd)}` failed: {r.stderr.strip() or r.stdout.strip()}"
    return fmu, " ".join(["pythonfmu", "build", "-f", "bench/python/tld_py.py"])


def python_window(sc, dt, quick):
    n = n_steps(sc, dt)
    return min(n, int(round(min(sc.T, 20.0) / dt)), 150 if quick else 2000)


_warm: dict = {}


def run_python(fi, sc, dt, a, refs, quick, tld_slave, py_slave):
    """scipy (DOP853, LSODA), pythonfmu RK4, and TLD.fmu through fmpy, on the window."""
    rows = []
    nw = python_window(sc, dt, quick)
    xref = refs[(sc.key, dt)]["x"][: nw + 1]
    p = sc.p

    def record(impl, method, setting, fn):
        times = []
        for _ in range(PY_REPEATS):
            t0 = time.perf_counter()
            try:
                x = fn()
            except Exception as e:  # a failed baseline is a result, not a crash
                rows.append(dict(scene=sc.key, dt=dt, n=nw, impl=impl, method=method,
                                 setting=setting, window=True, status="fail",
                                 message=str(e)[:200], err=None, ns_step=None, ns_simsec=None))
                return None
            times.append((time.perf_counter() - t0) * 1e9)
        ns = float(np.median(times))
        rows.append(dict(scene=sc.key, dt=dt, n=nw, impl=impl, method=method, setting=setting,
                         window=True, status="ok", ns_step=ns / nw, ns_simsec=ns / (nw * dt),
                         err=rel_err(x, xref), _x=x))
        return x

    def run_damper(make):
        d = make()
        if sc.kind == "coupled":
            return coupled_master(d, sc.coupled, dt, nw, p.m0)[0]
        return open_loop(d, a, dt, nw)

    for method in ("DOP853", "LSODA"):
        for tol in (TOLS if not quick else [1e-6, 1e-10]):
            record("scipy solve_ivp", method, f"rtol={tol:g}",
                   lambda: run_damper(lambda: ScipyDamper(p, method, tol)))
    # pythonfmu peer
    if py_slave is not None:
        if not _warm.get("py"):
            s = py_slave()      # first instance loads the embedded interpreter: not timed
            s.initialize({"zeta": 0.01})
            s.run(0.001, {"base_a": np.zeros(50)}, ["slosh_x"])
            s.close()
            _warm["py"] = True
        py_params = dict(tank_length=p.a, tank_breadth=p.b, tank_depth=p.h, density=p.rho,
                         g=p.g, eta=p.eta, phi=p.phi, zeta=p.zeta_fixed)
        for ns in substep_counts(dt, quick, cap=32):
            def go(ns=ns):
                s = py_slave()
                try:
                    s.initialize({**py_params, "fixed_step": dt / ns})
                    if sc.kind == "coupled":
                        d = FmpyDamper(s, "base_a", ["slosh_x", "slosh_v", "force"])
                        return coupled_master(d, sc.coupled, dt, nw, p.m0)[0]
                    r = s.run(dt, {"base_a": a[:nw]}, ["slosh_x"])
                    return r["slosh_x"]
                finally:
                    s.close()
            record("pythonfmu", "RK4", f"n={ns}", go)
    # TLD.fmu through fmpy: default solver settings (cross-check against the native host)
    def tld(sc=sc):
        s = tld_slave()
        try:
            s.initialize(fi.scene_params(sc))
            if sc.kind == "coupled":
                d = FmpyDamper(s, "base.a", ["slosh.x", "slosh.v", "force"])
                d.m0 = s.get("mass.inactive")
                return coupled_master(d, sc.coupled, dt, nw, d.m0)[0]
            return s.run(dt, {"base.a": a[:nw]}, ["slosh.x"])["slosh.x"]
        finally:
            s.close()
    record("TLD.fmu via fmpy", "default", "defaults", tld)
    return rows
