"""The coupled system Building.fmu + TLD.fmu as SSP 1.0 archives (System Structure and
Parameterization), and runs of such an archive in the SSP hosts that install here.

An archive (`.ssp`, a zip) holds
    SystemStructure.ssd          the system: components Building and TLD, their connectors, the
                                 connections, the units, a default experiment
    resources/Building.fmu, resources/TLD.fmu
    resources/Building.ssv, resources/TLD.ssv   each component's parameter values
Connections: Building.tld.a -> TLD.base.a, tld.v -> base.v, tld.x -> base.x (the damper floor's
absolute motion) and TLD.force -> Building.tld.force. TLD's `mass.inactive` (a calculated
parameter: the liquid moving rigidly with the tanks) goes into Building's `tld.mass` as a value
in Building.ssv, computed here by instantiating TLD.fmu with the system's TLD parameters: a
parameter-to-parameter connection is not something the hosts evaluate before initialisation.

Each system shakes itself: Building.ssv sets Building.fmu's built-in harmonic ground motion
(`ground.amplitude` A, `ground.omega` w: x_g = A sin(w t), exact within Building's step), so a
host that opens the archive and runs its default experiment, setting nothing, gets the damped
response (Table 2.1: 1 mm at w = w_s, the structure's resonance; the 3-storey building: the
example's 0.2 mm at its first mode with the damper's inactive liquid, Building's
mode[1].omega). Building.fmu's `ground.a` is left unconnected: a host may set it each step,
and that ground acceleration is ADDED to the built-in motion.

Everything named in the archive is read from the two FMUs' modelDescriptions (variable names,
types, units, the Integer aliases of Enumerations), so the archive cannot drift from the FMUs;
the .ssd and .ssv are validated against the SSP 1.0 schemas that fmpy ships.

The systems are described like the configurations of tld_fmu.building ({"building": {"masses",
"stiffnesses", "rayleigh"}, "dampers": [{"floor", "tanks", "params"}]}), with exactly one damper
(Building.fmu carries one), plus "ground": {"amplitude" [m], "omega" [rad/s], or None: the
building's first mode with the damper's inactive mass}, the built-in motion: `table21()` (the
seed's Table 2.1 structure, tld_fmu.sdof) and the example 3-storey building of
scripts/examples/building.toml.

Hosts (tld_fmu.ssp_hosts, also importable from here; each runs `steps` steps of h, sets
Building.ground.a before step k to ground_a[k] if given, else not at all, and returns
{"Component.variable": array over t_0..t_n}):
`run_libcosim` (libcosimpy: CosimExecution.from_ssp_file), `run_ecos` (ecospy: EcosSimulation
with ssp_path), `run_fmpy` (fmpy.ssp: its SSD reader and its Jacobi step over the components).
All three are Jacobi masters with inputs held over the step: every component steps from t_k with
the outputs of the others at t_k, so they compute the same numbers up to the rounding of their
clocks.

    .venv/bin/python -m tld_fmu.ssp                       # write systems/*.ssp from target/fmu
    .venv/bin/python -m tld_fmu.ssp run systems/tld_table21.ssp [--host libcosim ...] [--csv F]
                                                          # the default experiment, nothing set
"""
from __future__ import annotations

import math
import sys
import tempfile
import tomllib
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from . import fmulog
from .contract import Contract
from .paths import BUILDING_FMU, FMU, REPO
from .ssp_hosts import HOSTS, load_tbb, run_ecos, run_fmpy, run_libcosim  # noqa: F401  (the hosts, here too)

SSD_NS = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC_NS = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV_NS = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
# libcosim reads its fixed-step algorithm from this annotation of the default experiment (and
# matches the prefix `osp:` literally); other hosts ignore it.
OSP_NS = "http://opensimulationplatform.com/SSP/OSPAnnotations"

# the name of both components' parameter sets: Ecos merges the sets of one name across the
# components and applies the one named in init(); libcosim and OMSimulator apply each
# component's (first) binding whatever its name
PARAMETER_SET = "default"

# the system's name inside the archive (OMSimulator's paths: <archive name>.root.Building.ground.a)
SYSTEM = "root"

SYSTEMS_DIR = REPO / "systems"
BUILDING_EXAMPLE = REPO / "scripts" / "examples" / "building.toml"

# (Building output, TLD input) and (TLD output, Building input): the coupling of Building.fmu and TLD.fmu
CONNECTIONS = [("Building", "tld.a", "TLD", "base.a"),
               ("Building", "tld.v", "TLD", "base.v"),
               ("Building", "tld.x", "TLD", "base.x"),
               ("TLD", "force", "Building", "tld.force")]
# more connectors declared (for hosts and tools that list them; the results the tests compare)
EXTRA_CONNECTORS = {"Building": ["ground.a", "roof.x", "base_shear"],
                    "TLD": ["slosh.x", "force.mean", "energy.dissipated"]}


# Table 2.1's built-in ground motion: 1 mm, the README's demo amplitude, at w_s
TABLE21_GROUND_AMPLITUDE = 1e-3


def table21():
    """The seed's Table 2.1 structure (tld_fmu.sdof: M, zeta, w_s) as a 1-storey building with one
    25 cm tank at TLD.fmu's defaults on its floor, shaken at w_s by 1 mm."""
    from .sdof import K_S, M_S, W_S, ZETA_S
    return {"building": {"masses": [M_S], "stiffnesses": [K_S], "rayleigh": [ZETA_S, ZETA_S]},
            "dampers": [{"floor": 1, "tanks": 1, "params": {}}],
            "ground": {"amplitude": TABLE21_GROUND_AMPLITUDE, "omega": W_S}}


def building_example():
    """The example 3-storey building of scripts/examples/building.toml (its building and damper),
    shaken by the example's ground amplitude at its first mode (with the damper's inactive mass)."""
    cfg = tomllib.loads(BUILDING_EXAMPLE.read_text())
    return {"building": cfg["building"], "dampers": cfg["dampers"],
            "ground": {"amplitude": cfg["load"]["ground_amplitude"], "omega": None}}


# name of the archive in systems/ -> (description, configuration, default experiment (stop, step))
SYSTEMS = {
    "tld_table21": ("The seed's Table 2.1 structure (M = 168 kg, 0.32 % damping, w_s = 5.636 rad/s) "
                    "with one 25 cm tank (TLD.fmu's defaults)", table21, (60.0, 0.01)),
    "tld_building": ("The example 3-storey shear building of scripts/examples/building.toml with its "
                     "tanks on the roof", building_example, (60.0, 0.01)),
}


def _one_damper(cfg):
    dampers = cfg.get("dampers", [])
    if len(dampers) != 1:
        raise ValueError(f"an SSP system carries one damper (Building.fmu has one tld.floor), not {len(dampers)}")
    return dampers[0]


def tld_parameters(cfg, tld: Contract) -> dict:
    """TLD.fmu's parameter values of the system {name: value}, as every host can set them: an
    Enumeration through its Integer alias `<name>_id` (libcosim and Ecos cannot set
    Enumerations; the alias overrides the enumeration), its item given by name or value."""
    d = _one_damper(cfg)
    out = {"tanks": int(d.get("tanks", 1))}
    for name, value in d.get("params", {}).items():
        var = tld.variable(name)
        if var.type == "Enumeration":
            alias = f"{name}_id"
            if alias not in tld.variables:
                raise KeyError(f"{name} is an Enumeration without an Integer alias {alias}")
            out[alias] = int(tld.value(name, value))
        else:
            out[name] = value
    return out


def inactive_mass(tld_fmu: Path, params: dict) -> float:
    """TLD.fmu's mass.inactive with these parameters (instantiated and initialised with fmpy)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(str(tld_fmu))
    contract = Contract(md)
    with tempfile.TemporaryDirectory(prefix="tld_ssp_") as d:
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(tld_fmu), d),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="mass")
        cb = fmulog.callbacks()   # warnings to fmulog.REPORT, each on its own line
        fmu.instantiate(callbacks=cb)
        try:
            contract.initialise(fmu, params)
            return fmu.getReal([contract.vr("mass.inactive")])[0]
        finally:
            fmu.terminate()
            fmu.freeInstance()


def ground_motion(cfg, tld_mass: float) -> tuple[float, float]:
    """(amplitude [m], omega [rad/s]) of the system's built-in ground motion ((0, 0): none); an
    omega of None is the building's first mode with the damper's inactive mass on its floor."""
    g = cfg.get("ground")
    if not g:
        return 0.0, 0.0
    omega = g.get("omega")
    if omega is None:
        from .building import structure
        omega = structure(cfg, [(int(_one_damper(cfg)["floor"]) - 1, tld_mass)]).omega1
    return float(g["amplitude"]), float(omega)


def building_parameters(cfg, building: Contract, tld_mass: float) -> dict:
    """Building.fmu's parameter values of the system {name: value}."""
    b = cfg["building"]
    masses, stiffnesses, (z1, z2) = b["masses"], b["stiffnesses"], b["rayleigh"]
    if len(masses) != len(stiffnesses):
        raise ValueError("one mass and one stiffness per storey")
    out = {"storeys": len(masses), "tld.floor": int(_one_damper(cfg)["floor"])}
    if z1 == z2:
        out["damping.zeta"] = z1
    else:
        out["damping.zeta1"], out["damping.zeta2"] = z1, z2
    for i, (m, k) in enumerate(zip(masses, stiffnesses), start=1):
        out[f"storey[{i}].mass"], out[f"storey[{i}].stiffness"] = m, k
    out["tld.mass"] = tld_mass
    amplitude, omega = ground_motion(cfg, tld_mass)
    if amplitude:
        out["ground.amplitude"], out["ground.omega"] = amplitude, omega
    for name in out:
        building.variable(name)   # every name exists in Building.fmu
    return out


def _real(x) -> str:
    return repr(float(x))   # shortest round-trip form: the host reads back the same double


def ssv(name: str, contract: Contract, values: dict) -> str:
    """A parameter set (SystemStructureParameterValues 1.0) with each value typed as in the FMU."""
    lines = []
    for pname, value in values.items():
        var = contract.variable(pname)
        if var.type == "Real":
            unit = f' unit={quoteattr(var.unit)}' if var.unit else ""
            typed = f'<ssv:Real value="{_real(value)}"{unit}/>'
        elif var.type == "Integer":
            typed = f'<ssv:Integer value="{int(value)}"/>'
        elif var.type == "Boolean":
            typed = f'<ssv:Boolean value="{"true" if value else "false"}"/>'
        else:
            raise TypeError(f"{pname}: {var.type} parameters are not written (hosts cannot set them)")
        lines.append(f'    <ssv:Parameter name={quoteattr(pname)}>{typed}</ssv:Parameter>')
    units = _units(contract, [p for p in values if contract.variable(p).type == "Real"])
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<ssv:ParameterSet xmlns:ssv="{SSV_NS}" xmlns:ssc="{SSC_NS}" version="1.0" name={quoteattr(name)}>\n'
            '  <ssv:Parameters>\n' + "\n".join(lines) + '\n  </ssv:Parameters>\n'
            + _units_xml(units, "ssv", "  ") + '</ssv:ParameterSet>\n')


def _units(contract: Contract, names) -> dict:
    """{unit name: {base unit exponent: value}} of the named variables, from the modelDescription."""
    defined = {u.name: u for u in contract.md.unitDefinitions}
    out = {}
    for n in names:
        unit = contract.variable(n).unit
        if unit:
            bu = defined[unit].baseUnit
            exps = {}
            if bu is not None:
                for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad", "factor", "offset"):
                    v = getattr(bu, k, None)
                    if v not in (None, 0) and not (k == "factor" and v == 1):
                        exps[k] = v
            out[unit] = exps
    return out


def _units_xml(units: dict, prefix: str, indent: str) -> str:
    if not units:
        return ""
    rows = []
    for name, exps in sorted(units.items()):
        attrs = "".join(f' {k}="{v:g}"' if k in ("factor", "offset") else f' {k}="{int(v)}"'
                        for k, v in exps.items())
        rows.append(f'{indent}  <ssc:Unit name={quoteattr(name)}><ssc:BaseUnit{attrs}/></ssc:Unit>')
    return f'{indent}<{prefix}:Units>\n' + "\n".join(rows) + f'\n{indent}</{prefix}:Units>\n'


def connectors(contract: Contract, component: str) -> list[str]:
    """The connectors of a component: its ends of the connections, then the extra outputs."""
    names = [c[1] for c in CONNECTIONS if c[0] == component] + \
            [c[3] for c in CONNECTIONS if c[2] == component] + EXTRA_CONNECTORS[component]
    return list(dict.fromkeys(names))


def ssd(name: str, description: str, contracts: dict, stop: float, step: float) -> str:
    """SystemStructure.ssd (SystemStructureDescription 1.0) of the coupled system."""
    comps, all_units = [], {}
    for comp, contract in contracts.items():
        rows = []
        for cname in connectors(contract, comp):
            var = contract.variable(cname)
            if var.type != "Real" or var.causality not in ("input", "output"):
                raise TypeError(f"{comp}.{cname}: connectors are Real inputs and outputs")
            unit = f' unit={quoteattr(var.unit)}' if var.unit else ""
            rows.append(f'          <ssd:Connector name={quoteattr(cname)} kind="{var.causality}">'
                        f'<ssc:Real{unit}/></ssd:Connector>')
        all_units.update(_units(contract, connectors(contract, comp)))
        comps.append(
            f'      <ssd:Component name="{comp}" type="application/x-fmu-sharedlibrary" '
            f'source="resources/{comp}.fmu">\n'
            '        <ssd:Connectors>\n' + "\n".join(rows) + '\n        </ssd:Connectors>\n'
            '        <ssd:ParameterBindings>\n'
            f'          <ssd:ParameterBinding type="application/x-ssp-parameter-set" source="resources/{comp}.ssv"/>\n'
            '        </ssd:ParameterBindings>\n'
            '      </ssd:Component>')
    for a, ac, b, bc in CONNECTIONS:   # both ends must be an output and an input of the FMUs
        if contracts[a].variable(ac).causality != "output" or contracts[b].variable(bc).causality != "input":
            raise TypeError(f"{a}.{ac} -> {b}.{bc} is not output -> input")
    conns = [f'      <ssd:Connection startElement="{a}" startConnector="{ac}" endElement="{b}" endConnector="{bc}"/>'
             for a, ac, b, bc in CONNECTIONS]
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<ssd:SystemStructureDescription xmlns:ssd="{SSD_NS}" xmlns:ssc="{SSC_NS}" '
            f'xmlns:ssv="{SSV_NS}" xmlns:osp="{OSP_NS}" name={quoteattr(name)} version="1.0" '
            'generationTool="tld-fmu python/tld_fmu/ssp.py">\n'
            f'  <ssd:System name="{SYSTEM}" description={quoteattr(description + ". Building.fmu moves the ground itself (ground.amplitude, ground.omega in Building.ssv); Building.ground.a (m/s2), if a host sets it, adds to that motion.")}>\n'
            '    <ssd:Elements>\n' + "\n".join(comps) + '\n    </ssd:Elements>\n'
            '    <ssd:Connections>\n' + "\n".join(conns) + '\n    </ssd:Connections>\n'
            '  </ssd:System>\n'
            + _units_xml(all_units, "ssd", "  ") +
            f'  <ssd:DefaultExperiment startTime="0.0" stopTime="{_real(stop)}">\n'
            '    <ssd:Annotations>\n'
            '      <ssc:Annotation type="com.opensimulationplatform">\n'
            f'        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="{_real(step)}"/></osp:Algorithm>\n'
            '      </ssc:Annotation>\n'
            '    </ssd:Annotations>\n'
            '  </ssd:DefaultExperiment>\n'
            '</ssd:SystemStructureDescription>\n')


def validate(xml: str, schema: str):
    """Validate an .ssd or .ssv against fmpy's copy of the SSP 1.0 schema `schema`
    (SystemStructureDescription.xsd or SystemStructureParameterValues.xsd); raises with the
    schema's messages."""
    import fmpy.ssp
    from lxml import etree
    xsd = etree.XMLSchema(file=str(Path(fmpy.ssp.__file__).parent / "schema" / schema))
    doc = etree.fromstring(xml.encode())
    if not xsd.validate(doc):
        raise ValueError(f"not valid against SSP 1.0 {schema}:\n"
                         + "\n".join(f"  line {e.line}: {e.message}" for e in xsd.error_log))


def contents(name: str, tld_fmu: Path = FMU, building_fmu: Path = BUILDING_FMU, system=None) -> dict:
    """The text files of system `name`'s archive {path in the archive: text}, validated. system:
    (description, configuration, (stop, step)) as in SYSTEMS, for a system not listed there
    (scripts/tower.py's)."""
    description, make, (stop, step) = system or SYSTEMS[name]
    cfg = make()
    tld, bld = Contract(str(tld_fmu)), Contract(str(building_fmu))
    tp = tld_parameters(cfg, tld)
    bp = building_parameters(cfg, bld, inactive_mass(tld_fmu, tp))
    files = {"SystemStructure.ssd": ssd(name, description, {"Building": bld, "TLD": tld}, stop, step),
             "resources/Building.ssv": ssv(PARAMETER_SET, bld, bp),
             "resources/TLD.ssv": ssv(PARAMETER_SET, tld, tp)}
    validate(files["SystemStructure.ssd"], "SystemStructureDescription.xsd")
    for k in ("resources/Building.ssv", "resources/TLD.ssv"):
        validate(files[k], "SystemStructureParameterValues.xsd")
    return files


def write(name: str, out_dir: Path = SYSTEMS_DIR, tld_fmu: Path = FMU,
          building_fmu: Path = BUILDING_FMU, system=None) -> Path:
    """Write systems/<name>.ssp: the text files of `contents` and both FMUs."""
    files = contents(name, tld_fmu, building_fmu, system)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / f"{name}.ssp"
    tmp = path.with_suffix(".ssp.tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for arc, text in files.items():
            z.writestr(arc, text)
        z.write(building_fmu, "resources/Building.fmu")
        z.write(tld_fmu, "resources/TLD.fmu")
    tmp.replace(path)
    return path


def read(ssp: Path, member: str) -> str:
    with zipfile.ZipFile(ssp) as z:
        return z.read(member).decode()


def default_experiment(ssp: Path) -> tuple[float, float]:
    """(stop time, step) of an archive's default experiment (the step from its OSP annotation)."""
    from lxml import etree
    doc = etree.fromstring(read(ssp, "SystemStructure.ssd").encode())
    exp = doc.find(f"{{{SSD_NS}}}DefaultExperiment")
    algo = exp.find(f".//{{{OSP_NS}}}FixedStepAlgorithm")
    return float(exp.get("stopTime")), float(algo.get("baseStepSize"))


def harmonic_ground(w: float, amplitude: float):
    """Ground motion with x_g = amplitude (1 - cos w t) (at rest displaced by 0 at t = 0, zero-mean
    velocity: what Building.fmu integrates from ground.a from rest) as ground(t) -> (a_g, v_g,
    x_g), the form tld_fmu.building.simulate takes: the motion a host adds through ground.a."""
    return lambda t: (amplitude * w * w * math.cos(w * t), amplitude * w * math.sin(w * t),
                      amplitude * (1 - math.cos(w * t)))


def built_in_ground(ssp_path: Path) -> tuple[float, float]:
    """(amplitude [m], omega [rad/s]) of the built-in ground motion an archive's Building.ssv
    sets ((0, 0): none), read back from the archive."""
    from lxml import etree
    doc = etree.fromstring(read(ssp_path, "resources/Building.ssv").encode())
    value = {p.get("name"): float(p[0].get("value")) for p in doc.iter(f"{{{SSV_NS}}}Parameter")}
    return value.get("ground.amplitude", 0.0), value.get("ground.omega", 0.0)


def sum_grounds(*grounds):
    """The sum of ground motions ground(t) -> (a_g, v_g, x_g)."""
    return lambda t: tuple(sum(c) for c in zip(*(g(t) for g in grounds)))


def system_ground(ssp_path: Path, omega: float = 0.0, amplitude: float = 0.0):
    """The ground motion of a run of the archive as ground(t) -> (a_g, v_g, x_g): its built-in
    motion A sin(w t) (tld_fmu.building.harmonic_ground) plus, if amplitude, what the host adds
    through ground.a (harmonic_ground here; continuous, where the hosts hold ground.a over the
    step)."""
    from . import building
    built_in_amplitude, built_in_omega = built_in_ground(ssp_path)
    grounds = [building.harmonic_ground(built_in_omega, built_in_amplitude)]
    if amplitude:
        grounds.append(harmonic_ground(omega, amplitude))
    return sum_grounds(*grounds)


def run(ssp_path: Path, hosts, omega: float, amplitude: float, duration: float, h: float,
        outputs=("Building.roof.x", "Building.base_shear", "TLD.force", "TLD.slosh.x")) -> dict:
    """Run an archive in each of `hosts` for `duration`: its built-in ground motion, plus, if
    amplitude, the ground motion x_g = amplitude (1 - cos omega t) set on ground.a (held over
    each step of h); {host: {output: array at t_0..t_n}}."""
    steps = int(round(duration / h))
    a = None
    if amplitude:
        g = harmonic_ground(omega, amplitude)
        a = [g(k * h)[0] for k in range(steps)]
    return {host: HOSTS[host](ssp_path, h, steps, list(outputs), a) for host in hosts}


def _component(ssp_path: Path, name: str, directory: str):
    """(model description, unzipped directory) of component `name`'s FMU inside an archive."""
    from fmpy import extract, read_model_description
    fmu = Path(directory) / f"{name}.fmu"
    with zipfile.ZipFile(ssp_path) as z:
        fmu.write_bytes(z.read(f"resources/{name}.fmu"))
    return read_model_description(str(fmu)), extract(str(fmu), str(Path(directory) / name))


def units(ssp_path: Path, outputs) -> dict:
    """{"Component.variable": unit} of outputs, from the components' modelDescriptions."""
    out = {}
    with tempfile.TemporaryDirectory(prefix="tld_ssp_") as d:
        for comp in {o.split(".", 1)[0] for o in outputs}:
            md, _ = _component(ssp_path, comp, d)
            for v in md.modelVariables:
                unit = v.unit or (v.declaredType.unit if v.declaredType is not None else None)
                out[f"{comp}.{v.name}"] = unit or "1"
    return {o: out.get(o, "?") for o in outputs}


def without_damper(ssp_path: Path, h: float, steps: int, outputs, ground_a=None) -> dict:
    """The archive's Building.fmu alone, without the damper: its Building.ssv parameters but
    tld.mass = 0 and tld.force = 0, the same ground motion, steps of h (fmpy); {output: array at
    t_0..t_n} for the Building outputs among `outputs`."""
    from fmpy.fmi2 import FMU2Slave
    from lxml import etree
    doc = etree.fromstring(read(ssp_path, "resources/Building.ssv").encode())
    params = {}
    for p in doc.iter(f"{{{SSV_NS}}}Parameter"):
        v = p[0]
        params[p.get("name")] = int(v.get("value")) if etree.QName(v).localname == "Integer" else float(v.get("value"))
    params["tld.mass"] = 0.0
    names = [o.split(".", 1)[1] for o in outputs if o.startswith("Building.")]
    with tempfile.TemporaryDirectory(prefix="tld_ssp_") as d:
        md, unzipdir = _component(ssp_path, "Building", d)
        c = Contract(md)
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName="bare")
        cb = fmulog.callbacks()
        fmu.instantiate(callbacks=cb)
        try:
            c.initialise(fmu, params)
            vrs = [c.vr(n) for n in names]
            res = np.empty((steps + 1, len(names)))
            res[0] = fmu.getReal(vrs)
            for k in range(steps):
                if ground_a is not None:
                    fmu.setReal([c.vr("ground.a")], [float(ground_a[k])])
                fmu.doStep(k * h, h)
                res[k + 1] = fmu.getReal(vrs)
        finally:
            fmu.terminate()
            fmu.freeInstance()
    return {f"Building.{n}": res[:, j] for j, n in enumerate(names)}


def main(argv=None):
    import argparse
    ap = argparse.ArgumentParser(
        description="Write systems/*.ssp from target/fmu/TLD.fmu and target/fmu/Building.fmu "
                    "(no arguments), or run one archive in the SSP hosts (run ...).")
    sub = ap.add_subparsers(dest="cmd")
    w = sub.add_parser("write", help="write the archives (the default)")
    w.add_argument("--out", default=str(SYSTEMS_DIR))
    w.add_argument("names", nargs="*", default=list(SYSTEMS), choices=[[]] + list(SYSTEMS))
    r = sub.add_parser("run", help="run an archive (its built-in ground motion, plus harmonic ground.a if "
                                   "--amplitude) in SSP hosts and compare them")
    r.add_argument("ssp")
    r.add_argument("--host", action="append", choices=list(HOSTS),
                   help="libcosim, Ecos or fmpy (repeatable; default: all three)")
    r.add_argument("--omega", type=float, default=5.6,
                   help="frequency of the motion added through ground.a [rad/s] (5.6)")
    r.add_argument("--amplitude", type=float, default=0.0,
                   help="ground displacement amplitude A [m] added through ground.a: x_g = A (1 - cos w t) "
                        "(0: none, the archive's built-in motion alone)")
    r.add_argument("--duration", type=float, help="[s] (the default experiment's stop time)")
    r.add_argument("--step", type=float, help="communication step [s] (the default experiment's)")
    r.add_argument("--csv", help="write the first host's time histories to this CSV file")
    args = ap.parse_args(argv)
    if args.cmd != "run":
        out = Path(getattr(args, "out", SYSTEMS_DIR))
        for name in getattr(args, "names", None) or list(SYSTEMS):
            print(write(name, out))
        return
    hosts = args.host or list(HOSTS)
    if "Ecos" in hosts:
        import shutil
        if not shutil.which("unzip"):
            sys.exit("Ecos unpacks the FMUs with the system `unzip`: install it (apt-get install unzip)")
    stop, step = default_experiment(Path(args.ssp))
    args.duration = stop if args.duration is None else args.duration
    args.step = step if args.step is None else args.step
    runs = run(Path(args.ssp), hosts, args.omega, args.amplitude, args.duration, args.step)
    first = runs[hosts[0]]
    n = len(next(iter(first.values()))) - 1
    a_b, w_b = built_in_ground(Path(args.ssp))
    added = f" + ground.a: x_g = {args.amplitude:g} (1 - cos {args.omega:g} t) m" if args.amplitude else ""
    print(f"{args.ssp}: {n} steps of {args.step} s, built-in x_g = {a_b:g} sin({w_b:.6g} t) m{added}")
    unit = units(Path(args.ssp), list(first))
    for host, res in runs.items():
        print(f"  {host:9s} " + ", ".join(f"max|{o}| = {np.max(np.abs(v)):.9g} {unit[o]}" for o, v in res.items()))
    for host in hosts[1:]:
        worst = max(float(np.max(np.abs(runs[host][o] - first[o])) / np.max(np.abs(first[o])))
                    for o in first)
        print(f"  {host} vs {hosts[0]}: max relative difference {worst:.2e}")
    ga = None
    if args.amplitude:
        g = harmonic_ground(args.omega, args.amplitude)
        ga = [g(k * args.step)[0] for k in range(n)]
    bare = without_damper(Path(args.ssp), args.step, n, list(first), ga)
    print(f"  the same building without the damper over the same {n * args.step:g} s (Building.fmu alone, "
          f"tld.mass = 0, fmpy), against {hosts[0]} with it:")
    for o, v in bare.items():
        b, d = float(np.max(np.abs(v))), float(np.max(np.abs(first[o])))
        print(f"    max|{o}|: {b:.6g} {unit[o]} without, {d:.6g} {unit[o]} with the damper "
              f"({100 * (1 - d / b):.1f} % less)")
    if args.csv:
        cols = ["time"] + list(first)
        data = np.column_stack([np.arange(n + 1) * args.step] + [first[o] for o in first])
        np.savetxt(args.csv, data, delimiter=",", header=",".join(cols), comments="")
        print(f"wrote {args.csv} ({hosts[0]})")
    # the FMU messages that reached Python (fmpy's host and the run without the damper);
    # libcosim and Ecos print their FMUs' messages themselves as they run
    fmulog.REPORT.print_summary()


if __name__ == "__main__":
    main()
