"""The coupled systems as SSP archives (python/tld_fmu/ssp.py, systems/*.ssp): standard-conformant,
built from the FMUs, and the same numbers in every SSP host that installs here.

Scenes, 0.01 s steps for 10 s:
- the archive as it opens: nothing set by the host, Building.fmu's built-in ground motion
  (Building.ssv: x_g = A sin(w t), Table 2.1 1 mm at w_s, the 3-storey building 0.2 mm at its
  first mode) shakes the system;
- the same plus ground motion the host adds: x_g = A (1 - cos w t) near the first mode
  (ground.a = A w^2 cos(w t_k) held over step k, set by each host on Building.ground.a, the
  system's one free input).
Compared: Building's roof.x and base_shear, TLD's force and slosh.x at every communication point.

- libcosim (libcosimpy), Ecos (ecospy) and fmpy.ssp load the archive themselves (components,
  connections, parameter sets) and are all Jacobi masters with held inputs: every component
  steps from t_k with the others' outputs at t_k. They agree at round-off (fmpy and Ecos bit for
  bit; libcosim to ~1e-14, its integer-nanosecond clock giving step sizes that differ from 0.01
  in the last bits).
- tld_fmu.building.simulate (scripts/building.py's master) couples the same system differently
  (Gauss-Seidel: the building steps first with the damper's force.mean, by RK4, then the damper
  with the building's motion at the step's end): its difference from the hosts is the coupling
  error's, first order in the step, and halves with it.

Not compared: Building's tld.a, an output that feeds through tld.force. Read after a step, its
value depends on whether the host has already written the new TLD.force into Building: Ecos
reads outputs again after its connections (tld.a with force(t_k+1)), libcosim's observer and
fmpy before (tld.a with force(t_k)); the two differ by (force(t_k+1) - force(t_k)) / m, about
w h of the force: 2.6e-3 of tld.a's peak for Table 2.1 at 0.01 s. What the TLD receives is the
same in every host (its slosh.x and force agree bit for bit).
"""
from __future__ import annotations

import os
import shutil
import tempfile
import zipfile

import numpy as np
import pytest

from ecos_unzip import write_standin
from tld_fmu import ssp
from tld_fmu.building import Building, Damper, simulate

H, T_END = 0.01, 10.0
W, A_G = 5.6, 1e-4           # rad/s (near w_1 of both systems), m
OUTPUTS = ["Building.roof.x", "Building.base_shear", "TLD.force", "TLD.slosh.x"]
RTOL = 1e-12                 # max|diff| / max|value| between hosts


@pytest.fixture(scope="module", autouse=True)
def ecos_unzip(tmp_path_factory):
    """Ecos unpacks the archive's FMUs with the system `unzip` (test_hosts_ecospy.py)."""
    if shutil.which("unzip"):
        yield
        return
    d = tmp_path_factory.mktemp("ecos_unzip")
    write_standin(d)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PATH", f"{d}{os.pathsep}{os.environ.get('PATH', '')}")
        yield


@pytest.fixture(scope="module")
def archives(fmu_path, building_path, tmp_path_factory):
    """Both systems written afresh from the FMUs under test."""
    d = tmp_path_factory.mktemp("systems")
    return {name: ssp.write(name, d, fmu_path, building_path) for name in ssp.SYSTEMS}


def ground_a(h, t_end, scale=1.0):
    g = ssp.harmonic_ground(W, A_G * scale)
    return [g(k * h)[0] for k in range(int(round(t_end / h)))]


def rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


_RUNS = {}


def run(host, path, h=H, t_end=T_END, scale=1.0, added=True):
    """A host's run of an archive: its built-in ground motion, plus (added) the harmonic ground.a."""
    key = (host, str(path), h, t_end, scale, added)
    if key not in _RUNS:
        steps = int(round(t_end / h))
        _RUNS[key] = ssp.HOSTS[host](path, h, steps, OUTPUTS + ["Building.mode[1].omega"],
                                     ground_a(h, t_end, scale) if added else None)
    return _RUNS[key]


def test_archives_hold_the_coupled_system(archives, fmu_path, building_path):
    from fmpy.ssp.ssd import read_ssd
    from tld_fmu.contract import Contract
    contracts = {"Building": Contract(str(building_path)), "TLD": Contract(str(fmu_path))}
    for name, path in archives.items():
        with zipfile.ZipFile(path) as z:
            assert sorted(z.namelist()) == sorted(
                ["SystemStructure.ssd", "resources/Building.fmu", "resources/TLD.fmu",
                 "resources/Building.ssv", "resources/TLD.ssv"]), name
            assert z.read("resources/TLD.fmu") == fmu_path.read_bytes()
            assert z.read("resources/Building.fmu") == building_path.read_bytes()
        ssd = read_ssd(str(path), validate=True)       # fmpy checks it against the SSP 1.0 schema
        links = {(c.startElement, c.startConnector, c.endElement, c.endConnector)
                 for c in ssd.system.connections}
        assert links == {("Building", "tld.a", "TLD", "base.a"), ("Building", "tld.v", "TLD", "base.v"),
                         ("Building", "tld.x", "TLD", "base.x"), ("TLD", "force", "Building", "tld.force")}
        for comp in ssd.system.elements:
            for c in comp.connectors:   # every connector is a variable of its FMU, same causality
                assert contracts[comp.name].variable(c.name).causality == c.kind, (name, comp.name, c.name)
        for member in ("resources/Building.ssv", "resources/TLD.ssv"):
            ssp.validate(ssp.read(path, member), "SystemStructureParameterValues.xsd")


def test_a_bad_document_is_refused_by_the_schema():
    """The schema check can fail: a connection without its end connector is not SSP 1.0."""
    bad = ('<ssd:SystemStructureDescription xmlns:ssd="%s" name="x" version="1.0">'
           '<ssd:System name="x"><ssd:Connections><ssd:Connection startElement="a" startConnector="b" '
           'endElement="c"/></ssd:Connections></ssd:System></ssd:SystemStructureDescription>' % ssp.SSD_NS)
    with pytest.raises(ValueError, match="not valid"):
        ssp.validate(bad, "SystemStructureDescription.xsd")


def test_systems_directory_is_built_from_these_fmus(fmu_path, building_path):
    """systems/*.ssp (written by scripts/run and scripts/test after scripts/package) are what
    tld_fmu.ssp makes of the FMUs in target/fmu now: they cannot drift from them."""
    for name in ssp.SYSTEMS:
        path = ssp.SYSTEMS_DIR / f"{name}.ssp"
        assert path.is_file(), f"{path} missing: run .venv/bin/python -m tld_fmu.ssp (scripts/run does)"
        for member, text in ssp.contents(name, fmu_path, building_path).items():
            assert ssp.read(path, member) == text, f"{path}: {member} is stale; rebuild with -m tld_fmu.ssp"
        with zipfile.ZipFile(path) as z:
            assert z.read("resources/TLD.fmu") == fmu_path.read_bytes(), f"{path}: stale TLD.fmu"
            assert z.read("resources/Building.fmu") == building_path.read_bytes(), f"{path}: stale Building.fmu"


@pytest.mark.parametrize("name", list(ssp.SYSTEMS))
def test_every_host_applies_the_parameters(archives, fmu_path, name):
    """Building's first mode as each host reports it after loading the archive is the one
    tld_fmu.building computes from the system's masses and stiffnesses, with the damper's
    mass.inactive (read here from a TLD instance with the system's parameters) on its floor."""
    from fmpy import extract, read_model_description
    cfg = ssp.SYSTEMS[name][1]()
    d = cfg["dampers"][0]
    md = read_model_description(str(fmu_path))
    damper = Damper(extract(str(fmu_path), tempfile.mkdtemp()), md, d["floor"], d.get("tanks", 1),
                    d.get("params", {}), "mass")
    extra = np.zeros(len(cfg["building"]["masses"]))
    extra[damper.floor] = damper.inactive
    damper.close()
    b = cfg["building"]
    want = Building(b["masses"], b["stiffnesses"], b["rayleigh"], extra).omega1
    for host in ssp.HOSTS:
        got = run(host, archives[name])["Building.mode[1].omega"]
        assert abs(got[-1] - want) < 1e-12 * want, f"{host}: omega_1 {got[-1]} vs {want}"


def test_the_archives_shake_their_building(archives, fmu_path):
    """Building.ssv sets the built-in ground motion: Table 2.1 1 mm at w_s (its resonance), the
    3-storey building the example's amplitude at its first mode (Building's mode[1].omega, with
    the damper's inactive liquid, as the hosts report it)."""
    from tld_fmu.sdof import W_S
    assert ssp.built_in_ground(archives["tld_table21"]) == (ssp.TABLE21_GROUND_AMPLITUDE, W_S)
    amplitude, omega = ssp.built_in_ground(archives["tld_building"])
    assert amplitude == ssp.building_example()["ground"]["amplitude"] > 0
    for host in ssp.HOSTS:
        w1 = run(host, archives["tld_building"], added=False)["Building.mode[1].omega"][-1]
        assert abs(omega - w1) < 1e-12 * w1, (host, omega, w1)


@pytest.mark.parametrize("added", [False, True], ids=["as_opened", "with_ground.a"])
@pytest.mark.parametrize("name", list(ssp.SYSTEMS))
def test_hosts_agree(archives, name, added):
    """As opened (no input set: the built-in ground motion alone) and with ground.a added."""
    runs = {host: run(host, archives[name], added=added) for host in ssp.HOSTS}
    roof = runs["fmpy"]["Building.roof.x"]
    amplitude, _ = ssp.built_in_ground(archives[name])
    # near resonance the roof moves more than the ground
    assert np.max(np.abs(roof)) > amplitude, "the ground motion does not reach the building"
    hosts = list(runs)
    lines = []
    for i, a in enumerate(hosts):
        for b in hosts[i + 1:]:
            worst = max(rel(runs[a][o], runs[b][o]) for o in OUTPUTS)
            lines.append(f"{a} vs {b}: {worst:.2e}")
            assert worst < RTOL, f"{name}: {a} vs {b} differ by {worst:.3g}"
    print(f"\n{name}, {'with' if added else 'without'} ground.a, {len(roof) - 1} steps of {H} s, "
          f"max|roof.x| {np.max(np.abs(roof)):.4g} m, max relative difference: " + "; ".join(lines))


def test_the_comparison_tells_a_1ppm_change_apart(archives):
    a = run("fmpy", archives["tld_table21"])
    b = run("fmpy", archives["tld_table21"], scale=1 + 1e-6)
    assert min(rel(b[o], a[o]) for o in OUTPUTS) > 100 * RTOL


@pytest.mark.parametrize("added", [False, True], ids=["as_opened", "with_ground.a"])
@pytest.mark.parametrize("name", list(ssp.SYSTEMS))
def test_building_py_agrees_at_the_coupling_order(archives, fmu_path, name, added):
    """scripts/building.py's master on the same system (tld_fmu.building.simulate, Gauss-Seidel
    with force.mean, RK4) against the hosts (Jacobi, exact building step): the difference is
    first order in the step (halves when the step halves), of the size of w h. The ground
    motion given to building.py is the archive's built-in one, read back from Building.ssv
    (tld_fmu.building.harmonic_ground), plus the one the hosts add through ground.a."""
    from fmpy import extract, read_model_description
    cfg = ssp.SYSTEMS[name][1]()
    md = read_model_description(str(fmu_path))
    unzipdir = extract(str(fmu_path), tempfile.mkdtemp())
    g = ssp.system_ground(archives[name], W, A_G if added else 0.0)
    err = {}
    for h in (H, H / 2):
        host = run("libcosim", archives[name], h=h, added=added)
        py = simulate(cfg, unzipdir, md, g, h, T_END)
        err[h] = (rel(host["Building.roof.x"], py["X"][:, -1]), rel(host["TLD.force"], py["F"][:, 0]))
    print(f"\n{name} ({'with' if added else 'without'} ground.a) vs tld_fmu.building: "
          "max relative difference (roof.x, force) "
          + ", ".join(f"h = {h}: {e[0]:.2e}, {e[1]:.2e}" for h, e in err.items()))
    for j in range(2):
        ratio = err[H][j] / err[H / 2][j]
        assert 1.8 < ratio < 2.2, f"{name}: difference ratio {ratio:.3f} when the step halves (first order: 2)"
        assert err[H][j] < 2 * W * H, f"{name}: {err[H][j]:.3g} is more than the coupling error w h"


def test_libcosim_runs_the_default_experiment(archives):
    """With no step size given, libcosim takes the fixed-step algorithm of the default
    experiment's annotation (0.01 s), and with nothing set the building moves (its built-in
    ground motion)."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.WARNING)
    stop, step = ssp.SYSTEMS["tld_table21"][2]
    assert ssp.default_experiment(archives["tld_table21"]) == (stop, step)
    ex = CosimExecution.from_ssp_file(str(archives["tld_table21"]))
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    assert ex.step(100)
    assert ex.status().current_time == 100 * round(step * 1e9)
    index = {s.name.decode(): s.index for s in ex.slave_infos()}
    vr = {v.name.decode(): v.reference for v in ex.slave_variables(index["Building"])}
    roof = obs.last_real_values(index["Building"], [vr["roof.x"]])[0]
    assert abs(roof) > 1e-4, f"roof.x {roof} after 1 s: the building does not move"
    assert f'stopTime="{stop!r}"' in ssp.read(archives["tld_table21"], "SystemStructure.ssd")
