"""The FMU as a file: schema validity, the public variable names of FMU.md with their causality,
enumeration integer values, model structure, and the calculated parameters (Eqs 2.1/2.2)."""
import pytest

from tld_fmu import reference as R

# FMU.md, "Variables": the public interface (name -> causality)
FMU_MD_VARIABLES = {
    **{n: "parameter" for n in [
        "tank.length", "tank.breadth", "tank.depth", "liquid.density", "g", "tanks", "model",
        "eta", "phi", "damping", "zeta", "nsd.c", "nsd.p", "lambda.min", "lambda.max",
        "amplitude", "A_e", "amplitude.tau"]},
    **{n: "calculatedParameter" for n in ["omega_f", "mass.liquid", "mass.slosh", "mass.inactive"]},
    **{n: "input" for n in ["base.a", "base.v", "base.x"]},
    **{n: "output" for n in [
        "force", "force.mean", "base_shear", "slosh.x", "slosh.v", "energy.input",
        "energy.dissipated", "energy.stored", "A_e.estimate", "zeta.effective"]},
}

# FMU.md default values (start attributes)
FMU_MD_DEFAULTS = {
    "tank.length": 0.25, "tank.breadth": 0.32, "tank.depth": 0.021, "liquid.density": 1000,
    "g": 9.81, "tanks": 1, "eta": 2, "phi": 1, "zeta": 0.01, "nsd.c": 0.5, "nsd.p": 0.35,
    "lambda.min": 1e-3, "lambda.max": 0.1, "A_e": 0.005,
    "base.a": 0, "base.v": 0, "base.x": 0,
}

# enumeration item -> fmi2SetInteger value (modelDescription.xml; documented for libcosim users)
ENUMS = {
    "damping": {"Constant": 1, "NSD": 2},
    "amplitude": {"Fixed": 1, "Tracked": 2},
    "solver": {"DormandPrince45": 1, "RK4": 2},
    "model": {"Nonlinear": 2},
}
ENUM_DEFAULTS = {"model": "Nonlinear", "damping": "NSD", "amplitude": "Tracked",
                 "solver": "DormandPrince45"}


def test_validate_fmu(fmu_path):
    from fmpy.validation import validate_fmu
    problems = validate_fmu(str(fmu_path))
    assert problems == [], "fmpy.validate_fmu found problems:\n" + "\n".join(problems)


def test_public_variables_and_causality(variables):
    missing = sorted(set(FMU_MD_VARIABLES) - set(variables))
    assert not missing, f"variables of FMU.md missing from the FMU: {missing}"
    wrong = {n: (variables[n].causality, c) for n, c in FMU_MD_VARIABLES.items()
             if variables[n].causality != c}
    assert not wrong, f"wrong causality (have, want): {wrong}"
    for n in ("base.a", "base.v", "base.x"):
        assert variables[n].variability == "continuous" and variables[n].type == "Real"
    assert variables["tanks"].type == "Integer"
    for n in ENUMS:
        assert variables[n].type == "Enumeration", n


def test_default_values(variables):
    for n, want in FMU_MD_DEFAULTS.items():
        assert float(variables[n].start) == pytest.approx(want, rel=1e-15), n


def test_enumeration_values(model_description, variables):
    for name, items in ENUMS.items():
        v = variables[name]
        td = v.declaredType
        assert td is not None, f"{name} has no declaredType"
        have = {it.name: int(it.value) for it in td.items}
        for item, value in items.items():
            assert have.get(item) == value, f"{name}.{item}: {have}"
        assert int(v.start) == items[ENUM_DEFAULTS[name]], f"{name} default {v.start}"


def test_fmu_md_model_ladder_is_declared(variables):
    """FMU.md: `modes` and the items Linear, Nonlinear, SloshingSlamming of `model`."""
    assert "modes" in variables
    assert {it.name for it in variables["model"].declaredType.items} >= {
        "Linear", "Nonlinear", "SloshingSlamming"}


def test_capabilities(model_description):
    cs = model_description.coSimulation
    assert cs.modelIdentifier == "TLD"
    assert cs.canHandleVariableCommunicationStepSize
    assert not cs.needsExecutionTool
    assert not cs.canBeInstantiatedOnlyOncePerProcess
    assert model_description.fmiVersion == "2.0"
    assert model_description.variableNamingConvention == "structured"


def test_fmu_md_capabilities(model_description):
    """FMU.md: input interpolation, output derivatives and (serialisable) FMU state."""
    cs = model_description.coSimulation
    assert cs.canInterpolateInputs and cs.maxOutputDerivativeOrder >= 1
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate


def test_model_structure(model_description):
    all_deps = {u.variable.name: {d.name for d in (u.dependencies or [])}
                for u in model_description.outputs}
    inputs = {v.name for v in model_description.modelVariables if v.causality == "input"}
    deps = {n: d & inputs for n, d in all_deps.items()}
    outputs = [n for n, c in FMU_MD_VARIABLES.items() if c == "output"]
    assert set(outputs) <= set(deps)
    # force depends on the state only; base_shear feeds through base.a (FMU.md)
    assert deps["force"] == set()
    assert deps["base_shear"] == {"base.a"}
    for n in outputs:
        if n != "base_shear":
            assert deps[n] == set(), f"{n} declared to depend on {deps[n]}"
    # Model Exchange: the rest of each output's dependencies are continuous states
    states = {d.variable.derivative.name for d in model_description.derivatives}
    bank = {f"mode[{n}].{q}" for n in range(2, 11) for q in "xv"}
    tracker = {"A_e.tracker.v"} | {f"A_e.tracker.{q}[{k}]" for q in ("v2", "a2", "weight")
                                    for k in (1, 2)}
    assert states == {"slosh.x", "slosh.v", "energy.input", "energy.dissipated", "impact.z",
                      "impact.v"} | bank | tracker
    assert all(d - inputs <= states for d in all_deps.values())
    # The Linear model's force sums its modes; with amplitude = Tracked its damping follows the
    # estimate, formed from the second filters.
    estimate = {"A_e.tracker.v2[2]", "A_e.tracker.a2[2]", "A_e.tracker.weight[2]"}
    assert all_deps["force"] == {"slosh.x", "slosh.v"} | bank | estimate
    assert model_description.numberOfEventIndicators == 2


GEOMETRIES = [
    {},                                                         # Table 2.1 tank
    {"tanks": 3},
    {"tank.length": 2.0, "tank.breadth": 1.5, "tank.depth": 0.2, "liquid.density": 1025.0,
     "g": 9.80665, "tanks": 3},
    {"tank.length": 10.0, "tank.breadth": 4.0, "tank.depth": 1.2, "liquid.density": 998.0,
     "tanks": 12},
]


@pytest.mark.parametrize("geo", GEOMETRIES, ids=["default", "tanks3", "2m_tank_x3", "10m_x12"])
def test_calculated_parameters(slave_factory, variables, geo):
    s = slave_factory()
    s.initialize(geo)
    kw = {"a": "tank.length", "b": "tank.breadth", "h": "tank.depth", "rho": "liquid.density",
          "g": "g", "tanks": "tanks"}
    args = {k: geo.get(n, float(variables[n].start)) for k, n in kw.items()}
    args["tanks"] = int(args["tanks"])
    want = R.geometry(**args)
    for name, value in want.items():
        # same closed form evaluated in double precision: only operation order differs (1e-15);
        # 1e-12 leaves room for that and still catches any wrong factor or constant
        assert s.get(name) == pytest.approx(value, rel=1e-12), name
    if not geo:
        # MODEL.md check values, quoted to 4 digits there
        assert s.get("mass.liquid") == pytest.approx(1.68, rel=1e-12)
        assert s.get("mass.slosh") / s.get("mass.liquid") == pytest.approx(0.7923, abs=5e-5)
        assert s.get("omega_f") == pytest.approx(5.6389, abs=5e-5)


def test_tanks_scale_forces_not_motion(slave_factory):
    # N identical tanks: same sloshing motion, N times the force and energies
    import numpy as np
    dt, n = 1e-3, 3000
    p = R.TLD()
    bx, bv, ba = R.harmonic_base(1.05 * p.omega_f, 0.005, dt * np.arange(n))
    outs = ["slosh.x", "force", "base_shear", "energy.stored", "energy.input"]
    res = []
    for tanks in (1, 3):
        s = slave_factory()
        s.initialize({"tanks": tanks})
        res.append(s.run(dt, {"base.x": bx, "base.v": bv, "base.a": ba}, outs))
    assert R.rel_err(res[1]["slosh.x"], res[0]["slosh.x"]) < 1e-12
    for k in outs[1:]:
        assert R.rel_err(res[1][k], 3 * res[0][k]) < 1e-12, k
