"""The same run in fmpy and in Ecos (ecospy) gives the same numbers.

Ecos (Lars Ivar Hatledal's co-simulation engine; PyPI `ecospy` 0.7.2, a ctypes wrapper around the
bundled libecosc.so) co-simulates one TLD instance in the scene of test_hosts.py: communication
step 0.01 s for 20 s, base.a = -w^2 A sin(w t_k) held during step k. fmpy (the suite's `Slave`,
raw fmi2DoStep calls) runs the same scene; slosh.x and force must agree at every communication
point to max|diff|/max|value| < 1e-9.

How ecospy feeds a time-varying input: `sim.set_real("tld::base.a", v)` between steps. Ecos does
not call the FMU there: the value is cached in the variable's "property" and written with one
fmi2SetReal right before the next fmi2DoStep (the fixed-step algorithm applies the cached sets,
steps, then refreshes the cached gets). `sim.get_real(...)` after `sim.step()` reads that cache.
The same can be done from inside Ecos's own loop: a `SimulationListener` whose pre() sets the
input and whose post() reads the outputs, with one `sim.step(N)` call (both ways are run here and
give the same bits).

What Ecos does differently from fmpy (seen in its source and by tracing the FMI calls with gdb):
- time is a double accumulated step by step (t_(k+1) = t_k + 0.01), not k * 0.01: the
  communication points drift from k*dt by up to 3.2e-13 s over 2000 steps and the run ends at
  20.000000000000327 s. The step size passed to fmi2DoStep is exactly 0.01 every step. The
  FMU's results do not depend on that drift: Ecos and fmpy agree bit for bit (measured max
  relative difference 0.0), and fmpy replaying Ecos's own time grid is bitwise Ecos as well;
- call order: fmi2Instantiate (visible = false, loggingOn = false, a no-op logger: the FMU's log
  messages are dropped; fmuResourceLocation "file:////tmp/ecos_TLD_<uuid>/resources", with four
  slashes, in Ecos's own unpacked copy), fmi2SetupExperiment(no tolerance, start 0, no stop time),
  fmi2EnterInitializationMode, then every parameter in ONE fmi2SetInteger and ONE fmi2SetReal
  call (values from a parameter set or from set_* calls made before init()), then
  fmi2ExitInitializationMode. Per step: fmi2SetReal (only the values set since the last step),
  fmi2DoStep(t_k, 0.01, noSetFMUStatePriorToCurrentPoint = true), fmi2GetReal of only the
  variables read so far (twice per step: once in the algorithm, once after the connections);
- threading: properties are transferred with std::execution::par (TBB); with a single instance
  all FMI calls were seen on the calling Python thread and no worker thread was started. With
  several instances the calls may come from TBB worker threads;
- it does not check FMI status codes: fmi2SetReal, fmi2ExitInitializationMode and fmi2DoStep
  may return fmi2Error and init()/step() still report success. A parameter value the FMU
  rejects silently leaves the start value in place (test_ecos_does_not_report_fmi_errors), so
  the tests here read every parameter back through Ecos;
- Enumeration variables are not exposed at all ("No int property tld::model found!"): model,
  damping, amplitude and solver cannot be set; the plain Integer aliases model_id, damping_id,
  amplitude_id and solver_id can, and every model option is reached through them here.

Environment quirks of ecospy 0.7.2 on Linux (none of them about the FMU):
- libecosc.so needs libtbb.so.12, which the wheel does not ship: the pinned `tbb` wheel puts it
  in <venv>/lib, and this module loads it (RTLD_GLOBAL) before importing ecospy;
- Ecos unpacks an .fmu by running the system `unzip` (fork + execvp) and then `sh -c chmod +x`;
  with no `unzip` on PATH, add_model logs "Failed to unzip" and the process SEGFAULTS. If
  there is no `unzip` on PATH, this module puts a small Python stand-in (same arguments,
  zipfile) first on PATH, so the suite runs on a machine without Debian's unzip package too;
- add_model takes a path to the .fmu file: an extracted directory or a file:// URI is refused
  ("Unable to resolve model"). Identifiers are "instance::variable", also in parameter sets
  (an unqualified "nsd.c" there is ignored without a word);
- the `proxyfmu` executable (URI "proxyfmu://localhost?file=...": the FMU runs in a child
  process, over a Unix-domain socket) is installed without its execute bit; the test of that
  path runs a copy made executable in a temporary directory.
"""
from __future__ import annotations

import ctypes
import os
import shutil
import stat
from pathlib import Path

import numpy as np
import pytest

from conftest import MODELS_APART
from ecos_unzip import write_standin
from tld_fmu.contract import item, items
from tld_fmu.ssp import load_tbb
from host_scene import (
    DT, N, OUTPUTS, RTOL, T_END, base_acceleration, bitwise, compare, rel_diff, run_fmpy,
)


load_tbb()
# pinned in scripts/requirements.txt: a missing ecospy is an error here, not a skip
from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure, SimulationListener  # noqa: E402

EcosLib.set_log_level("warn")   # proxyfmu logs every boot at "info"

INSTANCE = "tld"

@pytest.fixture(scope="module", autouse=True)
def ecos_unzip(tmp_path_factory):
    """Ecos needs `unzip` on PATH (see the module docstring); provide one if there is none."""
    if shutil.which("unzip"):
        yield "system"
        return
    d = tmp_path_factory.mktemp("ecos_unzip")
    write_standin(d)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PATH", f"{d}{os.pathsep}{os.environ.get('PATH', '')}")
        yield "stand-in"


class _Feeder(SimulationListener):
    """Drives the input from inside Ecos's own step loop: pre() sets a[k] before step k, post()
    records the outputs. ctypes swallows exceptions raised in these callbacks (it only prints
    them), so they are kept and re-raised by the caller."""

    def __init__(self, sim, a):
        self.sim, self.a = sim, a
        self.rows, self.times, self.errors = [], [], []

    def pre(self, info):
        try:
            self.times.append(info.time)
            self.sim.set_real(f"{INSTANCE}::base.a", float(self.a[info.iterations]))
        except Exception as e:  # never let an exception unwind into libecosc
            self.errors.append(e)

    def post(self, info):
        try:
            self.rows.append([self.sim.get_real(f"{INSTANCE}::{n}") for n in OUTPUTS])
        except Exception as e:
            self.errors.append(e)


def run_ecos(uri, a, reals=None, ints=None, via="parameter_set", listener=False, readback=None):
    """The scene in Ecos. reals/ints: parameters, given to Ecos either as a parameter set of the
    simulation structure (via="parameter_set") or with set_real/set_integer before init()
    (via="setters"); both reach the FMU in initialization mode. The input is set with set_real
    before each sim.step() (or, listener=True, from a SimulationListener inside one
    sim.step(N)). Returns ({output: array of N values after each step}, communication points
    t_k, final time, {name: value read back through Ecos after init} for `readback`)."""
    reals, ints = dict(reals or {}), dict(ints or {})
    ss = EcosSimulationStructure()
    sim = None
    try:
        ss.add_model(INSTANCE, str(uri))
        pset = None
        if via == "parameter_set" and (reals or ints):
            pset = "scene"
            values = {f"{INSTANCE}::{k}": float(v) for k, v in reals.items()}
            values.update({f"{INSTANCE}::{k}": int(v) for k, v in ints.items()})
            assert ss.add_parameter_set(pset, values)
        sim = EcosSimulation(step_size=DT, structure=ss)
        if via == "setters":
            for k, v in reals.items():
                sim.set_real(f"{INSTANCE}::{k}", float(v))
            for k, v in ints.items():
                sim.set_integer(f"{INSTANCE}::{k}", int(v))
        assert sim.init(parameter_set=pset), EcosLib.get_last_error()
        back = {}
        for name in readback or []:
            kind = "integer" if name in ints else "real"
            back[name] = getattr(sim, f"get_{kind}")(f"{INSTANCE}::{name}")
        if listener:
            feeder = _Feeder(sim, a)
            sim.add_listener("feed", feeder)
            sim.step(N)
            if feeder.errors:
                raise feeder.errors[0]
            res, ts = np.array(feeder.rows), np.array(feeder.times)
        else:
            res, ts = np.empty((N, len(OUTPUTS))), np.empty(N)
            for k in range(N):
                ts[k] = sim.get_time()
                sim.set_real(f"{INSTANCE}::base.a", float(a[k]))
                sim.step()
                res[k] = [sim.get_real(f"{INSTANCE}::{n}") for n in OUTPUTS]
        t_final = sim.get_time()
        sim.terminate()
    finally:
        if sim is not None:
            sim.free()     # fmi2FreeInstance, removes Ecos's unpacked copy of the FMU
        ss.free()
    assert res.shape == (N, len(OUTPUTS)) and np.all(np.isfinite(res))
    assert abs(t_final - T_END) < 1e-9, t_final
    return {n: res[:, j] for j, n in enumerate(OUTPUTS)}, ts, t_final, back


def test_ecos_matches_fmpy(fmu_path, slave_factory, ecos_unzip):
    a = base_acceleration()
    fm = run_fmpy(slave_factory, a)
    ec, ts, t_final, _ = run_ecos(fmu_path, a)
    d = compare(ec, fm)
    print(f"\necos {EcosLib.version()} vs fmpy, {N} steps of {DT} s (unzip: {ecos_unzip}): "
          f"max|diff|/max|value| = {d}, bitwise identical: {bitwise(ec, fm)}; "
          f"max|slosh.x| = {np.max(np.abs(fm['slosh.x'])):.4g} m, "
          f"max|force| = {np.max(np.abs(fm['force'])):.4g} N; "
          f"ecos ends at t = {t_final!r}")
    assert np.max(np.abs(fm["slosh.x"])) > 1e-3   # the scene does move the liquid
    for n in OUTPUTS:
        assert d[n] < RTOL, f"{n}: ecos and fmpy differ by {d[n]:.3g} (relative)"


def test_ecos_listener_driven_run_is_the_same(fmu_path):
    """Feeding the input from a SimulationListener inside one sim.step(N) gives the same bits as
    set_real + sim.step() from Python, at the same communication points."""
    a = base_acceleration()
    loop, ts_loop, _, _ = run_ecos(fmu_path, a)
    lst, ts_lst, _, _ = run_ecos(fmu_path, a, listener=True)
    assert np.array_equal(ts_loop, ts_lst)
    assert bitwise(lst, loop), compare(lst, loop)


def test_ecos_time_grid_is_accumulated_and_fmpy_on_it_is_bitwise_ecos(fmu_path, variables, slave_factory):
    """Ecos's communication points are t_(k+1) = t_k + dt in double (not k*dt); fmpy calling
    fmi2DoStep(t_k, dt) on exactly those points reproduces Ecos bit for bit."""
    a = base_acceleration()
    ec, ts, t_final, _ = run_ecos(fmu_path, a)
    expect = np.concatenate([[0.0], np.cumsum(np.full(N, DT))])
    assert np.array_equal(ts, expect[:N]) and t_final == expect[N]
    drift = float(np.max(np.abs(ts - np.arange(N) * DT)))
    print(f"\necos communication points: max|t_k - k dt| = {drift:.3g} s, t_N = {t_final!r}")
    assert 0 < drift < 1e-11

    s = slave_factory(quiet=True).initialize()
    f, comp = s.fmu._functions, s.fmu.component
    in_vr = (ctypes.c_uint * 1)(variables["base.a"].valueReference)
    out_vr = (ctypes.c_uint * 2)(*[variables[n].valueReference for n in OUTPUTS])
    val, out = (ctypes.c_double * 1)(), (ctypes.c_double * 2)()
    res = np.empty((N, 2))
    for k in range(N):
        val[0] = a[k]
        assert f["fmi2SetReal"](comp, in_vr, 1, val) == 0
        assert f["fmi2DoStep"](comp, float(ts[k]), DT, 1) == 0, f"step {k}"
        assert f["fmi2GetReal"](comp, out_vr, 2, out) == 0
        res[k] = out[:]
    for j, n in enumerate(OUTPUTS):
        assert np.array_equal(res[:, j], ec[n]), f"{n}: {rel_diff(res[:, j], ec[n]):.3g}"


@pytest.mark.parametrize("via", ["parameter_set", "setters"])
def test_ecos_matches_fmpy_with_parameters(fmu_path, slave_factory, via):
    """A Real (nsd.c) and a plain Integer (tanks) set through Ecos (a parameter set of the
    structure, or set_real/set_integer before init) reach the FMU, change the result, and give
    fmpy's numbers."""
    a = base_acceleration()
    reals, ints = {"nsd.c": 0.8}, {"tanks": 3}
    fm = run_fmpy(slave_factory, a, {**reals, **ints})
    ec, _, _, back = run_ecos(fmu_path, a, reals, ints, via=via, readback=["nsd.c", "tanks"])
    assert back == {"nsd.c": 0.8, "tanks": 3}, back
    d = compare(ec, fm)
    default = run_fmpy(slave_factory, a)
    changed = rel_diff(fm["force"], default["force"])
    print(f"\nnsd.c = 0.8, tanks = 3 via {via}: ecos vs fmpy {d}, bitwise {bitwise(ec, fm)}; "
          f"vs the default run: force differs by {changed:.3g} (relative)")
    for n in OUTPUTS:
        assert d[n] < RTOL, f"{n}: ecos and fmpy differ by {d[n]:.3g} (relative)"
    assert changed > 0.1   # the parameters did change the run


def test_ecos_cannot_set_enumerations(fmu_path):
    """Records the limitation the alias test below works around: Ecos leaves Enumeration
    variables out; the plain Integer aliases are there. If a later ecospy exposes them, this
    fails: then also set model/damping themselves through Ecos."""
    ss = EcosSimulationStructure()
    ss.add_model(INSTANCE, str(fmu_path))
    sim = EcosSimulation(step_size=DT, structure=ss)
    try:
        for name in ("model", "damping", "amplitude", "solver"):
            with pytest.raises(Exception, match="No int property"):
                sim.set_integer(f"{INSTANCE}::{name}", items(name)[0][1])
            with pytest.raises(Exception, match="No int property"):
                sim.get_integer(f"{INSTANCE}::{name}")
        assert sim.init()
        # the aliases start at 0 ("use the enumeration"), not at an item
        assert [sim.get_integer(f"{INSTANCE}::{n}") for n in ("model_id", "damping_id", "tanks")] == [0, 0, 1]
        sim.terminate()
    finally:
        sim.free()
        ss.free()


DISTINCT = {"zeta": 0.02, **MODELS_APART}
MODELS = [name for name, _, _ in items("model")]   # every item of `model`, as declared


@pytest.mark.parametrize("model", MODELS)
def test_every_option_reachable_from_ecos_through_the_integer_aliases(fmu_path, slave_factory, model):
    """Ecos with model_id = m, damping_id = Constant's value, zeta = 0.02 (set_integer/set_real
    before init) matches fmpy setting the enumerations themselves (model = m, damping = Constant);
    the aliases take the enumerations' values."""
    a = base_acceleration()
    fm = {m: run_fmpy(slave_factory, a, {"model": m, "damping": "Constant", **DISTINCT}) for m in MODELS}
    aliases = {"model_id": item("model", model), "damping_id": item("damping", "Constant")}
    ec, _, _, back = run_ecos(fmu_path, a, DISTINCT, aliases,
                              via="setters", readback=["model_id", "damping_id", "zeta"])
    assert back == {**aliases, "zeta": 0.02}, back
    d = compare(ec, fm[model])
    print(f"\n{aliases}: ecos vs fmpy {d}")
    for n in OUTPUTS:
        assert d[n] < RTOL, f"model {model}, {n}: ecos and fmpy differ by {d[n]:.3g}"
    # the option took effect: Ecos's run is told apart from every other model's
    for other in set(fm) - {model}:
        assert rel_diff(ec["slosh.x"], fm[other]["slosh.x"]) > 100 * RTOL, (model, other)


def test_ecos_does_not_report_fmi_errors(fmu_path, variables, slave_factory):
    """A parameter value the FMU rejects (tank.length = -1, below its minimum): fmpy sees
    fmi2Error from fmi2SetReal; Ecos reports nothing, init() and the steps 'succeed', and the
    parameter keeps its start value. Hence the read-backs in the tests above."""
    from fmpy.fmi1 import FMICallException
    s = slave_factory()
    s.fmu.setupExperiment(startTime=0.0)
    with pytest.raises(FMICallException):
        s.set_vars({"tank.length": -1.0})
    assert any("tank.length" in m for _, _, m in s.error_messages())

    ss = EcosSimulationStructure()
    ss.add_model(INSTANCE, str(fmu_path))
    sim = EcosSimulation(step_size=DT, structure=ss)
    try:
        sim.set_real(f"{INSTANCE}::tank.length", -1.0)
        assert sim.init() is True
        sim.set_real(f"{INSTANCE}::base.a", 1.0)
        assert abs(sim.step(3) - 3 * DT) < 1e-12
        assert sim.get_real(f"{INSTANCE}::tank.length") == float(variables["tank.length"].start)
        sim.terminate()
    finally:
        sim.free()
        ss.free()


@pytest.mark.parametrize("scale, shift", [(1 + 1e-6, 0), (1.0, 1)], ids=["amplitude+1ppm", "one-step-late"])
def test_comparison_detects_a_different_input(fmu_path, slave_factory, scale, shift):
    """The comparison can fail: Ecos fed a slightly different input (1 ppm more amplitude, or the
    samples one step late) is told apart from fmpy by far more than the tolerance."""
    fm = run_fmpy(slave_factory, base_acceleration())
    ec, _, _, _ = run_ecos(fmu_path, base_acceleration(scale, shift))
    d = compare(ec, fm)
    print(f"\nperturbed input ({scale}, shift {shift}): {d}")
    assert all(v > 100 * RTOL for v in d.values()), d


@pytest.fixture(scope="module")
def proxyfmu_on_path(tmp_path_factory):
    """An executable copy of the wheel's proxyfmu (installed without its execute bit), first on
    PATH, where Ecos looks for it."""
    import ecospy
    src = Path(ecospy.__file__).parent / "binaries" / "proxyfmu"
    assert src.is_file(), src
    d = tmp_path_factory.mktemp("proxyfmu")
    exe = d / "proxyfmu"
    shutil.copy2(src, exe)
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PATH", f"{d}{os.pathsep}{os.environ.get('PATH', '')}")
        yield exe


def test_ecos_out_of_process_matches_fmpy(fmu_path, slave_factory, proxyfmu_on_path, tmp_path, monkeypatch):
    """Ecos's proxyfmu:// path: the FMU is loaded in a child process (proxyfmu) and every FMI call
    crosses a Unix-domain socket; parameters (parameter set) and the input (set_real per step)
    still give fmpy's numbers."""
    monkeypatch.chdir(tmp_path)   # proxyfmu writes logs/<instance>.txt into its working directory
    a = base_acceleration()
    reals, ints = {"nsd.c": 0.8}, {"tanks": 3}
    fm = run_fmpy(slave_factory, a, {**reals, **ints})
    uri = f"proxyfmu://localhost?file={fmu_path}"
    ec, _, _, back = run_ecos(uri, a, reals, ints, readback=["nsd.c", "tanks"])
    assert back == {"nsd.c": 0.8, "tanks": 3}, back
    d = compare(ec, fm)
    print(f"\necos out of process (proxyfmu) vs fmpy: {d}, bitwise {bitwise(ec, fm)}")
    for n in OUTPUTS:
        assert d[n] < RTOL, f"{n}: ecos (proxyfmu) and fmpy differ by {d[n]:.3g} (relative)"
