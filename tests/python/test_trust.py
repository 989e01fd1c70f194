"""What a structural engineer meets in the first hour (issue 26): the FMU's warnings shown on
their own lines and summarised, implausible configurations refused or flagged, misspelt names
answered with the closest valid ones, every script's --help, and no tracked file written by a
documented command. Each runs the scripts as a user does, on small inputs (a few seconds)."""
from __future__ import annotations

import io
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from tld_fmu import fmulog
from tld_fmu.paths import REPO
from tld_fmu.studyfile import dump_study

PY = sys.executable
WIND = tomllib.loads((REPO / "scripts" / "examples" / "wind.toml").read_text())
STUDY = tomllib.loads((REPO / "scripts" / "examples" / "study.toml").read_text())


def run(*args, cwd=REPO, timeout=300):
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    return subprocess.run(list(args), cwd=cwd, capture_output=True, text=True, timeout=timeout, env=env)


def building_file(tmp_path: Path, params: dict, duration=1.0, **building) -> Path:
    """wind.toml with its damper's params and the building changed, 1 s long."""
    d = {**WIND["dampers"][0], "params": params}
    text = (f"[building]\nmasses = {WIND['building']['masses']}\n"
            f"stiffnesses = {building.get('stiffnesses', WIND['building']['stiffnesses'])}\n"
            f"rayleigh = {WIND['building']['rayleigh']}\n"
            + "".join(f"{k} = {v!r}\n" for k, v in building.items() if k != "stiffnesses")
            + f"[[dampers]]\nfloor = {d['floor']}\ntanks = {d['tanks']}\n"
            + "params = { " + ", ".join(f'"{k}" = {v!r}' if not isinstance(v, str) else f'"{k}" = "{v}"'
                                         for k, v in params.items()) + " }\n"
            + "[load]\nkind = \"wind\"\nforce_rms = [0.6, 0.8, 1.0]\nseed = 1\n"
            + f"duration = {duration}\n[coupling]\nstep = 0.002\nderivatives = true\n")
    p = tmp_path / "b.toml"
    p.write_text(text.replace("'", '"'))
    return p


UNIT_MISTAKE = {"tank.length": 25.0, "tank.depth": 0.021, "amplitude": "Tracked"}   # 25 meant as cm


def test_report_line_stays_out_of_a_progress_bar(capsys):
    """A warning recorded while a bar is drawn is printed as a line of its own (not appended to
    the bar's line), and counted in the summary."""
    from tqdm import tqdm
    rep = fmulog.Report()
    bar = tqdm(total=10, desc="runs", file=sys.stderr, disable=False, ncols=60)
    bar.update(3)
    rep.record("tld0", 1, "logStatusWarning", "tank.length = 25 m: are the lengths in metres?")
    rep.record("tld0", 1, "logStatusWarning", "tank.length = 25 m: are the lengths in metres?")
    rep.record("tld0", 0, "logAll", "an OK message is no warning")
    bar.close()
    err = capsys.readouterr().err
    lines = [ln.split("\r")[-1] for ln in err.split("\n")]
    assert "FMU warning: tank.length = 25 m: are the lengths in metres?" in lines, err
    assert err.count("tank.length = 25 m") == 1, err      # shown once
    summary = rep.summary()
    assert summary[0].startswith("warnings: 2 (1 distinct)"), summary
    assert "FMU warning (x2): tank.length = 25 m" in summary[1]


def test_collected_messages_travel_and_merge():
    """A worker's messages are collected (not shown), handed back and merged into the parent."""
    rep = fmulog.REPORT
    before = len(rep)
    with fmulog.collected() as got:
        rep.record("w", 1, "", "from a worker")
    assert got == [("FMU warning", "from a worker")] and len(rep) == before
    rep.merge(fmulog.from_text(fmulog.as_text(got)))
    assert rep.counts[("FMU warning", "from a worker")] >= 1 and len(rep) == before + 1
    assert fmulog.from_text("[WARN] a, b | [WARN] c") == [("FMU warning", "a, b"), ("FMU warning", "c")]


def test_plausibility_bounds():
    refuse, flag = fmulog.plausibility(0.02, 1.0)
    assert not refuse and not flag
    refuse, flag = fmulog.plausibility(0.2, 1.0)
    assert refuse and "0.2" in refuse[0] and not flag
    refuse, flag = fmulog.plausibility(0.02, 0.3)
    assert flag and not refuse
    # the wind example: 2 lab tanks, 3.36 kg of water on the 170 kg building: plausible
    refuse, flag = fmulog.plausible_dampers([60.0, 60.0, 50.0], [9600.0, 8230.0, 6860.0], [(3, 3.36, 5.64)])
    assert not refuse and not flag, (refuse, flag)
    refuse, flag = fmulog.plausible_dampers([60.0, 60.0, 50.0], [9600.0, 8230.0, 6860.0], [(3, 336.0, 0.057)])
    assert refuse and flag


def test_building_refuses_a_unit_mistake(tmp_path, fmu_path):
    """tank.length = 25 (meant cm): 336 kg of water on a 170 kg building is refused before
    anything runs, the FMU's warning on its own line; --force runs it, and the result is
    followed by the summary that names the warning and the refusal."""
    cfg = building_file(tmp_path, UNIT_MISTAKE)
    r = run(PY, "scripts/building.py", str(cfg), "--out", str(tmp_path / "out"))
    assert r.returncode != 0
    assert "refused, an implausible configuration" in r.stderr and "water mass / structure modal mass" in r.stderr
    assert "--force" in r.stderr
    assert any(ln.startswith("FMU warning: tank.length = 25 m") for ln in r.stderr.splitlines()), r.stderr
    assert "% less" not in r.stdout, r.stdout
    r = run(PY, "scripts/building.py", str(cfg), "--out", str(tmp_path / "out"), "--force")
    assert r.returncode == 0, r.stderr
    out = r.stdout.splitlines()
    i = next(i for i, ln in enumerate(out) if ln.startswith("warnings:"))
    assert any("% less" in ln for ln in out[:i])           # the result, then the warnings
    assert any("FMU warning" in ln and "tank.length = 25 m" in ln for ln in out[i:]), r.stdout
    assert any("implausible configuration (run with --force)" in ln for ln in out[i:]), r.stdout


def test_building_misspelt_names(tmp_path, fmu_path):
    """A misspelt parameter and enumeration item, and a misspelt key: one line each with the
    closest valid names, no traceback, all of them at once."""
    cfg = building_file(tmp_path, {"tank.lenght": 0.25, "amplitude": "Trackd"})
    cfg.write_text(cfg.read_text().replace("stiffnesses =", "stifnesses ="))
    for script in ("scripts/building.py", "scripts/opensees.py"):
        args = [PY, script] + (["verify"] if "opensees" in script else []) + [str(cfg), "--out", str(tmp_path / "o")]
        r = run(*args)
        assert r.returncode != 0
        assert "Traceback" not in r.stderr, r.stderr
        assert "no variable 'tank.lenght' in the modelDescription; did you mean 'tank.length'" in r.stderr, r.stderr
        assert "amplitude has no item 'Trackd'" in r.stderr and "did you mean 'Tracked'" in r.stderr
        assert "unknown key 'stifnesses' in [building]; did you mean 'stiffnesses'?" in r.stderr
        assert "3 problems:" in r.stderr or "4 problems:" in r.stderr


def test_sweep_reports_every_error_up_front(tmp_path, fmu_path):
    """Ranges and enumerations from the modelDescription, every problem listed."""
    s = {**STUDY, "damper": {"params": {"amplitude": "Trackd", "tank.lenght": 0.25}},
         "study": {**STUDY["study"], "params": {"eta": [0.5, 2.0], "damping": ["NSDD"]}},
         "run": {**STUDY["run"], "derivatve": True}}
    p = tmp_path / "bad.toml"
    p.write_text(dump_study(s))
    r = run(PY, "scripts/sweep.py", str(p), "--serial", "--out", str(tmp_path / "o"))
    assert r.returncode != 0 and "Traceback" not in r.stderr, r.stderr
    for text in ("5 problems:", "did you mean 'derivatives'", "did you mean 'Tracked'", "did you mean 'tank.length'",
                 "eta = 0.5: outside its range 1..10", "did you mean 'NSD'"):
        assert text in r.stderr, (text, r.stderr)


def test_sweep_flags_implausible_rows_and_prints_the_best_design(tmp_path, fmu_path):
    """12 lab tanks on the 168 kg structure (12 % of its mass) and a tank tuned to 0.4 of the
    structure: the rows say so in the plausibility column, and the best design printed at the
    end is a plausible one."""
    s = {**STUDY, "study": {**STUDY["study"], "tuning": [0.4, 1.0], "tanks": [1, 12], "ground_amplitude": [2e-4],
                            "frequency": [0.9, 1.1, 3]},
         "run": {"duration": 3.0, "tail": 1.0, "step": 5e-3}}
    p = tmp_path / "small.toml"
    p.write_text(dump_study(s))
    r = run(PY, "scripts/sweep.py", str(p), "--serial", "--engine", "python", "--xtol", "0.05",
            "--out", str(tmp_path / "o"))
    assert r.returncode == 0, r.stderr
    import csv
    rows = list(csv.DictReader(open(tmp_path / "o" / "small-peaks.csv")))
    flags = {(float(x["tuning"]), int(x["tanks"])): x["plausibility"] for x in rows}
    assert flags[(1.0, 1)] == "" and "mass ratio above 0.1" in flags[(1.0, 12)]
    assert "tuning outside" in flags[(0.4, 1)]
    best = [ln for ln in r.stdout.splitlines() if ln.startswith("best design")]
    assert len(best) == 1 and "tuning 1, 1 tank(s)" in best[0] and "% less" in best[0], r.stdout
    assert "implausible configuration (flagged in the plausibility column)" in r.stdout


SCRIPTS = sorted(p.name for p in (REPO / "scripts").iterdir() if p.is_file() and os.access(p, os.X_OK)
                 or p.suffix == ".py")


@pytest.mark.parametrize("script", SCRIPTS)
def test_every_script_has_help(script, tmp_path):
    """-h and --help print usage and exit 0 without building, installing or running anything
    (and write nothing: git status is unchanged)."""
    status = run("git", "status", "--porcelain").stdout
    cmd = [PY, f"scripts/{script}"] if script.endswith(".py") else [f"scripts/{script}"]
    for flag in ("--help", "-h"):
        r = run(*cmd, flag, timeout=60)
        assert r.returncode == 0, (script, flag, r.stderr)
        assert len(r.stdout.strip().splitlines()) >= 2, (script, r.stdout)
        assert "usage" in r.stdout.lower() or f"scripts/{script}" in r.stdout, (script, r.stdout)
    assert run("git", "status", "--porcelain").stdout == status


def test_documented_writers_default_to_out():
    """The commands that regenerate tracked documents do so only on request (--docs): their
    default destination is out/, and the --quick fig25 run is not the documented one."""
    models = (REPO / "scripts" / "models.py").read_text()
    assert 'REPO / ("docs" if args.docs else "out") / "MODELS.md"' in models
    report = (REPO / "scripts" / "calibration-report").read_text()
    assert "\ndest=out/calibration\n" in report and "--docs) dest=docs" in report
    fig25 = (REPO / "scripts" / "fig25.py").read_text()
    assert 'REPO / "docs" if args.docs else Path(args.out)' in fig25
    assert "[QUICK_NOTE.format(" in fig25 and "if args.quick else [COMPARISON]" in fig25


def test_freqresp_coupled_prints_a_table(tmp_path):
    """scripts/freqresp --coupled: a readable table (and the JSON only with --json); the
    written files stay in out/ (untracked)."""
    if not (REPO / "target" / "release" / "tld-freqresp").is_file():
        pytest.skip("tld-freqresp not built (scripts/freqresp builds it on its first run)")
    status = run("git", "status", "--porcelain").stdout
    r = run("scripts/freqresp", "--coupled", "--Omega", "0.9", "--zeta", "0.01", "--from", "0.9", "--to", "1.1",
            "--points", "21")
    assert r.returncode == 0, r.stderr
    assert not r.stdout.lstrip().startswith("{") and "w/w_s" in r.stdout, r.stdout[:500]
    assert max(len(ln) for ln in r.stdout.splitlines()) < 200
    r = run("scripts/freqresp", "--coupled", "--json", "--from", "0.9", "--to", "1.1", "--points", "5")
    assert r.returncode == 0 and r.stdout.lstrip().startswith("{"), r.stdout[:300]
    assert run("git", "status", "--porcelain").stdout == status


def test_calibrate_draws_smooth_curves_and_writes_only_out():
    """scripts/calibrate (the NSD laws): the plot's curves on 81 values of Lambda, which meet the
    fit's own values at the samples' ends; nothing tracked is written."""
    if not (REPO / "target" / "release" / "tld-calibrate").is_file():
        pytest.skip("tld-calibrate not built (scripts/calibrate builds it on its first run)")
    status = run("git", "status", "--porcelain").stdout
    r = run("scripts/calibrate")
    assert r.returncode == 0, r.stderr
    assert "wrote out/calibration.png" in r.stdout and "scripts/calibrate: " in r.stdout
    import numpy as np
    from tld_fmu.calibration import read_curve, read_fit
    curve = read_curve(REPO / "out" / "calibration_curve.csv")
    _, d = read_fit(REPO / "out" / "calibration.csv")
    assert len(curve["lambda"]) == 81
    for i, j in ((0, 0), (-1, -1)):
        assert curve["lambda"][i] == pytest.approx(d["lambda"][j], rel=1e-12)
        for q in ("kappa_model", "zeta_model", "kappa_nsd", "zeta_nsd"):
            assert curve[q][i] == pytest.approx(d[q][j], rel=1e-9), q
    assert np.all(np.diff(curve["lambda"]) > 0)
    assert run("git", "status", "--porcelain").stdout == status


def test_summary_of_nothing_says_none():
    assert fmulog.Report().summary() == ["warnings: none (FMU and configuration)"]
    buf = io.StringIO()
    fmulog.Report().print_summary(buf)
    assert buf.getvalue().startswith("warnings: none")


def test_ssp_run_answers_with_units_and_the_undamped_building(tmp_path, fmu_path, building_path):
    """The SSP runner: maxima with their units, the same building without the damper beside
    them, and no libcosim warning about the Enumerations it ignores (explained in the code)."""
    from tld_fmu import ssp
    arch = ssp.write("tld_table21", tmp_path)
    r = run(PY, "-m", "tld_fmu.ssp", "run", str(arch), "--host", "libcosim", "--duration", "10")
    assert r.returncode == 0, r.stderr
    assert "max|Building.roof.x| = " in r.stdout and " m, max|Building.base_shear| = " in r.stdout, r.stdout
    line = next(ln for ln in r.stdout.splitlines() if ln.strip().startswith("max|Building.roof.x|:"))
    assert "m without" in line and "with the damper" in line and "% less" in line, line
    assert "Enumeration variable type not supported" not in r.stdout + r.stderr
