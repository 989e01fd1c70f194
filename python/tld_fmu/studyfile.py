"""Study files for tld_fmu.study (scripts/sweep.py): what a study TOML may hold, checked before
anything runs (check_study, load_study: unknown sections and keys, missing and impossible
values, FMU parameters the modelDescription lacks, all named at once), and a study dict written
back as TOML (dump_study)."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

# the columns of a study's table that come from its runs (tld_fmu.study)
COLUMNS = ["tuning", "tanks", "mass_ratio", "ground_amplitude", "frequency_ratio", "omega_s",
           "peak_displacement", "amplification"]


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
            errs.append(f"unknown section [{sec}] (known: {', '.join(_SCHEMA)})")
        elif not isinstance(table, dict):
            errs.append(f"[{sec}] must be a table")
        else:
            errs += [f"unknown key {k!r} in [{sec}] (known: {', '.join(_SCHEMA[sec])})"
                     for k in table if k not in _SCHEMA[sec]]
    for sec, keys in _REQUIRED.items():
        errs += [f"[{sec}] {k} is missing: {_SCHEMA[sec][k]}" for k in keys
                 if k not in study.get(sec, {}) if isinstance(study.get(sec, {}), dict)]
    if errs:
        raise StudyError("; ".join(errs))
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
        try:
            v = contract.variable(name)
            if v.causality != "parameter":
                errs.append(f"{where}: {name} is no parameter (causality {v.causality})")
                return
            contract.typed({name: value})
        except (KeyError, TypeError, ValueError) as e:
            errs.append(f"{where}: {e.args[0] if e.args else e}")

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
        raise StudyError("; ".join(errs))


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
    try:
        study = tomllib.loads(Path(path).read_text())
    except tomllib.TOMLDecodeError as e:
        raise StudyError(f"{path}: not valid TOML: {e}") from None
    except OSError as e:
        raise StudyError(f"{path}: {e.strerror}") from None
    try:
        check_study(study, contract)
    except StudyError as e:
        raise StudyError(f"{path}: {e}") from None
    return study
