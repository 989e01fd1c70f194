"""Writes modelDescription.xml, Building.fmu's single source of truth (the build script reads
it), from the per-storey pattern below: 20 storeys of parameters, inputs and outputs are
written once here instead of by hand. Run it after editing: python3 make.py"""
from pathlib import Path

N = 20
GUID = "{6a3e1d52-8c0b-4f7e-9b1a-3d2f5c7e9a41}"
# Table 2.1's structure (168 kg) tuned to the tank's 5.6389 rad/s as one storey.
MASS, STIFFNESS = 168.0, 5342.0

vars = []  # (name, vr, causality, variability, initial, type, attrs, description)

def add(name, vr, causality, variability, ty, description, initial=None, **attrs):
    vars.append((name, vr, causality, variability, initial, ty, attrs, description))
    return len(vars)  # 1-based index

P = dict(causality="parameter", variability="fixed", initial="exact")
storeys = add("storeys", 0, ty="Integer", start=1, min=1, max=N,
              description=f"N, the number of storeys (1..{N}); the variables of storeys above N are ignored", **P)
zeta = add("damping.zeta", 1, ty="Real", unit="1", start=0.02, min=0, max=0.99,
           description="damping ratio of modes 1 and 2 (Rayleigh damping), unless damping.zeta1/zeta2 are set", **P)
zeta1 = add("damping.zeta1", 2, ty="Real", unit="1", start=-1, min=-1, max=0.99,
            description="damping ratio of mode 1; -1 (default): damping.zeta", **P)
zeta2 = add("damping.zeta2", 3, ty="Real", unit="1", start=-1, min=-1, max=0.99,
            description="damping ratio of mode 2; -1 (default): damping.zeta", **P)
tld_floor = add("tld.floor", 4, ty="Integer", start=0, min=0, max=N,
                description="the floor carrying the damper (1..N); 0 (default): the roof, floor N", **P)
tld_mass = add("tld.mass", 5, ty="Real", unit="kg", start=0, min=0, max=1e9,
               description="mass moving rigidly with the damper's floor: TLD.fmu's mass.inactive", **P)
masses = [add(f"storey[{i}].mass", 100 + i - 1, ty="Real", unit="kg", start=MASS, min=1e-6, max=1e12,
              description=f"mass of floor {i}", **P) for i in range(1, N + 1)]
stiffs = [add(f"storey[{i}].stiffness", 200 + i - 1, ty="Real", unit="N/m", start=STIFFNESS, min=1e-6, max=1e15,
              description=f"lateral stiffness of storey {i} (between floor {i - 1} and floor {i}; floor 0 is the ground)", **P)
          for i in range(1, N + 1)]
I = dict(causality="input", variability="continuous")
ground_a = add("ground.a", 20, ty="Real", unit="m/s2", start=0,
               description="ground acceleration, +x (added to the built-in motion of ground.amplitude, ground.omega)", **I)
tld_force = add("tld.force", 21, ty="Real", unit="N", start=0,
                description="force of the damper on its floor, +x (TLD.fmu's force)", **I)
floor_f = [add(f"floor[{i}].force", 300 + i - 1, ty="Real", unit="N", start=0,
               description=f"external force on floor {i}, +x (wind)", **I) for i in range(1, N + 1)]
O = dict(causality="output", variability="continuous", initial="calculated")
tld_a = add("tld.a", 30, ty="Real", unit="m/s2",
            description="absolute acceleration of the damper's floor (TLD.fmu's base.a); feeds through tld.force and the floor forces", **O)
tld_v = add("tld.v", 31, ty="Real", unit="m/s",
            description="absolute velocity of the damper's floor (TLD.fmu's base.v): the ground's velocity (integrated from ground.a from rest, plus the built-in motion's) plus the floor's relative velocity", **O)
tld_x = add("tld.x", 32, ty="Real", unit="m",
            description="absolute displacement of the damper's floor (TLD.fmu's base.x), likewise", **O)
roof_x = add("roof.x", 33, ty="Real", unit="m", description="displacement of floor N relative to the ground", **O)
shear = add("base_shear", 34, ty="Real", unit="N",
            description="force of storey 1 on the ground: k_1 u_1 plus the Rayleigh damping forces 1^T C u'", **O)
floor_x = [add(f"floor[{i}].x", 400 + i - 1, ty="Real", unit="m",
               description=f"displacement of floor {i} relative to the ground", **O) for i in range(1, N + 1)]
floor_a = [add(f"floor[{i}].a", 500 + i - 1, ty="Real", unit="m/s2",
               description=f"absolute acceleration of floor {i}; feeds through its own force and tld.force", **O)
           for i in range(1, N + 1)]
C = dict(causality="calculatedParameter", variability="fixed", initial="calculated")
w1 = add("mode[1].omega", 40, ty="Real", unit="rad/s", description="circular frequency of mode 1", **C)
w2 = add("mode[2].omega", 41, ty="Real", unit="rad/s",
         description="circular frequency of mode 2 (one storey: mode 1's)", **C)
alpha = add("damping.alpha", 42, ty="Real", unit="1/s", description="Rayleigh mass coefficient: C = alpha M + beta K", **C)
beta = add("damping.beta", 43, ty="Real", unit="s", description="Rayleigh stiffness coefficient", **C)
# Added after the rest (indices of the variables above unchanged): the built-in ground motion.
ground_amp = add("ground.amplitude", 6, ty="Real", unit="m", start=0, min=-1000, max=1000,
                 description="A, amplitude of the built-in harmonic ground displacement x_g = A sin(ground.omega t) "
                             "(ground velocity A omega at t = 0, acceleration -A omega^2 sin(omega t)), added to "
                             "ground.a; 0 (default): none", **P)
ground_w = add("ground.omega", 7, ty="Real", unit="rad/s", start=5.6389, min=0, max=10000,
               description="omega, circular frequency of the built-in ground motion (default 5.6389: the "
                           "default one-storey building's own frequency)", **P)
# Added for Model Exchange (indices above unchanged): the continuous states z = [u, u', x_g, v_g,
# h, v_h] of the first-order system, padded to N storeys (the states of storeys above
# `storeys` stay 0), and their derivatives.
L = dict(causality="local", variability="continuous")
floor_v = [add(f"floor[{i}].v", 600 + i - 1, ty="Real", unit="m/s", start=0,
               description=f"velocity of floor {i} relative to the ground (a continuous state)", initial="exact", **L)
           for i in range(1, N + 1)]
ground_x = add("ground.x", 50, ty="Real", unit="m", start=0, initial="exact",
               description="the ground's displacement (ground.a integrated from rest, plus the built-in motion's; a continuous state)", **L)
ground_v = add("ground.v", 51, ty="Real", unit="m/s", initial="calculated",
               description="the ground's velocity (starts at ground.amplitude ground.omega; a continuous state)", **L)
ground_h = add("ground.motion.x", 52, ty="Real", unit="m", start=0, initial="exact",
               description="the built-in harmonic ground motion's displacement A sin(omega t) (a continuous state)", **L)
ground_hv = add("ground.motion.v", 53, ty="Real", unit="m/s", initial="calculated",
                description="the built-in harmonic ground motion's velocity A omega cos(omega t) (a continuous state)", **L)
states = floor_x + floor_v + [ground_x, ground_v, ground_h, ground_hv]
D = dict(causality="local", variability="continuous", initial="calculated")
ders = []
for i in range(1, N + 1):
    ders.append(add(f"der(floor[{i}].x)", 700 + i - 1, ty="Real", unit="m/s", derivative=floor_x[i - 1],
                    description=f"time derivative of floor[{i}].x", **D))
for i in range(1, N + 1):
    ders.append(add(f"der(floor[{i}].v)", 800 + i - 1, ty="Real", unit="m/s2", derivative=floor_v[i - 1],
                    description=f"time derivative of floor[{i}].v", **D))
for k, (name, unit) in enumerate([("ground.x", "m/s"), ("ground.v", "m/s2"), ("ground.motion.x", "m/s"),
                                   ("ground.motion.v", "m/s2")]):
    ders.append(add(f"der({name})", 54 + k, ty="Real", unit=unit, derivative=states[2 * N + k],
                    description=f"time derivative of {name}", **D))

# Added for Model Exchange couplings with impacts (indices above unchanged): TLD.fmu's
# impact.impulse in, the floor's velocity jump out, both discrete (they change at events).
tld_impulse = add("tld.impulse", 22, ty="Real", unit="N.s", start=0, causality="input", variability="discrete",
                  description="Model Exchange: momentum handed to the damper's floor by impulses so far, +x (connect "
                              "TLD.fmu's impact.impulse); where it changes (set in event mode) the floor's velocities "
                              "jump by M^-1 times the change (the damper's floor by the change over its mass with "
                              "tld.mass): an exact momentum transfer; ignored in Co-Simulation (use TLD.fmu's force.mean)")
tld_v_jump = add("tld.v.jump", 35, ty="Real", unit="m/s", causality="output", variability="discrete",
                 initial="calculated",
                 description="Model Exchange: the jumps of the damper's floor's velocity that tld.impulse made so far, "
                             "+x (connect TLD.fmu's base.v.jump)")

def deps(xs):
    return " ".join(str(x) for x in sorted(xs))

structure = [storeys, tld_floor, tld_mass] + masses
everything = structure + stiffs + [zeta, zeta1, zeta2]
forces = [tld_force] + floor_f
outputs = []  # (index, output deps, initial deps)
# Outputs depend on inputs and (Model Exchange) on the continuous states.
outputs.append((tld_a, forces + floor_x + floor_v, forces + structure))
# tld.v starts at the built-in ground motion's velocity A omega
outputs.append((tld_v, floor_v + [ground_v], [ground_amp, ground_w]))
outputs.append((tld_x, floor_x + [ground_x], []))
outputs.append((roof_x, floor_x, []))
outputs.append((shear, floor_x[:1] + floor_v, []))
for k in floor_x:
    outputs.append((k, [k], []))
for i, k in enumerate(floor_a):
    outputs.append((k, [tld_force, floor_f[i]] + floor_x + floor_v, [tld_force, floor_f[i]] + structure))
outputs.append((tld_v_jump, [tld_impulse], [tld_impulse] + structure))
outputs.sort()
initial = sorted(outputs + [(k, None, everything) for k in [w1, w2, alpha, beta]])
initial += [(ground_v, None, [ground_amp, ground_w]), (ground_hv, None, [ground_amp, ground_w])]
initial += [(k, None, everything + [ground_a, ground_amp, ground_w] + forces) for k in ders]
initial.sort()

def attr_text(attrs):
    return " ".join(f'{k}="{v}"' for k, v in attrs.items())

lines = ['<?xml version="1.0" encoding="UTF-8"?>',
         "<!-- The single source of truth for Building.fmu's variables, written by make.py (edit that,",
         "     then run it). The build script (build/) checks it and generates the Rust value-reference",
         "     table (building/src/description.rs). -->",
         f'''<fmiModelDescription
  fmiVersion="2.0"
  modelName="Building"
  guid="{GUID}"
  description="Linear N-storey shear building with Rayleigh damping, advanced exactly over each communication step (matrix exponential) for inputs held or polynomial over the step: the reference structure for TLD.fmu."
  author="tld-fmu developers"
  version="0.1.0"
  generationTool="tld-fmu (Rust)"
  variableNamingConvention="structured"
  numberOfEventIndicators="0">

  <ModelExchange
    modelIdentifier="Building"
    needsExecutionTool="false"
    completedIntegratorStepNotNeeded="true"
    canBeInstantiatedOnlyOncePerProcess="false"
    canNotUseMemoryManagementFunctions="true"
    canGetAndSetFMUstate="true"
    canSerializeFMUstate="true"
    providesDirectionalDerivative="true"/>

  <CoSimulation
    modelIdentifier="Building"
    needsExecutionTool="false"
    canHandleVariableCommunicationStepSize="true"
    canInterpolateInputs="true"
    maxOutputDerivativeOrder="1"
    canRunAsynchronuously="false"
    canBeInstantiatedOnlyOncePerProcess="false"
    canNotUseMemoryManagementFunctions="true"
    canGetAndSetFMUstate="true"
    canSerializeFMUstate="true"
    providesDirectionalDerivative="false"/>

  <UnitDefinitions>
    <Unit name="1"/>
    <Unit name="m"><BaseUnit m="1"/></Unit>
    <Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit>
    <Unit name="m/s2"><BaseUnit m="1" s="-2"/></Unit>
    <Unit name="kg"><BaseUnit kg="1"/></Unit>
    <Unit name="s"><BaseUnit s="1"/></Unit>
    <Unit name="1/s"><BaseUnit s="-1"/></Unit>
    <Unit name="rad/s"><BaseUnit s="-1" rad="1"/></Unit>
    <Unit name="N"><BaseUnit kg="1" m="1" s="-2"/></Unit>
    <Unit name="N/m"><BaseUnit kg="1" s="-2"/></Unit>
    <Unit name="N.s"><BaseUnit kg="1" m="1" s="-1"/></Unit>
  </UnitDefinitions>

  <LogCategories>
    <Category name="logStatusError" description="Errors: illegal calls, bad values, failed steps"/>
    <Category name="logStatusWarning" description="Warnings"/>
    <Category name="logCalls" description="Every FMI call"/>
  </LogCategories>

  <DefaultExperiment startTime="0" stopTime="60" stepSize="0.01"/>

  <ModelVariables>''']
for k, (name, vr, causality, variability, initial_, ty, attrs, description) in enumerate(vars, 1):
    init = f' initial="{initial_}"' if initial_ else ""
    lines.append(f'    <!-- {k} --><ScalarVariable name="{name}" valueReference="{vr}" causality="{causality}" '
                 f'variability="{variability}"{init} description="{description}">')
    lines.append(f"      <{ty} {attr_text(attrs)}/></ScalarVariable>".replace(f"<{ty} />", f"<{ty}/>"))
lines.append("  </ModelVariables>\n\n  <ModelStructure>\n    <Outputs>")
for k, d, _ in outputs:
    lines.append(f'      <Unknown index="{k}" dependencies="{deps(d)}"/>')
lines.append("    </Outputs>\n    <Derivatives>")
inputs = [ground_a] + forces
for k in ders:
    lines.append(f'      <Unknown index="{k}" dependencies="{deps(states + inputs)}"/>')
lines.append("    </Derivatives>\n    <InitialUnknowns>")
for k, _, d in initial:
    lines.append(f'      <Unknown index="{k}" dependencies="{deps(d)}"/>')
lines.append("    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>\n")
Path(__file__).with_name("modelDescription.xml").write_text("\n".join(lines))
