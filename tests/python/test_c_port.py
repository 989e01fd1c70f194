"""The benchmark's Rust port of the careful C FMU (bench/port) computes what the C FMU
(bench/c/tld_c.c) computes, bit for bit: the port exists to time rustc's back end on the C's own
program (issue #29), which only means something if it is the same program.

Both are built by the benchmark's own builder (bench/python/workprec/cfmu.py: gcc -O2 for the C,
cargo's release profile for the port), as they are and with the energies (-DTLD_C_ENERGIES /
feature energies), loaded with ctypes and
driven with the same calls: a strongly nonlinear resonant scene (2x/a near 0.6) through RK4 with
one and with three substeps and DormandPrince45 at two tolerances (steps rejected and the step
size carried), then the refusals: a value out of range, a runaway step (fmi2Discard, the state
kept), an unknown output."""
from __future__ import annotations

import ctypes as C
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench" / "python"))
from workprec.cfmu import BUILDS, c_fmu  # noqa: E402

VR = dict(eta=8, phi=9, damping=10, zeta=11, solver=21, tol=22, fixed_step=23, model=6,
          base_a=50, force=60, x=63, v=64, e_in=65, e_diss=66, omega_f=40, length=0)
OK, DISCARD, ERROR = 0, 2, 3


def _load(path):
    lib = C.CDLL(str(path))
    lib.fmi2Instantiate.restype = C.c_void_p
    lib.fmi2Instantiate.argtypes = [C.c_char_p, C.c_int, C.c_char_p, C.c_char_p, C.c_void_p,
                                    C.c_int, C.c_int]
    for f in ("fmi2SetReal", "fmi2GetReal"):
        getattr(lib, f).argtypes = [C.c_void_p, C.POINTER(C.c_uint), C.c_size_t,
                                    C.POINTER(C.c_double)]
    lib.fmi2SetInteger.argtypes = [C.c_void_p, C.POINTER(C.c_uint), C.c_size_t,
                                   C.POINTER(C.c_int)]
    lib.fmi2DoStep.argtypes = [C.c_void_p, C.c_double, C.c_double, C.c_int]
    for f in ("fmi2ExitInitializationMode", "fmi2FreeInstance"):
        getattr(lib, f).argtypes = [C.c_void_p]
    return lib


@pytest.fixture(scope="module")
def builds(tmp_path_factory):
    """{(name, energies): library}: the C FMU by gcc and the port by cargo, each both ways."""
    tmp = tmp_path_factory.mktemp("cport")
    index = {name: k for k, (name, *_) in enumerate(BUILDS)}
    return {(who, energies): _load(c_fmu(tmp, index[name + ", energies" * energies]))
            for who, name in (("C", "C FMU"), ("port", "C FMU, Rust port"))
            for energies in (False, True)}


class Instance:
    def __init__(self, lib, reals, ints):
        self.lib = lib
        self.c = lib.fmi2Instantiate(b"t", 1, b"", b"", None, 0, 0)
        assert self.c
        for k, v in ints.items():
            assert lib.fmi2SetInteger(self.c, (C.c_uint * 1)(VR[k]), 1, (C.c_int * 1)(v)) == OK
        for k, v in reals.items():
            assert self.set(k, v) == OK
        self.status = lib.fmi2ExitInitializationMode(self.c)

    def set(self, k, v):
        return self.lib.fmi2SetReal(self.c, (C.c_uint * 1)(VR[k]), 1, (C.c_double * 1)(v))

    def get(self, names):
        vals = (C.c_double * len(names))()
        status = self.lib.fmi2GetReal(self.c, (C.c_uint * len(names))(*[VR[k] for k in names]),
                                      len(names), vals)
        return status, list(vals)

    def step(self, t, dt):
        return self.lib.fmi2DoStep(self.c, t, dt, 1)

    def free(self):
        self.lib.fmi2FreeInstance(self.c)


SCENE = dict(eta=2.0, phi=1.0, zeta=0.02)
CASES = [("RK4, one substep", dict(solver=2), dict(fixed_step=0.01)),
         ("RK4, three substeps", dict(solver=2), dict(fixed_step=0.004)),
         ("DP45 1e-6", dict(solver=1), dict(tol=1e-6)),
         ("DP45 1e-10", dict(solver=1), dict(tol=1e-10))]


@pytest.mark.parametrize("energies", [False, True], ids=["as it is", "energies"])
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_the_port_steps_as_the_c_fmu_bit_for_bit(builds, case, energies):
    _, ints, reals = case
    outs = ["x", "v", "force"] + (["e_in", "e_diss"] if energies else [])
    runs = {}
    for name in ("C", "port"):
        fmu = Instance(builds[(name, energies)], {**SCENE, **reals}, {"model": 2, "damping": 1,
                                                                       **ints})
        assert fmu.status == OK
        _, (w,) = fmu.get(["omega_f"])
        dt, hist = 0.01, []
        for k in range(1500):
            # resonant, 15 mm: 2x/a reaches about 0.6, the hardening a third of the force
            assert fmu.set("base_a", -w * w * 0.015 * math.sin(w * k * dt)) == OK
            assert fmu.step(k * dt, dt) == OK
            status, vals = fmu.get(outs)
            assert status == OK
            hist.append(vals)
        runs[name] = hist
        fmu.free()
    peak = max(abs(h[0]) for h in runs["C"])
    assert 0.04 < peak < 0.1, peak   # the scene is the nonlinear one meant
    for k, (a, b) in enumerate(zip(runs["C"], runs["port"])):
        assert a == b, f"step {k}: C {a} port {b}"


def test_the_port_refuses_what_the_c_fmu_refuses(builds):
    for name in ("C", "port"):
        lib = builds[(name, False)]
        bad = Instance(lib, {}, {"model": 1})
        assert bad.status == ERROR, name          # a model it does not implement
        bad.free()
        fmu = Instance(lib, SCENE, {"model": 2, "damping": 1, "solver": 2})
        assert fmu.status == OK
        assert fmu.set("zeta", 0.5) == ERROR, name       # a parameter after initialisation
        assert fmu.set("base_a", math.nan) == ERROR, name
        assert fmu.step(0.0, 0.01) == OK
        before = fmu.get(["x", "v"])
        assert fmu.set("base_a", 1e9) == OK
        assert fmu.step(0.01, 0.01) == DISCARD, name     # the runaway: state kept
        assert fmu.get(["x", "v"]) == before, name
        assert fmu.step(0.01, -1.0) == ERROR, name
        assert fmu.get(["e_in"])[0] == ERROR, name       # not an output of this build
        fmu.free()
