"""scripts/sweep.py (tld_fmu.study): design studies on dask.distributed, FMU instances reused through fmi2Reset.

The distributed runs must give exactly the numbers of serial runs on fresh instances (reuse
through fmi2Reset and the trip through dask change nothing), on a LocalCluster started by the
script and on an existing scheduler given by address."""
from pathlib import Path

import numpy as np
import pytest

from tld_fmu import study as sweep

pytest.importorskip("distributed")   # pinned in scripts/requirements.txt; here for clarity only

STUDY = {
    "structure": {"mass": 168.0, "damping": 0.0032},
    "damper": {"params": {"amplitude": "Tracked"}},
    # two tank counts: a pooled instance is reset from 1 to 2 tanks and back between runs
    "study": {"tuning": [0.95, 1.05], "tanks": [1, 2], "ground_amplitude": [1e-4], "frequency": [0.9, 1.1, 3]},
    "run": {"duration": 8.0, "tail": 4.0, "step": 5e-3},
}
VALUES = ["tuning", "tanks", "mass_ratio", "ground_amplitude", "frequency_ratio", "peak_displacement"]


def fresh_rows(fmu_path):
    """The reference: every run serially, on a new FMU instance each."""
    data = Path(fmu_path).read_bytes()
    digest = sweep.hashlib.sha256(data).hexdigest()
    unzipdir, md, _ = sweep._fmu_on_worker(data, digest)
    return [sweep.run_one(data, digest, STUDY, r, fresh=True) for r in sweep.expand(STUDY, unzipdir, md)]


def assert_same(rows, ref):
    assert len(rows) == len(ref) == 12
    for r, q in zip(rows, ref):
        for k in VALUES:
            assert r[k] == q[k], (k, r, q)


@pytest.fixture(scope="module")
def reference(fmu_path):
    return fresh_rows(fmu_path)


def test_local_cluster_matches_fresh_serial_runs_and_reuses_instances(fmu_path, reference):
    client, cluster = sweep.connect(None, 2)
    try:
        rows, wall = sweep.run_study(STUDY, fmu_path, client, progress=False)
    finally:
        client.close()
        cluster.close()
    assert_same(rows, reference)
    workers = {r["worker"] for r in rows}
    runs_per_worker = [sum(r["worker"] == w for r in rows) for w in workers]
    print(f"\n{len(rows)} runs on {len(workers)} workers {runs_per_worker} in {wall:.2f} s")
    # one damper per run: each worker made one instance, however many runs it did
    assert max(r["instances"] for r in rows) == 1
    assert max(runs_per_worker) > 1
    # the study says something: more tanks, lower resonant amplification at tuning 0.95
    at = lambda tanks: max(r["amplification"] for r in rows if r["tanks"] == tanks and r["tuning"] == 0.95)  # noqa: E731
    assert at(2) < 0.8 * at(1)


def test_existing_scheduler_by_address_writes_table_and_heat_maps(fmu_path, reference, tmp_path):
    import tomllib  # noqa: F401  (the study goes through a TOML file, as a user gives it)
    from distributed import LocalCluster
    study_file = tmp_path / "study.toml"
    study_file.write_text(toml(STUDY))
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=True, dashboard_address=":0") as cluster:
        rows = sweep.main([str(study_file), "--scheduler", cluster.scheduler_address,
                           "--fmu", str(fmu_path), "--out", str(tmp_path / "out"), "--xtol", "0.01"])
    assert_same(rows, reference)
    table = np.genfromtxt(tmp_path / "out" / "study.csv", delimiter=",", names=True, dtype=None, encoding=None)
    grid = table[table["refinement"] == 0]
    assert len(grid) == 12
    assert np.array_equal(grid["peak_displacement"], [r["peak_displacement"] for r in reference])
    assert (tmp_path / "out" / "study.png").stat().st_size > 10_000
    assert_peaks_refined(table, tmp_path / "out" / "study-peaks.csv", 0.01)


def assert_peaks_refined(table, peaks_file, xtol):
    """Each case's reported peak is the best of its grid and refinement runs, at least the grid's,
    and the refinement ran where the grid brackets a maximum."""
    peaks = np.genfromtxt(peaks_file, delimiter=",", names=True, dtype=None, encoding=None)
    assert len(peaks) == 4
    for p in peaks:
        case = (table["tuning"] == p["tuning"]) & (table["tanks"] == p["tanks"]) \
            & (table["ground_amplitude"] == p["ground_amplitude"])
        assert p["peak_amplification"] == table["amplification"][case].max()
        assert p["peak_amplification"] >= p["grid_amplification"] and p["xtol"] == xtol
        if p["bounded"]:
            assert p["refinement_runs"] >= 3 and abs(p["peak_frequency_ratio"] - p["grid_frequency_ratio"]) <= 0.1
        else:
            assert "edge" in p["note"]
    assert any(peaks["bounded"])


def test_serial_mode_reuses_one_instance(fmu_path, reference, tmp_path):
    study_file = tmp_path / "study.toml"
    study_file.write_text(toml(STUDY))
    rows = sweep.main([str(study_file), "--serial", "--fmu", str(fmu_path), "--out", str(tmp_path), "--xtol", "0.01"])
    assert_same(rows, reference)
    assert len({r["worker"] for r in rows}) == 1 and max(r["instances"] for r in rows) == 1


def test_outputs_are_named_after_the_study_file(fmu_path, tmp_path):
    """Two studies in one output directory do not overwrite each other's results."""
    small = {**STUDY, "study": {**STUDY["study"], "tuning": [1.0], "tanks": [1]}}
    for name in ("tall_building", "small_tank"):
        (tmp_path / f"{name}.toml").write_text(toml(small))
        sweep.main([str(tmp_path / f"{name}.toml"), "--serial", "--fmu", str(fmu_path), "--out",
                    str(tmp_path / "out"), "--xtol", "0.02"])
    written = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert written == ["small_tank-best.png", "small_tank-peaks.csv", "small_tank.csv", "small_tank.png",
                       "tall_building-best.png", "tall_building-peaks.csv", "tall_building.csv",
                       "tall_building.png"]


toml = sweep.dump_study


@pytest.mark.parametrize("where", ["serial", "dask"])
def test_a_failed_run_is_reported_and_loses_nothing(fmu_path, reference, where):
    """A run the FMU refuses (here a NaN ground amplitude: base.a = NaN) becomes a row with NaN
    results and the reason; every other run is still there, with the numbers it has alone."""
    study = {**STUDY, "study": {**STUDY["study"], "ground_amplitude": [1e-4, float("nan")]}}
    client = cluster = None
    if where == "dask":
        client, cluster = sweep.connect(None, 1)
    try:
        rows, _ = sweep.run_study(study, fmu_path, client, progress=False)
    finally:
        if client is not None:
            client.close()
            cluster.close()
    failed = [r for r in rows if r["error"]]
    good = [r for r in rows if not r["error"]]
    assert len(rows) == 24 and len(failed) == 12 and len(good) == 12
    assert all(np.isnan(r["peak_displacement"]) and np.isnan(r["ground_amplitude"]) for r in failed)
    assert all("refused" in r["error"] for r in failed), failed[0]["error"]
    assert_same(good, reference)
