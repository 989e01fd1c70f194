"""The FMU's contract, read from modelDescription.xml with fmpy: value references by variable
name and enumeration values by item name, so that Python never repeats the XML's integers.

    from tld_fmu.contract import vr, item
    vr("base.a")                 # value reference of base.a
    item("solver", "ExpRK4")     # fmi2SetInteger value of the solver's item ExpRK4

The module-level functions read the repository's modelDescription/modelDescription.xml (the
XML the FMU packs unchanged); `Contract(path_or_model_description)` reads another one, e.g. a
packed FMU's."""
from __future__ import annotations

import functools

from .paths import MODEL_DESCRIPTION


class Contract:
    """The variables of one modelDescription: source is an FMU, an unpacked FMU directory, a
    modelDescription.xml or a model description fmpy has read."""

    def __init__(self, source=MODEL_DESCRIPTION):
        if hasattr(source, "modelVariables"):
            self.md = source
        else:
            from fmpy import read_model_description
            self.md = read_model_description(str(source))
        self.variables = {v.name: v for v in self.md.modelVariables}

    def variable(self, name: str):
        try:
            return self.variables[name]
        except KeyError:
            raise KeyError(f"no variable {name!r} in the modelDescription{closest(name, self.variables)}") from None

    def check(self, name: str, value) -> str | None:
        """Why `name = value` cannot be set as a parameter (None: it can): an unknown name (with
        the closest valid ones), no parameter, a wrong type, an Enumeration's unknown item, or a
        value outside the modelDescription's min..max."""
        try:
            v = self.variable(name)
            if v.causality != "parameter":
                return f"{name} is no parameter (causality {v.causality})"
            ((_, setter, x),) = self.typed({name: value})
        except (KeyError, TypeError, ValueError) as e:
            return str(e.args[0] if e.args else e)
        if v.type == "Enumeration":
            values = [n for _, n, _ in self.items(name)]
            if x not in values:
                return f"{name} = {value!r}: not an item of {name} ({', '.join(i for i, _, _ in self.items(name))})"
            return None
        if setter != "boolean" and isinstance(value, bool):
            return f"{name} = {value!r}: a {v.type}, not true/false"
        lo, hi = (float(b) if b is not None else None for b in (v.min, v.max))
        if (lo is not None and not x >= lo) or (hi is not None and not x <= hi):
            return f"{name} = {value!r}: outside its range {v.min}..{v.max} (modelDescription)"
        return None

    def vr(self, name: str) -> int:
        """The value reference of variable `name`."""
        return self.variable(name).valueReference

    def items(self, name: str) -> list[tuple[str, int, str]]:
        """[(item name, value, description)] of the Enumeration variable `name`."""
        v = self.variable(name)
        if v.type != "Enumeration":
            raise TypeError(f"{name} is a {v.type}, not an Enumeration")
        return [(i.name, int(i.value), i.description or "") for i in v.declaredType.items]

    def item(self, name: str, item: str) -> int:
        """The value of item `item` of the Enumeration variable `name` (the fmi2SetInteger
        value)."""
        for n, value, _ in self.items(name):
            if n == item:
                return value
        names = [n for n, _, _ in self.items(name)]
        raise KeyError(f"{name} has no item {item!r}: {', '.join(names)}{closest(item, names)}")

    def value(self, name: str, value):
        """A parameter value as the FMU takes it: an Enumeration's item may be given by name."""
        if isinstance(value, str) and self.variable(name).type == "Enumeration":
            return self.item(name, value)
        return value

    def typed(self, values: dict) -> list[tuple[int, str, object]]:
        """{name: value} as [(value reference, setter, value)] in the dict's order, setter one
        of "real", "integer" (an Enumeration's too, its item by name or value) and "boolean"."""
        out = []
        for name, value in values.items():
            v = self.variable(name)
            value = self.value(name, value)
            if v.type == "Real":
                out.append((v.valueReference, "real", float(value)))
            elif v.type in ("Integer", "Enumeration"):
                out.append((v.valueReference, "integer", int(value)))
            elif v.type == "Boolean":
                out.append((v.valueReference, "boolean", bool(value)))
            else:
                raise TypeError(f"{name}: type {v.type}")
        return out

    def set(self, fmu, values: dict):
        """Set {name: value} on an fmpy FMU2Slave, each through its type's setter (an
        Enumeration's item by name or value)."""
        setters = {"real": fmu.setReal, "integer": fmu.setInteger, "boolean": fmu.setBoolean}
        for vr, setter, value in self.typed(values):
            setters[setter]([vr], [value])

    def initialise(self, fmu, values: dict, start: float = 0.0, tolerance=None):
        """Initialise an instantiated fmpy FMU2Slave: fmi2SetupExperiment at `start`, then
        {name: value} set (see `set`), fmi2EnterInitializationMode, fmi2ExitInitializationMode."""
        fmu.setupExperiment(tolerance=tolerance, startTime=start)
        self.set(fmu, values)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()


def closest(name: str, valid) -> str:
    """'; did you mean A or B?' for the valid names closest to a misspelt one (difflib), else ''."""
    import difflib
    near = difflib.get_close_matches(name, list(valid), n=3, cutoff=0.6)
    return f"; did you mean {' or '.join(repr(n) for n in near)}?" if near else ""


@functools.cache
def default() -> Contract:
    """The repository's modelDescription/modelDescription.xml, read once."""
    return Contract()


def vr(name: str) -> int:
    return default().vr(name)


def item(name: str, item: str) -> int:
    return default().item(name, item)


def items(name: str) -> list[tuple[str, int, str]]:
    return default().items(name)
