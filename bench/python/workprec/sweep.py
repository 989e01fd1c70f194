"""The design-study throughput (issue: "runs per second for 1 and 2 workers"): scripts/sweep.py's
study machinery on a fixed small study, serially in this process and on LocalClusters of 1 and
2 single-threaded worker processes; the clusters are started before the clock runs."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np


# A fixed small study: 2 tunings x 2 tank counts x 10 frequency ratios from 0.8 to 1.2 (3 with
# --quick), one ground amplitude.
SWEEP_STUDY = {
    "structure": {"mass": 168.0, "damping": 0.0032},
    "damper": {"params": {"amplitude": "Tracked"}},
    "study": {"tuning": [0.95, 1.05], "tanks": [1, 2], "ground_amplitude": [1e-4], "frequency": [0.8, 1.2, 10]},
    "run": {"duration": 20.0, "tail": 5.0, "step": 5e-3},
}


def sweep_throughput(fmu: Path, quick: bool, repeats: int = 3):
    """[(label, runs, median wall [s], runs/s)] for serial, 1 and 2 workers, and the steps per
    run; each timed `repeats` times on the same client (after the first, the workers' FMU
    instances are warm)."""
    from tld_fmu import study as sweep
    study = json.loads(json.dumps(SWEEP_STUDY))
    if quick:
        study["study"]["frequency"][2], study["run"]["duration"], repeats = 3, 4.0, 1
    out = []
    for label, workers in (("serial (this process, no dask)", 0), ("LocalCluster, 1 worker", 1),
                           ("LocalCluster, 2 workers", 2)):
        client = cluster = None
        if workers:
            client, cluster = sweep.connect(None, workers)
        try:
            walls = []
            for _ in range(repeats):
                rows, wall = sweep.run_study(study, fmu, client, progress=False)
                walls.append(wall)
        finally:
            if client is not None:
                client.close()
                cluster.close()
        w = float(np.median(walls))
        out.append((label, len(rows), w, len(rows) / w))
    steps = int(round(study["run"]["duration"] / study["run"]["step"]))
    return out, steps, repeats


def sweep_section(result) -> list[str]:
    rows, steps, repeats = result
    base = rows[0][3]
    L = ["## Design-study throughput (scripts/sweep.py on dask.distributed)", "",
         f"A fixed study of {rows[0][1]} runs (one-mode Table 2.1 structure + TLD.fmu, {steps} communication "
         "steps each through the Python master of scripts/building.py, FMU instances reused through "
         f"fmi2Reset), median wall time of {repeats} repetitions; cluster start-up not included. A run's "
         "cost is mostly the Python master (~30 µs per step), not the FMU.", "",
         "| where | runs | wall [s] | runs/s | vs serial |", "|---|---:|---:|---:|---:|"]
    for label, n, w, rps in rows:
        L.append(f"| {label} | {n} | {w:.2f} | {rps:.2f} | {rps / base:.2f}× |")
    L.append("")
    return L
