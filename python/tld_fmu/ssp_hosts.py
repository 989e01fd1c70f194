"""The SSP hosts that install here, each running an archive of tld_fmu.ssp: `run_libcosim`
(libcosimpy), `run_ecos` (ecospy), `run_fmpy` (fmpy.ssp). Each runs `steps` steps of h, sets
Building.ground.a before step k to ground_a[k] if given (added to Building's built-in ground
motion), else not at all, and likewise every input of `inputs` ({"Component.variable": values per
step}, e.g. Building's floor[i].force: wind), and returns {"Component.variable": array over
t_0..t_n}."""
from __future__ import annotations

import ctypes
import sys
from pathlib import Path

import numpy as np


def _columns(outputs):
    return [tuple(o.split(".", 1)) for o in outputs]


def _inputs(ground_a, inputs) -> list:
    """[((component, variable), values per step)]: ground_a as Building.ground.a, and `inputs`."""
    given = dict(inputs or {})
    if ground_a is not None:
        given["Building.ground.a"] = ground_a
    return list(zip(_columns(given), given.values()))


def run_libcosim(ssp: Path, h: float, steps: int, outputs, ground_a=None, inputs=None) -> dict:
    """libcosim (libcosimpy): the archive as libcosim loads it (CosimExecution.from_ssp_file, a
    fixed-step execution of step h, integer nanoseconds), ground.a (if given) through an
    override manipulator before each step, the outputs from a last-value observer. ground_a[k]
    is held over step k; returns the outputs at t_0..t_n (t_0: 0, the observer has no values
    before the first step; the outputs compared are 0 at rest)."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    # Loading, libcosim warns once per Enumeration variable of TLD.fmu (model, damping, amplitude,
    # solver: "FMI 2.0 Enumeration variable type not supported ... will be ignored"). Nothing is
    # lost: the archive sets those parameters through their Integer aliases (model_id, ...), which
    # libcosim handles. Those four lines are all it says while loading these archives, so the load
    # runs at level error; the run itself at warning.
    log_output_level(CosimLogLevel.ERROR)
    try:
        ex = CosimExecution.from_ssp_file(str(Path(ssp).resolve()), round(h * 1e9))
    finally:
        log_output_level(CosimLogLevel.WARNING)
    index = {s.name.decode(): s.index for s in ex.slave_infos()}
    vr = {name: {v.name.decode(): v.reference for v in ex.slave_variables(i)} for name, i in index.items()}
    man, obs = CosimManipulator.create_override(), CosimObserver.create_last_value()
    ex.add_manipulator(man)
    ex.add_observer(obs)
    cols = _columns(outputs)
    n = steps
    res = np.empty((n + 1, len(cols)))
    given = [(index[c], [vr[c][v]], values) for (c, v), values in _inputs(ground_a, inputs)]

    def read(k):
        for j, (c, v) in enumerate(cols):
            res[k, j] = obs.last_real_values(index[c], [vr[c][v]])[0]
    for k in range(n):
        for i, refs, values in given:
            man.slave_real_values(i, refs, [float(values[k])])
        ex.step(1)
        if k == 0:
            # the observer sees values after the first step only: t_0 is the state at rest
            res[0] = 0.0
        read(k + 1)
    return {o: res[:, j] for j, o in enumerate(outputs)}


def load_tbb():
    """Load libecosc.so's libtbb.so.12 (before importing ecospy): from the pinned `tbb` wheel
    (<venv>/lib), else the system's."""
    here = Path(sys.prefix) / "lib" / "libtbb.so.12"
    try:
        ctypes.CDLL(str(here) if here.is_file() else "libtbb.so.12", mode=ctypes.RTLD_GLOBAL)
    except OSError as e:
        raise RuntimeError(f"ecospy's libecosc.so needs libtbb.so.12: pip install tbb "
                           f"(pinned in scripts/requirements.txt) ({e})") from e


def run_ecos(ssp: Path, h: float, steps: int, outputs, ground_a=None, inputs=None) -> dict:
    """Ecos (ecospy): EcosSimulation from the archive, ground.a (if given) set between steps (Ecos
    passes it on right before the next fmi2DoStep), outputs read after each step. Needs `unzip`
    on PATH."""
    load_tbb()
    from ecospy import EcosSimulation
    sim = EcosSimulation(ssp_path=str(Path(ssp).resolve()), step_size=h)
    try:
        from .ssp import PARAMETER_SET
        sim.init(parameter_set=PARAMETER_SET)   # Ecos applies no set unless named
        ident = [f"{c}::{v}" for c, v in _columns(outputs)]
        n = steps
        res = np.empty((n + 1, len(ident)))
        res[0] = [sim.get_real(i) for i in ident]
        given = [(f"{c}::{v}", values) for (c, v), values in _inputs(ground_a, inputs)]
        for k in range(n):
            for name, values in given:
                sim.set_real(name, float(values[k]))
            sim.step()
            res[k + 1] = [sim.get_real(i) for i in ident]
    finally:
        sim.terminate()
        sim.free()
    return {o: res[:, j] for j, o in enumerate(outputs)}


def run_fmpy(ssp: Path, h: float, steps: int, outputs, ground_a=None, inputs=None) -> dict:
    """fmpy's SSP support (fmpy.ssp): its reader of the archive (schema-validated), its
    instantiation of the components and its Jacobi step `do_step` (set the inputs from the
    connectors, fmi2DoStep, get the outputs), the connections applied after every step as
    fmpy.ssp.simulate_ssp does. Two things simulate_ssp itself does not do are done here: it
    applies no ParameterBinding of the SSD (only a parameter set passed to it), so each
    component's .ssv is handed to it with the component's name prefixed; and it takes inputs
    only on system connectors, one step late, so ground.a (if given) is set on Building's
    connector; and it starts every connector at 0, where libcosim and Ecos pass on the outputs
    after initialisation before the first step (with the built-in ground motion tld.v starts at
    A w, not 0), so this does too."""
    from fmpy.ssp.simulation import do_step, free_fmu, instantiate_fmu
    from fmpy.ssp.ssd import ParameterSet, find_components, find_connectors, read_ssd
    from fmpy import extract
    ssd_ = read_ssd(str(ssp))
    components = {c.name: c for c in find_components(ssd_.system)}
    for c in find_connectors(ssd_.system):
        c.value = 0.0
    conn = {(c.parent.name, c.name): c for comp in components.values() for c in comp.connectors}
    # the SSD's connections as (start, end) connectors (fmpy.ssp.ssd.get_connections would wire
    # the unconnected input ground.a to the source of the input listed before it)
    connections = [(conn[(c.startElement, c.startConnector)], conn[(c.endElement, c.endConnector)])
                   for c in ssd_.system.connections]
    tmp = extract(str(ssp))
    try:
        for comp in components.values():
            comp.parent = ssd_.system   # set by read_ssd; the prefix of set_parameters
            params = ParameterSet(name=comp.name)
            for binding in comp.parameterBindings:
                for pset in binding.parameterValues:
                    for p in pset.parameters:
                        p.name = f"{comp.name}.{p.name}"
                        params.parameters.append(p)
            instantiate_fmu(comp, tmp, 0.0, None, params)
        from fmpy.ssp.simulation import get_value
        for comp in components.values():   # the outputs after initialisation, passed on
            for c in comp.connectors:
                if c.kind == "output":
                    c.value = get_value(comp, c.name)
        for start, end in connections:
            end.value = start.value
        ground = conn[("Building", "ground.a")]
        from fmpy.ssp.simulation import set_value
        others = _inputs(None, inputs)
        cols = _columns(outputs)
        n = steps
        res = np.empty((n + 1, len(cols)))

        def read(k):
            res[k] = [get_value(components[c], v) for c, v in cols]
        read(0)
        t = 0.0
        for k in range(n):
            if ground_a is not None:
                ground.value = float(ground_a[k])
            for (c, v), values in others:   # inputs that are no connectors of the SSD
                set_value(components[c], v, float(values[k]))
            for comp in components.values():
                do_step(comp, t, h)
            for start, end in connections:
                end.value = start.value
            t = (k + 1) * h
            read(k + 1)
        for comp in components.values():
            free_fmu(comp)
    finally:
        import shutil
        shutil.rmtree(tmp, ignore_errors=True)
    return {o: res[:, j] for j, o in enumerate(outputs)}


HOSTS = {"libcosim": run_libcosim, "Ecos": run_ecos, "fmpy": run_fmpy}
