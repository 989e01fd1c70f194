"""The compiled design-study master (tools' tld-study, tld_fmu.native) against the Python master
(tld_fmu.building.simulate): the same study through both engines gives the same numbers in every
output column (held inputs and derivative coupling, several tank counts, a varied FMU parameter),
the same peaks per floor for a 3-storey building with dampers on two floors, and study files or
runs that cannot work are refused with a message that names them."""
import math
import tomllib

import numpy as np
import pytest

from tld_fmu import building, native
from tld_fmu import study as sweep
from tld_fmu.contract import Contract
from tld_fmu.paths import REPO

STUDY = {
    "structure": {"mass": 168.0, "damping": 0.0032},
    "damper": {"params": {"amplitude": "Tracked"}},
    "study": {"tuning": [0.95, 1.05], "tanks": [1, 3], "ground_amplitude": [1e-4, 1e-3],
              "frequency": [0.9, 1.1, 3], "params": {"damping": ["Constant", "NSD"]}},
    "run": {"duration": 6.0, "tail": 3.0, "step": 5e-3},
}
OUTPUTS = ["peak_displacement", "amplification"]
TOL = 1e-12


def rel(a, b):
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


@pytest.fixture(scope="module")
def master_path():
    return sweep.master_binary()


@pytest.mark.parametrize("engine", sweep.ENGINES)
def test_a_refused_run_names_itself_whichever_engine(fmu_path, engine):
    study = {**STUDY, "study": {**STUDY["study"], "params": {}, "tanks": [1], "tuning": [1.0],
                                "ground_amplitude": [math.nan], "frequency": [1.0, 1.0, 1]}}
    rows, _ = sweep.run_study(study, fmu_path, progress=False, engine=engine)
    assert len(rows) == 1
    e = rows[0]["error"]
    assert e.startswith("run 0 (tuning 1; 1 tank(s); ground amplitude nan m; w/w_s 1): RuntimeError: "
                        "the damper refused its inputs at t = 0"), e


@pytest.mark.parametrize("derivatives", [False, True], ids=["held", "derivatives"])
def test_the_engines_agree_in_every_column(fmu_path, master_path, derivatives):
    study = {**STUDY, "run": {**STUDY["run"], "derivatives": derivatives}}
    rows = {e: sweep.run_study(study, fmu_path, progress=False, engine=e)[0] for e in sweep.ENGINES}
    n = len(rows["native"])
    assert n == len(rows["python"]) == 2 * 2 * 2 * 2 * 3
    worst = 0.0
    for a, b in zip(rows["native"], rows["python"]):
        assert not a["error"] and not b["error"], (a["error"], b["error"])
        for k in ["damping"] + sweep.COLUMNS:
            if k in OUTPUTS:
                worst = max(worst, rel(a[k], b[k]))
                assert rel(a[k], b[k]) <= TOL, (k, a, b)
            else:
                assert a[k] == b[k], (k, a, b)
    print(f"\n{n} runs ({'derivatives' if derivatives else 'held inputs'}): largest relative difference "
          f"between the engines {worst:.1e}")
    # the study says something: the runs differ (a master that ignored its inputs would not)
    peaks = [r["peak_displacement"] for r in rows["native"]]
    assert len(set(peaks)) == n and all(p > 0 for p in peaks)


@pytest.mark.parametrize("derivatives", [False, True], ids=["held", "derivatives"])
def test_a_building_with_dampers_on_two_floors(unzipdir, model_description, master_path, derivatives):
    """N storeys, two dampers on different floors: the master's matrix arithmetic and its sums
    onto floors, floor by floor (numpy's matrix products may sum in another order: 1e-12)."""
    cfg = tomllib.loads((REPO / "scripts" / "examples" / "building.toml").read_text())
    cfg["dampers"].append({"floor": 2, "tanks": 1, "params": {"amplitude": "Fixed"}})
    h, duration, tail, w, a = 2e-3, 6.0, 3.0, 5.3, 3e-4
    s = building.simulate(cfg, unzipdir, model_description, building.harmonic_ground(w, a), h, duration,
                          derivatives=derivatives)
    keep = s["t"] > duration - tail
    ref = np.max(np.abs(s["X"][keep]), axis=0)
    inactive = []
    for d in cfg["dampers"]:
        dp = building.Damper(unzipdir, model_description, d["floor"], d["tanks"], d["params"], "probe")
        inactive.append(dp.inactive)
        dp.close()
    m = native.Master(master_path, unzipdir, model_description)
    try:
        got = m.run([native.request("building", cfg, Contract(model_description), inactive, w, a, h, duration,
                                    tail, derivatives)])[0]
    finally:
        m.close()
    assert "error" not in got, got
    assert got["instances"] == 2 and got["steps"] == 3000
    diff = [rel(x, y) for x, y in zip(got["peak"], ref)]
    print(f"\npeaks per floor {ref}; relative differences {diff}")
    assert len(got["peak"]) == 3 and max(diff) <= TOL


def test_a_run_the_fmu_refuses_is_named_and_the_others_complete(fmu_path, tmp_path):
    """NaN ground amplitude: the FMU refuses base.a; the master names the run and goes on."""
    study = {**STUDY, "study": {**STUDY["study"], "params": {}, "tanks": [1],
                                "ground_amplitude": [1e-4, math.nan]}}
    rows, _ = sweep.run_study(study, fmu_path, progress=False)
    bad = [r for r in rows if r["error"]]
    assert len(bad) == 6 and len(rows) == 12
    for r in bad:
        assert math.isnan(r["ground_amplitude"]) and math.isnan(r["peak_displacement"])
        assert "refused its inputs at t = 0" in r["error"], r["error"]
        assert f"w/w_s {r['frequency_ratio']:g})" in r["error"] and "run " in r["error"], r["error"]
    assert all(r["peak_displacement"] > 0 for r in rows if not r["error"])


def test_a_master_that_dies_fails_its_runs_with_the_reason(fmu_path, tmp_path, monkeypatch):
    """A master that cannot start: every run of its batches fails, saying so, none is lost."""
    fake = tmp_path / "tld-study"
    fake.write_text("#!/bin/sh\necho 'no FMU here' >&2\nexit 3\n")
    fake.chmod(0o755)
    monkeypatch.setenv("TLD_STUDY_MASTER", str(fake))
    study = {**STUDY, "study": {**STUDY["study"], "params": {}, "tanks": [1], "tuning": [1.0]}}
    rows, _ = sweep.run_study(study, fmu_path, progress=False)
    assert len(rows) == 6
    assert all("no FMU here" in r["error"] and math.isnan(r["peak_displacement"]) for r in rows), rows[0]
    assert all(r["error"].startswith(f"run {i} (tuning 1;") for i, r in enumerate(rows)), rows[0]["error"]


@pytest.mark.parametrize("change, says", [
    (lambda s: s["structure"].update(dampng=0.1), "unknown key 'dampng' in [structure]"),
    (lambda s: s.update(runs={}), "unknown section [runs]"),
    (lambda s: s["run"].pop("tail"), "[run] tail is missing"),
    (lambda s: s["structure"].update(mass=-1.0), "[structure] mass = -1.0"),
    (lambda s: s["study"].update(tanks=[1, 2.5]), "[study] tanks = [1, 2.5]"),
    (lambda s: s["study"].update(frequency=[1.2, 0.8, 5]), "[study] frequency = [1.2, 0.8, 5]"),
    (lambda s: s["run"].update(tail=100.0), "[run] tail = 100.0"),
    (lambda s: s["study"]["params"].update(damping=["Constant", "Viscous"]), "no item 'Viscous'"),
    (lambda s: s["damper"]["params"].update({"tank.lenght": 0.3}), "no variable 'tank.lenght'"),
    (lambda s: s["damper"]["params"].update({"force": 1.0}), "force is no parameter"),
])
def test_study_files_that_cannot_work_are_refused_by_name(fmu_path, tmp_path, change, says):
    import copy
    study = copy.deepcopy(STUDY)
    change(study)
    f = tmp_path / "bad.toml"
    f.write_text(sweep.dump_study(study))
    with pytest.raises(SystemExit) as e:
        sweep.main([str(f), "--serial", "--fmu", str(fmu_path), "--out", str(tmp_path / "out")])
    assert says in str(e.value) and str(f) in str(e.value), str(e.value)
    assert not (tmp_path / "out" / "bad.csv").exists()


def test_the_example_study_files_are_valid(fmu_path):
    c = Contract(fmu_path)
    for name in ("study.toml", "design.toml"):
        sweep.load_study(REPO / "scripts" / "examples" / name, c)


def test_a_master_binary_busy_for_a_moment_is_started_on_a_later_attempt(monkeypatch):
    """study.py writes the compiled master next to the unpacked FMU; a process another worker
    thread forks during that write keeps the file "busy" (ETXTBSY) for a moment (a CI run's sweep
    lost a run to it). native.start tries again for that error only, and not for ever."""
    import errno
    import subprocess

    monkeypatch.setattr(native.time, "sleep", lambda s: None)
    calls = []

    def popen(args, **kw):
        calls.append(args)
        if len(calls) <= busy:
            raise OSError(errno.ETXTBSY, "Text file busy")
        if other:
            raise OSError(errno.ENOENT, "No such file")
        return "started"

    monkeypatch.setattr(subprocess, "Popen", popen)
    busy, other = 3, False
    assert native.start(["tld-study"], stdin=None) == "started"
    assert len(calls) == 4
    calls.clear()
    busy = 100   # busy on every attempt: the error reaches the caller after them all
    with pytest.raises(OSError) as e:
        native.start(["tld-study"], attempts=5)
    assert e.value.errno == errno.ETXTBSY and len(calls) == 5
    calls.clear()
    busy, other = 0, True   # any other error at once
    with pytest.raises(OSError) as e:
        native.start(["tld-study"])
    assert e.value.errno == errno.ENOENT and len(calls) == 1
