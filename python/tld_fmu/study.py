"""Design studies with TLD.fmu on dask.distributed: every combination of tuning ratio x mass ratio
(number of tanks) x ground amplitude x excitation frequency of a study file is one co-simulation
of a one-mode structure with the dampers on it (tld_fmu.building's master), run as one dask
task. Each worker keeps its FMU instances and reuses them through fmi2Reset. The command line
(scripts/sweep.py runs `main`):

    .venv/bin/python scripts/sweep.py scripts/examples/study.toml            # LocalCluster, 2 workers
    .venv/bin/python scripts/sweep.py STUDY --workers 1
    .venv/bin/python scripts/sweep.py STUDY --scheduler tcp://host:8786      # an existing cluster

The FMU travels to the workers as data (scattered once); the workers of a LocalCluster import
this package from the venv, those of an existing scheduler get it uploaded (a zip), so a remote
cluster needs only numpy and fmpy installed. Writes one CSV table (a row per run) and heat maps
of the peak amplification (max over frequency of the steady structure displacement / ground
displacement) over tuning x mass ratio, one panel per amplitude.
"""
from __future__ import annotations

import argparse
import hashlib
import itertools
import math
import os
import tempfile
import threading
import time
import tomllib
import zipfile
from pathlib import Path

import numpy as np

from . import building
from .paths import FMU, REPO
COLUMNS = ["tuning", "tanks", "mass_ratio", "ground_amplitude", "frequency_ratio", "omega_s",
           "peak_displacement", "amplification"]

_local = threading.local()   # per worker thread: {digest: (unzipdir, md, pool)}


def _fmu_on_worker(fmu_bytes: bytes, digest: str):
    """The unpacked FMU and this thread's instance pool (created on first use)."""
    cache = getattr(_local, "cache", None)
    if cache is None:
        cache = _local.cache = {}
    if digest not in cache:
        from fmpy import extract, read_model_description
        d = Path(tempfile.mkdtemp(prefix="tld-sweep-"))
        fmu = d / "TLD.fmu"
        fmu.write_bytes(fmu_bytes)
        md = read_model_description(str(fmu))
        unzipdir = extract(str(fmu), str(d / "unzipped"))
        cache[digest] = (unzipdir, md, building.DamperPool(unzipdir, md))
    return cache[digest]


def probe(unzipdir, md, params, tanks):
    """omega_f, mass.liquid and mass.inactive of `tanks` tanks with these parameters."""
    d = building.Damper(unzipdir, md, 1, tanks, params, "probe")
    vr = [d.var[n].valueReference for n in ("omega_f", "mass.liquid", "mass.inactive")]
    values = d.fmu.getReal(vr)
    d.close()
    return values


def expand(study: dict, unzipdir, md) -> list[dict]:
    """The runs of a study: one dict per combination, with the structure that realises it."""
    st, sw = study["structure"], study["study"]
    params = study.get("damper", {}).get("params", {})
    f0, f1, nf = sw["frequency"]
    runs = []
    for tanks in sw["tanks"]:
        w_f, m_liquid, m_inactive = probe(unzipdir, md, params, tanks)
        for tuning, amp, r in itertools.product(sw["tuning"], sw["ground_amplitude"], np.linspace(f0, f1, int(nf))):
            w_s = w_f / tuning
            runs.append({"tuning": tuning, "tanks": tanks, "mass_ratio": m_liquid / st["mass"],
                         "ground_amplitude": amp, "frequency_ratio": float(r), "omega_s": w_s,
                         # the inactive liquid moves with the structure: K tunes M + inactive
                         "stiffness": (st["mass"] + m_inactive) * w_s ** 2})
    return runs


def run_one(fmu_bytes: bytes, digest: str, study: dict, run: dict, fresh: bool = False) -> dict:
    """One co-simulation; returns the run's row plus where it ran and how many instances its
    thread has created so far. fresh=True: a new instance instead of the pool (for checks)."""
    unzipdir, md, pool = _fmu_on_worker(fmu_bytes, digest)
    st, rn = study["structure"], study["run"]
    cfg = {"building": {"masses": [st["mass"]], "stiffnesses": [run["stiffness"]],
                        "rayleigh": [st["damping"], st["damping"]]},
           "dampers": [{"floor": 1, "tanks": run["tanks"], "params": study.get("damper", {}).get("params", {})}]}
    w, a = run["frequency_ratio"] * run["omega_s"], run["ground_amplitude"]
    s = building.simulate(cfg, unzipdir, md, building.harmonic_ground(w, a), rn["step"], rn["duration"], pool=None if fresh else pool,
                          derivatives=bool(rn.get("derivatives", False)))
    tail = s["t"] > rn["duration"] - rn["tail"]
    peak = float(np.max(np.abs(s["X"][tail, 0])))
    return _row(run, peak_displacement=peak, amplification=peak / a,
                worker=f"{os.getpid()}/{threading.get_ident()}", instances=len(pool.dampers), error="")


def _row(run: dict, **results) -> dict:
    """A table row: the run's parameters and its results."""
    return {**{k: run[k] for k in COLUMNS if k in run}, **results}


def run_study(study: dict, fmu_path: Path, client=None, progress=True) -> tuple[list[dict], float]:
    """All runs of a study, on a dask client (None: here, serially, on one pool). Returns the
    rows in study order and the wall time of the runs [s]."""
    fmu_bytes = Path(fmu_path).read_bytes()
    digest = hashlib.sha256(fmu_bytes).hexdigest()
    unzipdir, md, _ = _fmu_on_worker(fmu_bytes, digest)
    runs = expand(study, unzipdir, md)
    from tqdm import tqdm
    bar = tqdm(total=len(runs), desc="runs", disable=not progress)
    t0 = time.perf_counter()
    rows = [None] * len(runs)
    if client is None:
        for i, r in enumerate(runs):
            try:
                rows[i] = run_one(fmu_bytes, digest, study, r)
            except Exception as e:   # one failed run must not lose the others
                rows[i] = failed_row(r, e)
            bar.update()
    else:
        from distributed import as_completed
        data = client.scatter(fmu_bytes, broadcast=True, hash=False)   # a fresh key: no race with a released earlier scatter
        futures = client.map(run_one, [data] * len(runs), [digest] * len(runs), [study] * len(runs), runs,
                             pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        for f in as_completed(futures):
            i = index[f.key]
            try:
                rows[i] = f.result()
            except Exception as e:
                rows[i] = failed_row(runs[i], e)
            bar.update()
    bar.close()
    return rows, time.perf_counter() - t0


def failed_row(run: dict, error: Exception) -> dict:
    """A run that raised: its parameters, NaN results and the reason."""
    return _row(run, peak_displacement=math.nan, amplification=math.nan, worker="", instances=0,
                error=f"{type(error).__name__}: {error}".replace(",", ";").replace("\n", " "))


def connect(scheduler: str | None, workers: int):
    """A client: on an existing scheduler, or on a new LocalCluster of single-threaded worker
    processes. The scripts are uploaded so that remote workers can import them."""
    from distributed import Client, LocalCluster
    if scheduler:
        client, cluster = Client(scheduler), None
    else:
        import dask
        # The runs hold the GIL (the Python master); the worker's own periodic work (the
        # statistical profiler every 10 ms, the 20 ms tick, the system monitor) then takes it
        # away often enough to cost ~50 % on this 2-core machine. Measured: 2.0 s -> 1.46 s for
        # 10 runs that take 1.31 s in a plain process.
        with dask.config.set({"distributed.worker.profile.enabled": False,
                              "distributed.admin.tick.interval": "1s",
                              "distributed.admin.system-monitor.interval": "1s"}):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=":0")
        client = Client(cluster)
    if scheduler:
        # its workers may not have this package: a worker plugin puts it on their sys.path as a
        # zip (workers only: a scheduler started in this process keeps the installed package)
        from distributed.diagnostics.plugin import UploadFile
        with tempfile.TemporaryDirectory() as d:
            client.register_plugin(UploadFile(_package_zip(Path(d))))
    return client, cluster


def _package_zip(directory: Path) -> str:
    """This package's modules as DIRECTORY/tld_fmu.zip (importable from a zip on sys.path)."""
    here = Path(__file__).resolve().parent
    path = directory / "tld_fmu.zip"
    with zipfile.ZipFile(path, "w") as z:
        for f in sorted(here.glob("*.py")):
            z.write(f, f"tld_fmu/{f.name}")
    return str(path)


def write_table(rows: list[dict], path: Path):
    cols = COLUMNS + ["worker", "instances", "error"]
    with open(path, "w") as fh:
        fh.write(",".join(cols) + "\n")
        for r in rows:
            fh.write(",".join(repr(r[c]) if isinstance(r[c], float) else str(r[c]) for c in cols) + "\n")


def heat_maps(rows: list[dict], path: Path):
    """Peak amplification (max over frequency) over tuning x mass ratio, a panel per amplitude."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    tunings = sorted({r["tuning"] for r in rows})
    ratios = sorted({r["mass_ratio"] for r in rows})
    amps = sorted({r["ground_amplitude"] for r in rows})
    fig, axes = plt.subplots(1, len(amps), figsize=(4.5 * len(amps), 3.8), squeeze=False)
    for ax, amp in zip(axes[0], amps):
        Z = np.full((len(ratios), len(tunings)), np.nan)
        for r in rows:
            if r["ground_amplitude"] == amp:
                i, j = ratios.index(r["mass_ratio"]), tunings.index(r["tuning"])
                Z[i, j] = np.fmax(Z[i, j], r["amplification"])
        im = ax.imshow(Z, origin="lower", aspect="auto", cmap="viridis")
        ax.set_xticks(range(len(tunings)), [f"{t:.2f}" for t in tunings])
        ax.set_yticks(range(len(ratios)), [f"{100 * m:.2g} %" for m in ratios])
        for i, j in itertools.product(range(len(ratios)), range(len(tunings))):
            ax.text(j, i, f"{Z[i, j]:.0f}", ha="center", va="center", color="w", fontsize=8)
        ax.set_xlabel(r"tuning $\omega_f / \omega_s$")
        ax.set_ylabel("mass ratio")
        ax.set_title(f"ground amplitude {amp * 1e3:g} mm")
        fig.colorbar(im, ax=ax, label="peak |X| / ground amplitude")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study", nargs="?", default=str(REPO / "scripts" / "examples" / "study.toml"))
    ap.add_argument("--scheduler", help="address of an existing dask scheduler (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    ap.add_argument("--serial", action="store_true", help="no dask: run here, one instance pool")
    ap.add_argument("--fmu", default=str(FMU))
    ap.add_argument("--out", default=str(REPO / "out" / "sweep"))
    args = ap.parse_args(argv)
    study = tomllib.loads(Path(args.study).read_text())
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    client = cluster = None
    if not args.serial:
        client, cluster = connect(args.scheduler, args.workers)
    try:
        rows, wall = run_study(study, Path(args.fmu), client)
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    write_table(rows, out / "study.csv")
    heat_maps(rows, out / "study.png")
    where = "serial" if args.serial else (args.scheduler or f"LocalCluster, {args.workers} workers")
    failed = [r for r in rows if r["error"]]
    if failed:
        print(f"{len(failed)} of {len(rows)} runs failed (NaN in the table, reason in its 'error' column); "
              f"first: {failed[0]['error']}")
    print(f"{len(rows)} runs in {wall:.1f} s ({len(rows) / wall:.2f} runs/s, {where}); "
          f"{len({r['worker'] for r in rows})} worker threads, at most {max(r['instances'] for r in rows)} "
          f"FMU instance(s) each; wrote {out}/study.csv, study.png")
    return rows
