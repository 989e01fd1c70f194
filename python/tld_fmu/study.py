"""Design studies with TLD.fmu on dask.distributed: every combination of tuning ratio x mass ratio
(number of tanks) x ground amplitude x excitation frequency of a study file, and of the FMU
parameters it varies ([study] params = {name = [values]}), is one co-simulation of a one-mode
structure with the dampers on it. The command line (scripts/sweep.py runs `main`):

    .venv/bin/python scripts/sweep.py scripts/examples/study.toml            # LocalCluster, 2 workers
    .venv/bin/python scripts/sweep.py STUDY --workers 1
    .venv/bin/python scripts/sweep.py STUDY --scheduler tcp://host:8786      # an existing cluster
    .venv/bin/python scripts/sweep.py STUDY --engine python                  # the Python master

Engines: "native" (the default) is the compiled master, tools' tld-study (tld_fmu.native): it
dlopens TLD.fmu and runs tld_fmu.building's coupling, operation for operation the same, at the
FMU's speed; the runs go to dask in batches, and each worker thread keeps one master process
(its FMU instances reused through fmi2Reset). "python" is tld_fmu.building's master, a dask task
per run, each worker keeping its FMU instances. Both give the same numbers
(tests/python/test_study_engines.py).

The FMU (and the master) travel to the workers as data (scattered once); the workers of a
LocalCluster import this package from the venv, those of an existing scheduler get it uploaded
(a zip), so a remote cluster needs only numpy and fmpy installed.

The peak over frequency of each case (varied parameters x tuning x tanks x amplitude) is refined
(tld_fmu.peaks): the frequency grid brackets the largest response and a golden-section search of
further runs, all cases in lockstep, locates it to +-xtol in w / w_s (--xtol, default 0.002).

A study file is checked first (check_study: unknown keys, impossible values, parameters the
modelDescription lacks); a run that fails is a row with NaN results and the reason, naming the
run, and loses no other.

Writes, named after the study file STUDY.toml, into --out (default out/sweep): STUDY.csv (a row
per run, the refinement runs included and marked), STUDY-peaks.csv (a row per case: the refined
peak, the grid's, and the tolerance), STUDY.png (heat maps of the refined peak amplification,
max over frequency of the steady structure displacement / ground displacement, over tuning x mass
ratio, a panel per amplitude and varied parameter, with the bare structure's value for reference)
and STUDY-best.png (the design chart: the best tuning's peak amplification against the mass
ratio, a line per amplitude and varied parameter).
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
import zipfile
from pathlib import Path

import numpy as np

from . import building, fmulog
from . import peaks as pk
from .paths import FMU, REPO
from .studyfile import COLUMNS, StudyError, check_study, dump_study, load_study  # noqa: F401 (this module's API)
from .studyplots import bare_peak_amplification, best_tuning, heat_maps  # noqa: F401

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


def axes(study: dict) -> list[str]:
    """The FMU parameters the study varies ([study] params = {NAME = [values]}), in order."""
    return list(study["study"].get("params", {}))


def variants(study: dict) -> list[dict]:
    """Every combination of the varied FMU parameters' values ([{}] if none is varied)."""
    p = study["study"].get("params", {})
    return [dict(zip(p, combo)) for combo in itertools.product(*p.values())]


def expand(study: dict, unzipdir, md) -> list[dict]:
    """The runs of a study: one dict per combination, with the structure that realises it."""
    st, sw = study["structure"], study["study"]
    params = study.get("damper", {}).get("params", {})
    f0, f1, nf = sw["frequency"]
    runs = []
    for variant in variants(study):
        for tanks in sw["tanks"]:
            w_f, m_liquid, m_inactive = probe(unzipdir, md, {**params, **variant}, tanks)
            for tuning, amp, r in itertools.product(sw["tuning"], sw["ground_amplitude"], np.linspace(f0, f1, int(nf))):
                w_s = w_f / tuning
                refuse, flag = fmulog.plausibility(m_liquid / st["mass"], tuning)
                runs.append({"index": len(runs), **variant, "params": variant, "tuning": tuning, "tanks": tanks,
                             "mass_ratio": m_liquid / st["mass"], "plausibility": _flag(refuse + flag),
                             "ground_amplitude": amp, "frequency_ratio": float(r), "omega_s": w_s,
                             # the inactive liquid moves with the structure: K tunes M + inactive
                             "stiffness": (st["mass"] + m_inactive) * w_s ** 2, "inactive": m_inactive})
    return runs


def _flag(problems: list[str]) -> str:
    """A run's plausibility column: '' or what is implausible, short and CSV-safe."""
    out = []
    for p in problems:
        if "water mass" in p:
            out.append(f"mass ratio above {fmulog.MASS_RATIO_MAX:g}")
        else:
            out.append(f"tuning outside {fmulog.TUNING_BAND[0]:g}-{fmulog.TUNING_BAND[1]:g}")
    return " & ".join(out)


def _config(study: dict, run: dict) -> tuple[dict, float, float]:
    """A run as tld_fmu.building's master takes it: (cfg, w, ground amplitude)."""
    st = study["structure"]
    cfg = {"building": {"masses": [st["mass"]], "stiffnesses": [run["stiffness"]],
                        "rayleigh": [st["damping"], st["damping"]]},
           "dampers": [{"floor": 1, "tanks": run["tanks"],
                        "params": {**study.get("damper", {}).get("params", {}), **run.get("params", {})}}]}
    return cfg, run["frequency_ratio"] * run["omega_s"], run["ground_amplitude"]


def run_one(fmu_bytes: bytes, digest: str, study: dict, run: dict, fresh: bool = False) -> dict:
    """One co-simulation by the Python master; returns the run's row plus where it ran and how
    many instances its thread has created so far. fresh=True: a new instance instead of the
    pool (for checks)."""
    unzipdir, md, pool = _fmu_on_worker(fmu_bytes, digest)
    rn = study["run"]
    cfg, w, a = _config(study, run)
    with fmulog.collected() as warned:   # they travel with the row (a worker's lines would be lost)
        s = building.simulate(cfg, unzipdir, md, building.harmonic_ground(w, a), rn["step"], rn["duration"],
                              pool=None if fresh else pool, derivatives=bool(rn.get("derivatives", False)))
    tail = s["t"] > rn["duration"] - rn["tail"]
    peak = float(np.max(np.abs(s["X"][tail, 0])))
    return _row(run, peak_displacement=peak, amplification=peak / a,
                worker=f"{os.getpid()}/{threading.get_ident()}", instances=len(pool.dampers), error="",
                fmu_warnings=fmulog.as_text(warned))


def run_name(run: dict) -> str:
    """A run as its error messages name it."""
    return (f"run {run['index']} (tuning {run['tuning']:g}, {run['tanks']} tank(s), ground amplitude "
            f"{run['ground_amplitude']:g} m, w/w_s {run['frequency_ratio']:g})")


def _master_on_worker(fmu_bytes: bytes, digest: str, master_bytes: bytes, master_digest: str):
    """This thread's compiled master (a tld-study process with the FMU loaded), started on first
    use and again if it has died; the binary is written next to the unpacked FMU."""
    unzipdir, md, _ = _fmu_on_worker(fmu_bytes, digest)
    masters = getattr(_local, "masters", None)
    if masters is None:
        masters = _local.masters = {}
    key = (digest, master_digest)
    m = masters.get(key)
    if m is None or not m.alive():
        from .native import Master
        exe = Path(unzipdir).parent / f"tld-study-{master_digest[:16]}"
        if not exe.exists():
            # a name of this thread's own: threads of one worker may write it at once
            tmp = exe.with_name(f"{exe.name}.{os.getpid()}.{threading.get_ident()}.part")
            tmp.write_bytes(master_bytes)
            tmp.chmod(0o755)
            tmp.replace(exe)
        m = masters[key] = Master(exe, unzipdir, md)
    return m, md


def run_batch(fmu_bytes: bytes, digest: str, master_bytes: bytes, master_digest: str, study: dict,
              runs: list[dict]) -> list[dict]:
    """Runs by the compiled master, one request for the batch; a row per run (a failed run's
    row carries its error)."""
    from .contract import Contract
    from .native import request
    m, md = _master_on_worker(fmu_bytes, digest, master_bytes, master_digest)
    rn = study["run"]
    contract = Contract(md)
    reqs = []
    for r in runs:
        cfg, w, a = _config(study, r)
        reqs.append(request(run_name(r), cfg, contract, [r["inactive"]], w, a, rn["step"], rn["duration"],
                            rn["tail"], bool(rn.get("derivatives", False))))
    where = f"{os.getpid()}/{threading.get_ident()}"
    rows = []
    for r, got in zip(runs, m.run(reqs)):
        if "error" in got:
            rows.append(failed_row(r, RuntimeError(got["error"])))
        else:
            peak = got["peak"][0]
            rows.append(_row(r, peak_displacement=peak, amplification=peak / r["ground_amplitude"],
                             worker=where, instances=got["instances"], error="",
                             fmu_warnings=fmulog.as_text(fmulog.from_text(got.get("warnings", "")))))
    return rows


ENGINES = ("native", "python")


def master_binary() -> Path:
    """The compiled master: $TLD_STUDY_MASTER, else tools' tld-study built (release) by cargo."""
    from .paths import cargo_executable
    env = os.environ.get("TLD_STUDY_MASTER")
    return Path(env) if env else cargo_executable("tld-study", release=True)


class Executor:
    """Runs lists of runs of one study with one engine, here (client None) or on a dask client:
    the python engine a task per run (the Python master), the native engine a task per batch of
    runs (the compiled master, one per worker thread). The FMU (and the master) travel to the
    workers as data, once."""

    def __init__(self, study: dict, fmu_path: Path, client=None, engine: str = "native"):
        if engine not in ENGINES:
            raise ValueError(f"engine {engine!r}: one of {', '.join(ENGINES)}")
        self.study, self.client, self.engine = study, client, engine
        self.fmu_bytes = Path(fmu_path).read_bytes()
        self.digest = hashlib.sha256(self.fmu_bytes).hexdigest()
        self.unzipdir, self.md, _ = _fmu_on_worker(self.fmu_bytes, self.digest)
        if engine == "native":
            self.master_bytes = master_binary().read_bytes()
            self.master_digest = hashlib.sha256(self.master_bytes).hexdigest()
        self.data = self.master_data = None
        if client is not None:
            # fresh keys: no race with a released earlier scatter
            self.data = client.scatter(self.fmu_bytes, broadcast=True, hash=False)
            if engine == "native":
                self.master_data = client.scatter(self.master_bytes, broadcast=True, hash=False)

    def batch_size(self, n: int) -> int:
        """Runs per task: about 8 tasks per worker thread (load balance at the end, progress),
        at most 64 runs (the task overhead is then < 1 %)."""
        threads = sum(self.client.nthreads().values()) if self.client is not None else 1
        return max(1, min(64, math.ceil(n / (8 * threads))))

    def run(self, runs: list[dict], bar=None) -> list[dict]:
        """The runs' rows, in their order; a run that failed is a row with NaN results and the
        reason (the others are not lost)."""
        rows: list = [None] * len(runs)
        if self.engine == "python":
            chunks = [[i] for i in range(len(runs))]
        else:
            b = self.batch_size(len(runs))
            chunks = [list(range(i, min(i + b, len(runs)))) for i in range(0, len(runs), b)]

        def done(idx, result=None, error=None):
            for j, i in enumerate(idx):
                rows[i] = result[j] if error is None else failed_row(runs[i], error)
            if bar is not None:
                bar.update(len(idx))

        if self.client is None:
            for idx in chunks:
                try:
                    done(idx, self._call(self.fmu_bytes, self.master_bytes if self.engine == "native" else None,
                                         [runs[i] for i in idx]))
                except Exception as e:   # one failed run (or batch) must not lose the others
                    done(idx, error=e)
            return rows
        from distributed import as_completed
        if self.engine == "python":
            futures = self.client.map(run_one, [self.data] * len(runs), [self.digest] * len(runs),
                                      [self.study] * len(runs), runs, pure=False)
        else:
            futures = self.client.map(run_batch, [self.data] * len(chunks), [self.digest] * len(chunks),
                                      [self.master_data] * len(chunks), [self.master_digest] * len(chunks),
                                      [self.study] * len(chunks), [[runs[i] for i in idx] for idx in chunks],
                                      pure=False)
        index = {f.key: idx for f, idx in zip(futures, chunks)}
        for f in as_completed(futures):
            idx = index[f.key]
            try:
                got = f.result()
                done(idx, [got] if self.engine == "python" else got)
            except Exception as e:
                done(idx, error=e)
        return rows

    def _call(self, fmu_bytes, master_bytes, runs):
        if self.engine == "python":
            return [run_one(fmu_bytes, self.digest, self.study, runs[0])]
        return run_batch(fmu_bytes, self.digest, master_bytes, self.master_digest, self.study, runs)


def _row(run: dict, **results) -> dict:
    """A table row: the run's parameters and its results."""
    return {**run.get("params", {}), **{k: run[k] for k in COLUMNS if k in run}, **results}


def run_study(study: dict, fmu_path: Path, client=None, progress=True, engine: str = "native",
              executor: Executor | None = None) -> tuple[list[dict], float]:
    """All runs of a study, on a dask client (None: here, serially), by the compiled master
    (engine "native") or the Python one ("python"). Returns the rows in study order and the
    wall time of the runs [s]."""
    ex = executor or Executor(study, fmu_path, client, engine)
    runs = expand(study, ex.unzipdir, ex.md)
    from tqdm import tqdm
    bar = tqdm(total=len(runs), desc=f"runs ({ex.engine} master)", disable=None if progress else True)
    t0 = time.perf_counter()
    rows = ex.run(runs, bar)
    bar.close()
    return rows, time.perf_counter() - t0


def failed_row(run: dict, error: Exception) -> dict:
    """A run that raised: its parameters, NaN results and the reason, which names the run
    (whichever engine, and whether the run or its whole batch failed)."""
    text, name = str(error), run_name(run) if "index" in run else ""
    if name and text.startswith(name + ": "):
        text = text[len(name) + 2:]
    msg = f"{name + ': ' if name else ''}{type(error).__name__}: {text}"
    return _row(run, peak_displacement=math.nan, amplification=math.nan, worker="", instances=0,
                error=msg.replace(",", ";").replace("\n", " "), fmu_warnings="")


def connect(scheduler: str | None, workers: int):
    """A client: on an existing scheduler, or on a new LocalCluster of single-threaded worker
    processes. The scripts are uploaded so that remote workers can import them."""
    import logging
    import sys
    if not sys.stderr.isatty():
        # a log file gets the results, not the cluster's INFO lines (its workers inherit this)
        os.environ["DASK_LOGGING__DISTRIBUTED"] = "warning"
        logging.getLogger("distributed").setLevel(logging.WARNING)
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


def write_table(rows: list[dict], path: Path, axes: list[str] = ()):
    """A row per run; axes: the varied FMU parameters' columns (first)."""
    cols = list(axes) + COLUMNS + ["worker", "instances", "error", "fmu_warnings"]
    if any("refinement" in r for r in rows):
        cols.append("refinement")
        rows = [{"refinement": 0, **r} for r in rows]
    with open(path, "w") as fh:
        fh.write(",".join(cols) + "\n")
        for r in rows:
            fh.write(",".join(repr(r[c]) if isinstance(r[c], float) else str(r[c]).replace(",", ";")
                              for c in cols) + "\n")


def _case(r: dict) -> tuple:
    """The case of a run (what its peak over frequency belongs to)."""
    return (tuple(r.get("params", {}).items()), r["tuning"], r["tanks"], r["ground_amplitude"])


def refine_study(study: dict, fmu_path: Path, rows: list[dict], client=None, xtol: float = 2e-3,
                 progress=True, engine: str = "native", executor: Executor | None = None
                 ) -> tuple[list[dict], list[dict]]:
    """The peak over frequency of every case of a study (tuning x tanks x amplitude), refined from
    the grid runs `rows` (run_study's) by golden-section search to xtol in w / w_s; the searches of
    all cases advance in lockstep, one round of runs at a time (dask tasks on a client, else
    serially). Returns (peaks: a row per case, the refinement runs' rows, numbered on from the
    grid's). A case whose grid has a failed run is not refined (its peak row says so)."""
    ex = executor or Executor(study, fmu_path, client, engine)
    runs = expand(study, ex.unzipdir, ex.md)
    cases: dict[tuple, list[int]] = {}
    for i, r in enumerate(runs):
        cases.setdefault(_case(r), []).append(i)
    curves = {c: ([runs[i]["frequency_ratio"] for i in idx], [rows[i]["amplification"] for i in idx])
              for c, idx in cases.items() if not any(math.isnan(rows[i]["amplification"]) for i in idx)}
    from tqdm import tqdm
    bar = tqdm(desc=f"peak refinement runs ({ex.engine} master)", disable=None if progress else True)
    extra: list[dict] = []

    def evaluate(batch):
        todo = [{**runs[cases[c][0]], "frequency_ratio": float(x), "index": len(runs) + len(extra) + j}
                for j, (c, x) in enumerate(batch)]
        got = ex.run(todo, bar)
        for g in got:
            g["refinement"] = 1
        extra.extend(got)
        return [g["amplification"] for g in got]

    # every grid maximum within half of the largest: a tuned damper's two peaks, either of which
    # may turn out the higher once refined
    found = pk.refine_curves(curves, evaluate, xtol, every=True, rel=0.5)
    bar.close()
    out = []
    for c, idx in cases.items():
        first = rows[idx[0]]
        base = {**runs[idx[0]]["params"],
                **{k: first[k] for k in ("tuning", "tanks", "mass_ratio", "ground_amplitude", "plausibility")}}
        if c not in found:
            out.append({**base, "peak_frequency_ratio": math.nan, "peak_amplification": math.nan, "xtol": xtol,
                        "grid_frequency_ratio": math.nan, "grid_amplification": math.nan, "bounded": False,
                        "refinement_runs": 0, "note": "a grid run failed: not refined"})
            continue
        p = pk.highest(found[c])
        out.append({**base, "peak_frequency_ratio": p.x, "peak_amplification": p.y, "xtol": xtol,
                    "grid_frequency_ratio": p.grid_x, "grid_amplification": p.grid_y, "bounded": p.bounded,
                    "refinement_runs": sum(len(q.points) for q in found[c]),
                    "note": "" if p.bounded else "peak at the edge of the frequency range: widen it"})
    return out, extra


PEAK_COLUMNS = ["tuning", "tanks", "mass_ratio", "ground_amplitude", "peak_frequency_ratio", "peak_amplification",
                "xtol", "grid_frequency_ratio", "grid_amplification", "bounded", "refinement_runs", "note", "plausibility"]


def write_peaks(peaks: list[dict], path: Path, axes: list[str] = ()):
    """A row per case; axes: the varied FMU parameters' columns (first)."""
    cols = list(axes) + PEAK_COLUMNS
    with open(path, "w") as fh:
        fh.write(",".join(cols) + "\n")
        for r in peaks:
            fh.write(",".join(repr(r[c]) if isinstance(r[c], float) else str(r[c]) for c in cols) + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study", nargs="?", default=str(REPO / "scripts" / "examples" / "study.toml"))
    ap.add_argument("--scheduler", help="address of an existing dask scheduler (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    ap.add_argument("--serial", action="store_true", help="no dask: run here, one instance pool")
    ap.add_argument("--fmu", default=str(FMU))
    ap.add_argument("--out", default=str(REPO / "out" / "sweep"),
                    help="directory for STUDY.csv, STUDY-peaks.csv and STUDY.png (default out/sweep)")
    ap.add_argument("--xtol", type=float, default=2e-3,
                    help="tolerance of the refined peak frequencies, in w / w_s (default 0.002)")
    ap.add_argument("--engine", choices=ENGINES, default="native",
                    help="native (default): the compiled master, tools' tld-study, batches of runs per task; "
                         "python: tld_fmu.building's master, a task per run")
    args = ap.parse_args(argv)
    from .contract import Contract
    try:
        study = load_study(Path(args.study), Contract(args.fmu))
    except StudyError as e:
        raise SystemExit(f"scripts/sweep.py: {e}") from None
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    client = cluster = None
    if not args.serial:
        client, cluster = connect(args.scheduler, args.workers)
    try:
        ex = Executor(study, Path(args.fmu), client, args.engine)
        rows, wall = run_study(study, Path(args.fmu), executor=ex)
        t0 = time.perf_counter()
        peaks, extra = refine_study(study, Path(args.fmu), rows, xtol=args.xtol, executor=ex)
        wall_refine = time.perf_counter() - t0
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    name = Path(args.study).stem
    table, peaks_file, png = out / f"{name}.csv", out / f"{name}-peaks.csv", out / f"{name}.png"
    write_table(rows + extra, table, axes(study))
    write_peaks(peaks, peaks_file, axes(study))
    heat_maps(peaks, png, study["structure"].get("damping"), name, axes(study))
    chart = out / f"{name}-best.png"
    best_tuning(peaks, chart, study["structure"].get("damping"), name, axes(study))
    where = "serial" if args.serial else (args.scheduler or f"LocalCluster, {args.workers} workers")
    for r in rows + extra:
        fmulog.REPORT.merge(fmulog.from_text(r.get("fmu_warnings", "")))
    flagged = [p for p in peaks if p["plausibility"]]
    for p in flagged:
        fmulog.REPORT.add("implausible configuration (flagged in the plausibility column)",
                          f"{p['tanks']} tank(s) at tuning {p['tuning']:g}: {p['plausibility']}")
    failed = [r for r in rows if r["error"]]
    if failed:
        print(f"{len(failed)} of {len(rows)} runs failed (NaN in the table, reason in its 'error' column); "
              f"first: {failed[0]['error']}")
    print(f"{len(rows)} runs in {wall:.1f} s ({len(rows) / wall:.2f} runs/s, {where}, {args.engine} master); "
          f"{len({r['worker'] for r in rows})} worker threads, at most {max(r['instances'] for r in rows)} "
          f"FMU instance(s) each; then {len(extra)} refinement runs in {wall_refine:.1f} s "
          f"(peaks to +-{args.xtol:g} w_s)")
    print(f"wrote {table}, {peaks_file}, {png}, {chart}")
    for line in best_designs(peaks, study["structure"]["damping"], axes(study)):
        print(line)
    fmulog.REPORT.print_summary()
    return rows


def best_designs(peaks: list[dict], zeta: float, axes: list[str] = ()) -> list[str]:
    """The engineering answer of a study: per ground amplitude (and combination of the varied
    FMU parameters), the plausible case with the lowest refined peak amplification, against the
    bare structure's (closed form)."""
    bare = bare_peak_amplification(zeta)
    groups: dict[tuple, list[dict]] = {}
    for p in peaks:
        groups.setdefault((p["ground_amplitude"], *(p[a] for a in axes)), []).append(p)
    lines = []
    for key, ps in groups.items():
        ok = [p for p in ps if not p["plausibility"] and not math.isnan(p["peak_amplification"])]
        varied = "".join(f", {a} = {v}" for a, v in zip(axes, key[1:]))
        if not ok:
            lines.append(f"best design at ground amplitude {key[0]:g} m{varied}: none (every case failed or was flagged)")
            continue
        b = min(ok, key=lambda p: p["peak_amplification"])
        lines.append(f"best design at ground amplitude {key[0]:g} m{varied}: tuning {b['tuning']:g}, {b['tanks']} tank(s) "
                     f"(mass ratio {b['mass_ratio']:.3g}): peak |X|/x_g {b['peak_amplification']:.4g} at w/w_s "
                     f"{b['peak_frequency_ratio']:.4f}, against {bare:.4g} for the bare structure "
                     f"({100 * (1 - b['peak_amplification'] / bare):.1f} % less)"
                     + ("" if b["bounded"] else " [peak at the edge of the frequency range]"))
    return lines
