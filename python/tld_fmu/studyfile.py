"""Study files for tld_fmu.study (scripts/sweep.py) and building files (scripts/building.py,
scripts/opensees.py): what a TOML may hold, checked before anything runs (check_study, load_study: unknown sections and keys, missing and impossible
values, FMU parameters the modelDescription lacks, all named at once), and a study dict written
back as TOML (dump_study)."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

from .contract import closest

# the columns of a study's table that come from its runs (tld_fmu.study)
COLUMNS = ["tuning", "tanks", "mass_ratio", "ground_amplitude", "frequency_ratio", "omega_s",
           "peak_displacement", "amplification", "plausibility"]


class StudyError(ValueError):
    """A study file that cannot be run as written."""


# the keys a study file may have, and what each must be
_SCHEMA = {
    "structure": {"mass": "modal mass [kg], > 0", "damping": "damping ratio, 0 <= zeta < 1"},
    "damper": {"params": "FMU parameters {name = value}"},
    "study": {"tuning": "omega_f / omega_s, a list of numbers > 0",
              "tanks": "a list of whole numbers >= 1",
              "ground_amplitude": "a list of amplitudes [m] > 0",
              "frequency": "[from, to, points] in omega / omega_s, 0 < from <= to, points >= 1",
              "params": "FMU parameters varied: {name = [values]}"},
    "run": {"duration": "s per run, > 0", "tail": "s, 0 < tail <= duration",
            "step": "communication step [s], 0 < step <= duration",
            "derivatives": "true or false"},
}
_REQUIRED = {"structure": ("mass", "damping"), "study": ("tuning", "tanks", "ground_amplitude", "frequency"),
             "run": ("duration", "tail", "step")}


def check_study(study: dict, contract) -> None:
    """Raise StudyError listing everything wrong with a study (unknown keys, missing ones,
    impossible values, FMU parameters the modelDescription does not have)."""
    errs = []

    def num(x, ok=lambda v: True) -> bool:
        return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and ok(x)

    for sec, table in study.items():
        if sec not in _SCHEMA:
            errs.append(f"unknown section [{sec}]{closest(sec, _SCHEMA)} (known: {', '.join(_SCHEMA)})")
        elif not isinstance(table, dict):
            errs.append(f"[{sec}] must be a table")
        else:
            errs += [f"unknown key {k!r} in [{sec}]{closest(k, _SCHEMA[sec])} (known: {', '.join(_SCHEMA[sec])})"
                     for k in table if k not in _SCHEMA[sec]]
    missing = [f"[{sec}] {k} is missing: {_SCHEMA[sec][k]}" for sec, keys in _REQUIRED.items() for k in keys
               if not isinstance(study.get(sec, {}), dict) or k not in study.get(sec, {})]
    if missing or any(not isinstance(t, dict) for t in study.values()):
        raise StudyError(_listed(errs + missing))
    st, sw, rn = study["structure"], study["study"], study["run"]

    def want(ok, sec, key):
        if not ok:
            errs.append(f"[{sec}] {key} = {study[sec][key]!r}: need {_SCHEMA[sec][key]}")

    want(num(st["mass"], lambda v: v > 0), "structure", "mass")
    want(num(st["damping"], lambda v: 0 <= v < 1), "structure", "damping")
    for key, ok in (("tuning", lambda v: num(v, lambda x: x > 0)),
                    ("tanks", lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 1),
                    ("ground_amplitude", lambda v: num(v, lambda x: x > 0))):
        want(isinstance(sw[key], list) and sw[key] and all(ok(v) for v in sw[key]), "study", key)
    f = sw["frequency"]
    want(isinstance(f, list) and len(f) == 3 and num(f[0], lambda v: v > 0) and num(f[1], lambda v: v >= f[0])
         and isinstance(f[2], int) and f[2] >= 1, "study", "frequency")
    want(num(rn["duration"], lambda v: v > 0), "run", "duration")
    if not errs:
        want(num(rn["tail"], lambda v: 0 < v <= rn["duration"]), "run", "tail")
        want(num(rn["step"], lambda v: 0 < v <= rn["duration"]), "run", "step")
    want(isinstance(rn.get("derivatives", False), bool), "run", "derivatives") if "derivatives" in rn else None

    def param(name, value, where):
        why = contract.check(name, value)
        if why:
            errs.append(f"{where}: {why}")

    fixed = study.get("damper", {}).get("params", {})
    if not isinstance(fixed, dict):
        errs.append("[damper] params must be a table {name = value}")
        fixed = {}
    for name, value in fixed.items():
        param(name, value, "[damper] params")
    varied = sw.get("params", {})
    if not isinstance(varied, dict):
        errs.append("[study] params must be a table {name = [values]}")
        varied = {}
    for name, values in varied.items():
        if name in COLUMNS or name == "tanks":
            errs.append(f"[study] params: {name} is a column of the study; vary it with its own key")
        elif not isinstance(values, list) or not values:
            errs.append(f"[study] params.{name} = {values!r}: need a non-empty list of values")
        else:
            for value in values:
                param(name, value, f"[study] params.{name}")
    if errs:
        raise StudyError(_listed(errs))


def _listed(errs: list[str]) -> str:
    """Every problem, one per line."""
    return f"{len(errs)} problem{'s' if len(errs) > 1 else ''}:\n" + "\n".join(f"  - {e}" for e in errs)


def dump_study(d: dict) -> str:
    """A study dict as a TOML file (tables of scalars, lists and inline tables)."""
    def value(v):
        if isinstance(v, dict):
            return "{ " + ", ".join(f'"{k}" = {value(x)}' for k, x in v.items()) + " }"
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, float) and not math.isfinite(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        return repr(v)
    return "".join(f"[{name}]\n" + "".join(f"{k} = {value(v)}\n" for k, v in table.items())
                   for name, table in d.items())


def load_study(path: Path, contract) -> dict:
    """A study file, read and checked (StudyError names what is wrong)."""
    return _load(path, check_study, contract)


def _load(path: Path, check, contract) -> dict:
    try:
        cfg = tomllib.loads(Path(path).read_text())
    except tomllib.TOMLDecodeError as e:
        raise StudyError(f"{path}: not valid TOML: {e}") from None
    except OSError as e:
        raise StudyError(f"{path}: {e.strerror}") from None
    try:
        check(cfg, contract)
    except StudyError as e:
        raise StudyError(f"{path}: {e}") from None
    return cfg


# the keys a building file may have (scripts/building.py, scripts/opensees.py)
_BUILDING = {
    "building": ("masses", "stiffnesses", "rayleigh"),
    "dampers": ("floor", "tanks", "params"),
    "load": ("kind", "ground_amplitude", "from", "to", "points", "duration", "record", "force_rms", "band",
             "corner", "coherence", "seed"),
    "coupling": ("step", "derivatives"),
}


def check_building(cfg: dict, contract) -> None:
    """Raise StudyError listing everything wrong with a building file that can be told before
    a run: unknown sections and keys (with the closest known ones), floors off the building,
    and damper parameters the modelDescription does not have or does not allow (unknown name,
    Enumeration item, range)."""
    errs = []
    for sec, table in cfg.items():
        if sec not in _BUILDING:
            errs.append(f"unknown section [{sec}]{closest(sec, _BUILDING)} (known: {', '.join(_BUILDING)})")
            continue
        for i, t in enumerate(table if sec == "dampers" and isinstance(table, list) else [table]):
            where = f"[[dampers]] {i + 1}" if sec == "dampers" else f"[{sec}]"
            if not isinstance(t, dict):
                errs.append(f"{where} must be a table")
                continue
            errs += [f"unknown key {k!r} in {where}{closest(k, _BUILDING[sec])} (known: {', '.join(_BUILDING[sec])})"
                     for k in t if k not in _BUILDING[sec]]
    b = cfg.get("building", {})
    errs += [f"[building] {k} is missing" for k in _BUILDING["building"] if isinstance(b, dict) and k not in b]
    n = len(b.get("masses", [])) if isinstance(b, dict) else 0
    for i, d in enumerate(cfg.get("dampers", []) if isinstance(cfg.get("dampers", []), list) else []):
        if not isinstance(d, dict):
            continue
        floor = d.get("floor")
        if not (isinstance(floor, int) and 1 <= floor <= max(n, 1)):
            errs.append(f"[[dampers]] {i + 1}: floor = {floor!r}: need a whole number 1..{n} (1-based, from the ground up)")
        params = d.get("params", {})
        if not isinstance(params, dict):
            errs.append(f"[[dampers]] {i + 1}: params must be a table {{name = value}}")
            continue
        for name, value in {"tanks": d.get("tanks", 1), **params}.items():
            why = contract.check(name, value)
            if why:
                errs.append(f"[[dampers]] {i + 1} params: {why}")
    if errs:
        raise StudyError(_listed(errs))


def load_building(path: Path, contract) -> dict:
    """A building file, read and checked (StudyError names what is wrong)."""
    return _load(path, check_building, contract)
