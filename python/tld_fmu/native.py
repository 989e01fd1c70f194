"""The compiled design-study master (tools' `tld-study`, tools/src/bin/study): a process that
dlopens TLD.fmu's binary and runs batches of co-simulations of tld_fmu.building's master at the
FMU's speed, talking JSON lines over its standard input and output (`tld-study --help`).

Python builds each run's structure (tld_fmu.building.structure: masses with the dampers'
inactive liquid, Rayleigh damping) and resolves the parameters' names against the
modelDescription (tld_fmu.contract); the master does the coupling, the same arithmetic in the
same order as tld_fmu.building.simulate, and returns each floor's peak |X| over the tail.

    m = Master(binary, unzipdir, md)          # starts the process, loads the FMU once
    m.run([request(...), ...])                # [{"peak": [...], "instances": n} | {"error": ...}]
"""
from __future__ import annotations

import errno
import json
import math
import subprocess
import tempfile
import time
from pathlib import Path

from . import building
from .contract import Contract

# the value references the master needs, by the names it knows them by
VARIABLES = ("base.a", "base.v", "base.x", "force", "force.mean", "mass.inactive")


def _encode(x):
    """JSON has no NaN or infinity: the master takes them as strings."""
    if isinstance(x, float) and not math.isfinite(x):
        return "NaN" if math.isnan(x) else ("Infinity" if x > 0 else "-Infinity")
    if isinstance(x, dict):
        return {k: _encode(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_encode(v) for v in x]
    return x


def request(name: str, cfg: dict, contract: Contract, inactive: list[float], w: float, amplitude: float,
            step: float, duration: float, tail: float, derivatives: bool, timing: bool = False) -> dict:
    """One run for the master: cfg as tld_fmu.building.simulate takes it (building, dampers),
    inactive the dampers' mass.inactive (the master checks the FMU reports the same), ground
    motion x_g = amplitude sin(w t). timing: the master measures its time inside fmi2DoStep
    (do_step_seconds; the clock costs some 50 ns a step, so only for benchmarks)."""
    dampers = cfg.get("dampers", [])
    bld = building.structure(cfg, [(d["floor"] - 1, m) for d, m in zip(dampers, inactive)])
    return {"name": name, "minv": bld.minv.tolist(), "c": bld.C.tolist(), "k": bld.K.tolist(),
            "dampers": [{"floor": d["floor"] - 1,
                         "params": [{"vr": vr, kind: value} for vr, kind, value in
                                    contract.typed({"tanks": d.get("tanks", 1), **d.get("params", {})})],
                         "inactive": m} for d, m in zip(dampers, inactive)],
            "ground": {"w": w, "amplitude": amplitude},
            "step": step, "duration": duration, "tail": tail, "derivatives": bool(derivatives),
            "timing": bool(timing)}


def start(args: list[str], attempts: int = 12, **popen) -> subprocess.Popen:
    """subprocess.Popen(args, **popen), tried again while the executable is "busy" (ETXTBSY).

    A binary just written (study.py writes the master next to the unpacked FMU) cannot be
    executed while any process holds it open for writing, and a process that another thread
    forks at the moment of the write holds the writer's descriptor until it executes its own
    program: a window of microseconds that a worker with two threads starting masters at once
    hits now and then. Waits 2, 4, 8, ... ms between attempts (about 4 s in all)."""
    for k in range(attempts - 1):
        try:
            return subprocess.Popen(args, **popen)
        except OSError as e:
            if e.errno != errno.ETXTBSY:
                raise
            time.sleep(0.002 * 2 ** k)
    return subprocess.Popen(args, **popen)


class MasterError(RuntimeError):
    """The master process failed as a whole (not one run)."""


class Master:
    """One tld-study process with TLD.fmu loaded."""

    def __init__(self, binary: str | Path, unzipdir: str | Path, md):
        self.binary = str(binary)
        # stderr to a file: a pipe nobody reads could fill and stall the master
        self.err = tempfile.TemporaryFile(mode="w+")
        self.proc = start([self.binary], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                          stderr=self.err, text=True, bufsize=1)
        contract = Contract(md)
        ident = md.coSimulation.modelIdentifier
        library = Path(unzipdir) / "binaries" / "linux64" / f"{ident}.so"
        reply = self._ask({"load": {"library": str(library), "guid": md.guid,
                                    "resources": (Path(unzipdir) / "resources").resolve().as_uri(),
                                    "vr": {n: contract.vr(n) for n in VARIABLES}}})
        if "loaded" not in reply:
            self.close()
            raise MasterError(f"tld-study could not load {library}: {reply.get('error', reply)}")

    def _ask(self, obj: dict) -> dict:
        if self.proc.poll() is not None:
            raise MasterError(f"tld-study ({self.binary}) has ended with status {self.proc.returncode}: "
                              f"{self._stderr()}")
        try:
            self.proc.stdin.write(json.dumps(_encode(obj)) + "\n")
            self.proc.stdin.flush()
            line = self.proc.stdout.readline()
        except (BrokenPipeError, OSError) as e:
            line = ""
            why = str(e)
        else:
            why = "no answer"
        if not line:
            code = self.proc.wait(timeout=10)
            raise MasterError(f"tld-study ({self.binary}) ended during a request ({why}, status {code}): "
                              f"{self._stderr()}")
        return json.loads(line)

    def _stderr(self) -> str:
        try:
            self.err.seek(0)
            return self.err.read().strip()[-2000:] or "(nothing on stderr)"
        except (OSError, ValueError):
            return "(stderr unreadable)"

    def run(self, requests: list[dict]) -> list[dict]:
        """Each request's result: {"peak": [per floor, NaN for null], "steps", "instances"} or
        {"error": "NAME: why"}."""
        reply = self._ask({"runs": requests})
        if "results" not in reply:
            raise MasterError(f"tld-study refused the batch: {reply.get('error', reply)}")
        out = reply["results"]
        for r in out:
            if "peak" in r:
                r["peak"] = [math.nan if p is None else p for p in r["peak"]]
        return out

    def alive(self) -> bool:
        return self.proc.poll() is None

    def close(self):
        self.err.close()
        if self.proc.poll() is None:
            self.proc.stdin.close()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
