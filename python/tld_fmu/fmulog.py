"""What the project's masters tell an engineer besides their numbers: the FMU's log messages of
status Warning or worse, each on its own line (tqdm.write, on standard error: never inside a progress bar) and
summarised at the end of the run, and whether a configuration is plausible for its structure
before its result is presented as an engineering answer.

    from tld_fmu import fmulog
    fmu.instantiate(callbacks=fmulog.callbacks())      # messages reach fmulog.REPORT
    ...
    fmulog.REPORT.print_summary()

Plausibility (`plausibility`): a water mass of more than MASS_RATIO_MAX (10 %) of the structure's
modal mass is refused by the masters that run a user's structure (scripts/building.py,
scripts/opensees.py; --force runs it anyway), and a sloshing frequency outside TUNING_BAND (0.5 to
1.5 times the structure's nearest natural frequency) is flagged: such a tank is no tuned damper,
and a unit mistake (a length in cm read as metres) produces both."""
from __future__ import annotations

import contextlib
import ctypes
import sys

MASS_RATIO_MAX = 0.1
TUNING_BAND = (0.5, 1.5)

LABELS = ["OK", "Warning", "Discard", "Error", "Fatal", "Pending"]

_LOGGER = None      # the one Python logger fmpy's printf proxy calls (see callbacks)
_ROUTES: dict = {}  # componentEnvironment -> sink(instance, status, category, message)


def _route(env, instance, status, category, message):
    try:
        sink = _ROUTES.get(env or 0, None) or REPORT.record
        dec = lambda b: (b or b"").decode("utf-8", "replace")  # noqa: E731
        sink(dec(instance), int(status), dec(category), dec(message))
    except Exception:  # never let an exception unwind into the FMU
        pass


def callbacks(sink=None):
    """fmi2CallbackFunctions for fmpy's FMU2Slave.instantiate whose logger reaches
    sink(instance, status, category, message) (default: REPORT.record). Keep the returned
    structure alive as long as the instance.

    fmpy's printf-formatting proxy (its logging library) keeps ONE global Python target for every
    instance in the process, whatever structure it was installed into: a per-instance Python
    logger would dangle there once its instance is gone. So the target is one module-level router
    that lives forever and dispatches on componentEnvironment (0, also fmpy's default callbacks'
    value: the process's REPORT)."""
    from fmpy import calloc, free
    from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                           fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
    from fmpy.logging import addLoggerProxy
    global _LOGGER
    if _LOGGER is None:
        _LOGGER = fmi2CallbackLoggerTYPE(_route)
    key = 0
    if sink is not None:
        key = len(_ROUTES) + 1
        _ROUTES[key] = sink
    cb = fmi2CallbackFunctions()
    cb.logger = _LOGGER
    cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    cb.componentEnvironment = key
    addLoggerProxy(ctypes.byref(cb))
    return cb


class Report:
    """The warnings of one run of a master: the FMU's messages of status Warning or worse and
    the master's own notes (an implausible configuration), each shown once on its own line when
    it first occurs and counted; `summary` lists them at the end. A collecting report (a worker
    process's, or a master's while it runs something whose messages travel with its result)
    only keeps them for `drain`."""

    def __init__(self):
        self.collecting = False
        self.counts: dict[tuple[str, str], int] = {}
        self.pending: list[tuple[str, str]] = []   # collected since the last drain

    def record(self, instance, status, category, message):
        """An FMU log message (status OK is ignored)."""
        if status >= 1:
            self.add(f"FMU {LABELS[min(status, 5)].lower()}", message)

    def add(self, kind, message):
        key = (kind, message)
        if self.collecting:
            self.pending.append(key)
            return
        first = key not in self.counts
        self.counts[key] = self.counts.get(key, 0) + 1
        if first:
            _line(f"{kind}: {message}")

    def drain(self) -> list[tuple[str, str]]:
        """The (kind, message) collected since the last drain: a worker hands them to the
        parent's REPORT (`merge`)."""
        out, self.pending = self.pending, []
        return out

    def merge(self, items):
        for kind, message in items:
            self.add(kind, message)

    def __len__(self):
        return sum(self.counts.values())

    def summary(self) -> list[str]:
        if not self.counts:
            return ["warnings: none (FMU and configuration)"]
        lines = [f"warnings: {len(self)} ({len(self.counts)} distinct); read them before the result:"]
        for (kind, message), n in self.counts.items():
            lines.append(f"  {kind}{f' (x{n})' if n > 1 else ''}: {message}")
        return lines

    def print_summary(self, file=None):
        print("\n".join(self.summary()), file=file or sys.stdout, flush=True)


def _line(text):
    """One line on standard error that never lands inside a tqdm bar."""
    try:
        from tqdm import tqdm
        tqdm.write(text, file=sys.stderr)
    except ImportError:
        print(text, file=sys.stderr, flush=True)


REPORT = Report()


@contextlib.contextmanager
def collected():
    """Messages inside the block are collected, not shown: the list yielded holds them after
    the block (what a run hands back with its result, to be merged where the results are)."""
    prev, got = REPORT.collecting, []
    REPORT.collecting = True
    try:
        yield got
    finally:
        got.extend(REPORT.drain())
        REPORT.collecting = prev


def as_text(items) -> str:
    """Collected messages as one field (' | ' between them)."""
    return " | ".join(f"{k}: {m}" for k, m in items)


def from_text(text: str) -> list[tuple[str, str]]:
    """as_text's field (or the compiled master's '[WARN] message | ...') as (kind, message)."""
    out = []
    for part in filter(None, (p.strip() for p in (text or "").split(" | "))):
        if part.startswith("[WARN] "):
            out.append(("FMU warning", part[7:]))
        elif part.startswith("[ERROR] "):
            out.append(("FMU error", part[8:]))
        else:
            kind, _, msg = part.partition(": ")
            out.append((kind, msg) if msg else ("FMU warning", kind))
    return out


def quiet_worker():
    """A worker process's initializer: its messages are collected, not shown (the worker hands
    REPORT.drain() back with its result; the parent merges them into its own REPORT, which shows
    them outside its progress bar)."""
    REPORT.collecting = True
    REPORT.drain()


def plausibility(mass_ratio: float, tuning: float, where: str = "") -> tuple[list[str], list[str]]:
    """(refusals, flags) of a damper configuration: mass_ratio is the water mass over the
    structure's modal mass (at the dampers' floors, in the mode nearest the sloshing frequency),
    tuning the sloshing frequency over that mode's."""
    pre = f"{where}: " if where else ""
    refuse, flag = [], []
    if not mass_ratio <= MASS_RATIO_MAX:
        refuse.append(f"{pre}water mass / structure modal mass = {mass_ratio:.3g}, above {MASS_RATIO_MAX:g} "
                      f"(TLDs are 1-5 % of the modal mass): check the tank's units and count")
    lo, hi = TUNING_BAND
    if not lo <= tuning <= hi:
        flag.append(f"{pre}sloshing frequency / structure's nearest natural frequency = {tuning:.3g}, "
                    f"outside {lo:g}-{hi:g}: the tank is not tuned to the structure")
    return refuse, flag


def plausible_dampers(masses, stiffnesses, dampers) -> tuple[list[str], list[str]]:
    """plausibility of the dampers [(1-based floor, water mass [kg], omega_f [rad/s])] on a
    shear building (storey masses, stiffnesses): for each damper the mode nearest its sloshing
    frequency, and the mass ratio summed over the dampers that are nearest to the same mode,
    sum m_d phi(floor_d)^2 / (phi' M phi)."""
    import numpy as np
    from .building import Building, np_eig
    bld = Building(masses, stiffnesses, [0.01, 0.01])
    w2, vec = np_eig(bld.K, np.diag(bld.M))
    w = np.sqrt(w2)
    phi = vec / np.sqrt(np.diag(bld.M))[:, None]     # mass-normalised: phi' M phi = 1
    refuse, flag, ratio = [], [], {}
    for i, (floor, m, wf) in enumerate(dampers):
        j = int(np.argmin(np.abs(np.log(max(wf, 1e-300) / w))))
        ratio[j] = ratio.get(j, 0.0) + m * phi[floor - 1, j] ** 2
        _, f = plausibility(0.0, wf / w[j], f"damper {i + 1} (floor {floor}), mode {j + 1} at {w[j]:.4g} rad/s")
        flag += f
    for j, mu in ratio.items():
        r, _ = plausibility(mu, 1.0, f"mode {j + 1} at {w[j]:.4g} rad/s")
        refuse += r
    return refuse, flag
