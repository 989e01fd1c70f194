//! Every output of every model, through the damper that wires it (x, v, force, force.mean,
//! base_shear, the three energies, A_e.estimate, zeta.effective, impact.z, impacts,
//! surface.left/right, and the exact output rates), against a reference written here from the
//! equations of MODEL.md, independently of src/physics: closed forms for the linear models and
//! the S^2 impact mass's flights, a tiny-step RK4 with a Richardson check for the nonlinear
//! ones. Each run also saves and restores its state half way. Seconds in all: a wrong wiring
//! fails `cargo test` at once (issue 30, and scripts/mutants over src/model).

mod bounds;
mod nonlinear;
mod shallow_water;
mod slamming;
mod state;

use super::{Damper, Inputs, Output, StartValues};
use crate::description::vr;
use std::f64::consts::PI;

/// Items of the enumerations (modelDescription.xml).
const LINEAR: f64 = 1.0;
const NONLINEAR: f64 = 2.0;
const SLAMMING: f64 = 3.0;
const AUTO: f64 = 4.0;
const FIXED: f64 = 1.0;
const TRACKED: f64 = 2.0;
const CONSTANT: f64 = 1.0;
const DOP853: f64 = 5.0;

/// The default tank (Table 2.1): length a, breadth b, depth h, density, g.
const A: f64 = 0.25;
const B: f64 = 0.32;
const H: f64 = 0.021;
const RHO: f64 = 1000.0;
const G: f64 = 9.81;

/// Liquid of one tank [kg].
fn liquid() -> f64 {
    RHO * A * B * H
}

/// Eqs 2.1 and 2.2 for mode n of one tank: (modal mass, natural frequency).
fn natural(n: u32) -> (f64, f64) {
    let k = f64::from(2 * n - 1) * PI;
    let th = (k * H / A).tanh();
    (
        liquid() * 8.0 * th / (k * k * k * (H / A)),
        (G * k * th / A).sqrt(),
    )
}

/// The NSD law at its defaults (c 0.5, p 0.35, Lambda in [0.001, 0.1]).
fn nsd_zeta(a_e: f64) -> f64 {
    0.5 * (a_e / A).clamp(0.001, 0.1).powf(0.35)
}

/// Wave height at the left wall per metre of slosh.x: the fundamental mode cos(pi x/a) with
/// the first moment m_1 x of one tank, eta(0) = -pi^2 m_1 x / (2 rho b a^2).
fn surface_per_x() -> f64 {
    -PI * PI * natural(1).0 / (2.0 * RHO * B * A * A)
}

/// Every output of the damper.
pub(super) const OUTPUTS: [Output; 14] = [
    Output::Force,
    Output::X,
    Output::V,
    Output::ForceMean,
    Output::BaseShear,
    Output::EnergyInput,
    Output::EnergyDissipated,
    Output::EnergyStored,
    Output::Amplitude,
    Output::Zeta,
    Output::ImpactZ,
    Output::Impacts,
    Output::SurfaceLeft,
    Output::SurfaceRight,
];

/// The reference's values of the outputs (indexed as `OUTPUTS`), and of the rates the damper
/// gives exactly (None: not checked).
#[derive(Clone, Copy, Debug, Default)]
struct Expected {
    values: [f64; 14],
    rates: Option<[f64; 14]>,
}

impl Expected {
    fn set(&mut self, which: Output, value: f64) {
        self.values[index(which)] = value;
    }
}

fn index(which: Output) -> usize {
    OUTPUTS.iter().position(|o| *o == which).expect("listed")
}

/// The largest error and the largest reference value of every output over a whole run.
struct History {
    what: String,
    err: [f64; 14],
    size: [f64; 14],
    rate_err: [f64; 14],
    rate_size: [f64; 14],
}

impl History {
    fn new(what: &str) -> Self {
        History {
            what: what.into(),
            err: [0.0; 14],
            size: [0.0; 14],
            rate_err: [0.0; 14],
            rate_size: [0.0; 14],
        }
    }

    /// Compare every output of `sim` (read with `inputs`) with `e`.
    fn compare(&mut self, sim: &Damper, inputs: &Inputs, e: &Expected) {
        for (k, which) in OUTPUTS.iter().enumerate() {
            let got = sim.output(*which, inputs);
            let diff = (got - e.values[k]).abs();
            // NaN never passes.
            self.err[k] = if diff.is_nan() {
                f64::INFINITY
            } else {
                self.err[k].max(diff)
            };
            self.size[k] = self.size[k].max(e.values[k].abs());
            if let Some(rates) = e.rates {
                let got = sim.output_derivative(*which, inputs);
                let diff = (got - rates[k]).abs();
                self.rate_err[k] = if diff.is_nan() {
                    f64::INFINITY
                } else {
                    self.rate_err[k].max(diff)
                };
                self.rate_size[k] = self.rate_size[k].max(rates[k].abs());
            }
        }
    }

    /// Every output within `tol` of its largest reference value over the run (outputs that
    /// are 0 throughout: exactly 0), and the rates alike.
    fn assert(&self, tol: f64) {
        for (k, which) in OUTPUTS.iter().enumerate() {
            for (kind, err, size) in [
                ("value", self.err[k], self.size[k]),
                ("rate", self.rate_err[k], self.rate_size[k]),
            ] {
                if std::env::var("WIRING_DEBUG").is_ok() {
                    eprintln!("{} {which:?} {kind} {:e}", self.what, err / size);
                }
                assert!(
                    err <= tol * size,
                    "{}: {which:?} ({kind}) off by {err:e}, largest {size:e}",
                    self.what
                );
            }
        }
    }
}

/// A held base acceleration `a`.
fn held(a: f64) -> Inputs {
    Inputs {
        a,
        ..Inputs::default()
    }
}

fn damper(p: &StartValues) -> Damper {
    Damper::configure(p).expect("configuration").0
}

/// `sim` through its state: saved and restored with the same parameters.
fn reloaded(sim: &Damper, p: &StartValues) -> Damper {
    Damper::restore(p, &sim.snapshot()).expect("restore")
}

/// One linear oscillator x'' + 2 zeta w x' + w^2 x = -a (per unit mass) and its energies.
#[derive(Clone, Copy, Debug, Default)]
struct Mode {
    w: f64,
    x: f64,
    v: f64,
    work: f64,
}

impl Mode {
    /// Advanced by `h` under the held acceleration `a`, in closed form: the static deflection
    /// -a/w^2 plus the damped free oscillation about it. The work of the base -int a v dt is
    /// -a dx for a held a.
    fn held(&mut self, zeta: f64, a: f64, h: f64) {
        let s = zeta * self.w;
        let wd = self.w * (1.0 - zeta * zeta).sqrt();
        let xs = -a / (self.w * self.w);
        let u0 = self.x - xs;
        let b = (self.v + s * u0) / wd;
        let (c, sn, e) = ((wd * h).cos(), (wd * h).sin(), (-s * h).exp());
        let x = xs + e * (u0 * c + b * sn);
        let v = e * (-s * (u0 * c + b * sn) + wd * (b * c - u0 * sn));
        self.work += -a * (x - self.x);
        self.x = x;
        self.v = v;
    }

    fn stored(&self) -> f64 {
        0.5 * (self.v * self.v + self.w * self.w * self.x * self.x)
    }

    /// Force on the tank per unit mass, 2 zeta w v + w^2 x.
    fn force(&self, zeta: f64) -> f64 {
        2.0 * zeta * self.w * self.v + self.w * self.w * self.x
    }

    /// x'' under `a`.
    fn acceleration(&self, zeta: f64, a: f64) -> f64 {
        -a - 2.0 * zeta * self.w * self.v - self.w * self.w * self.x
    }
}

/// Tracked amplitude: the filter's time constant (0: two sloshing periods) and whether the host
/// gives base.v (else the tracker rebuilds it).
#[derive(Clone, Copy, Debug)]
struct Tracking {
    tau: f64,
    measured: bool,
}

/// Model = Linear with `modes` modes and `tanks` tanks, held inputs that change every step,
/// amplitude fixed or tracked: every output and rate against the closed form.
fn linear_run(modes: u32, tanks: u32, tracking: Option<Tracking>) {
    let tracked = tracking.is_some();
    let a_e = 0.004;
    let p = StartValues::default()
        .with(vr::MODEL, LINEAR)
        .with(vr::MODES, f64::from(modes))
        .with(vr::TANKS, f64::from(tanks))
        .with(vr::AMPLITUDE, if tracked { TRACKED } else { FIXED })
        .with(vr::AMPLITUDE_TAU, tracking.map_or(0.0, |t| t.tau))
        .with(vr::A_E, a_e)
        .with(vr::SLOSH_X0, 0.004)
        .with(vr::SLOSH_V0, -0.01);
    let mut sim = damper(&p);
    let n = f64::from(tanks);
    let mut ref_modes: Vec<(f64, Mode)> = (1..=modes)
        .map(|k| {
            let (m, w) = natural(k);
            let (x, v) = if k == 1 { (0.004, -0.01) } else { (0.0, 0.0) };
            let mode = Mode { w, x, v, work: 0.0 };
            (m * n, mode)
        })
        .collect();
    let slosh: f64 = ref_modes.iter().map(|(m, _)| m).sum();
    let inactive = liquid() * n - slosh;
    let initial: f64 = ref_modes.iter().map(|(m, o)| m * o.stored()).sum();
    // The tracker is the physics' own (tested there); what is checked is that its estimate sets
    // the damping of the step and the outputs.
    let w1 = natural(1).1;
    let mut tracker = tracking.map(|t| {
        let tau = if t.tau > 0.0 {
            t.tau
        } else {
            2.0 * 2.0 * PI / w1
        };
        crate::physics::amplitude::AmplitudeTracker::new(tau, 0.05 * w1, a_e, w1)
    });
    let measured = tracking.is_some_and(|t| t.measured);
    let mut amplitude = a_e;
    let mut zeta = nsd_zeta(a_e);
    let what = format!("Linear, {modes} modes, {tanks} tanks, tracking {tracking:?}");
    let mut history = History::new(&what);
    let h = 0.02;
    let mut base_v = 0.0;
    for k in 0..600 {
        let t = f64::from(k) * h;
        let a = -0.004 * (1.1 * w1).powi(2) * (1.1 * w1 * t).sin() + 0.3 * (0.37 * t).cos();
        let inputs = Inputs {
            a,
            v: if measured { base_v } else { 0.0 },
            ..Inputs::default()
        };
        base_v += a * h;
        sim.step(t, h, &inputs).expect("step");
        if let Some(tr) = tracker.as_mut() {
            tr.update(h, inputs.a, inputs.v);
            amplitude = tr.estimate();
            zeta = nsd_zeta(amplitude);
        }
        let before: Vec<f64> = ref_modes.iter().map(|(_, o)| o.v).collect();
        ref_modes.iter_mut().for_each(|(_, o)| o.held(zeta, a, h));
        let mut e = Expected::default();
        let sum = |f: &dyn Fn(f64, &Mode) -> f64| ref_modes.iter().map(|(m, o)| f(*m, o)).sum();
        let force = sum(&|m, o| m * o.force(zeta));
        let impulse: f64 = ref_modes
            .iter()
            .zip(&before)
            .map(|((m, o), v0)| m * (-(o.v - v0) - a * h))
            .sum();
        let work = sum(&|m, o| m * o.work);
        let stored = sum(&|m, o| m * o.stored());
        let (x, v) = (ref_modes[0].1.x, ref_modes[0].1.v);
        // Read with another input than the step's: base_shear takes the one it is read with.
        let read = Inputs {
            a: 0.7 * a - 0.1,
            a_derivatives: [0.9, 0.0],
            ..inputs
        };
        let surface = surface_per_x();
        for (which, value) in [
            (Output::Force, force),
            (Output::X, x),
            (Output::V, v),
            (Output::ForceMean, impulse / h),
            (Output::BaseShear, force - inactive * read.a),
            (Output::EnergyInput, initial + work),
            (Output::EnergyDissipated, initial + work - stored),
            (Output::EnergyStored, stored),
            (Output::Amplitude, amplitude),
            (Output::Zeta, zeta),
            (Output::SurfaceLeft, surface * x),
            (Output::SurfaceRight, -surface * x),
        ] {
            e.set(which, value);
        }
        // The rates under the input read: d/dt of each output along the equation of motion.
        let ra = read.a;
        let rate_force = sum(&|m, o| {
            let acc = o.acceleration(zeta, ra);
            m * (2.0 * zeta * o.w * acc + o.w * o.w * o.v)
        });
        let mut rates = [0.0; 14];
        for (which, value) in [
            (Output::Force, rate_force),
            (Output::X, v),
            (Output::V, ref_modes[0].1.acceleration(zeta, ra)),
            (Output::BaseShear, rate_force - inactive * 0.9),
            (Output::EnergyInput, sum(&|m, o| -m * ra * o.v)),
            (
                Output::EnergyDissipated,
                sum(&|m, o| m * 2.0 * zeta * o.w * o.v * o.v),
            ),
            (
                Output::EnergyStored,
                sum(&|m, o| -m * ra * o.v) - sum(&|m, o| m * 2.0 * zeta * o.w * o.v * o.v),
            ),
            (Output::SurfaceLeft, surface * v),
            (Output::SurfaceRight, -surface * v),
        ] {
            rates[index(which)] = value;
        }
        e.rates = Some(rates);
        history.compare(&sim, &read, &e);
        if k == 300 {
            sim = reloaded(&sim, &p);
            history.compare(&sim, &read, &e);
        }
    }
    history.assert(1e-9);
}

#[test]
fn linear_outputs_are_the_closed_form() {
    linear_run(1, 1, None);
    linear_run(3, 2, None);
    for (tau, measured) in [(0.0, true), (1.5, true), (0.0, false)] {
        linear_run(2, 3, Some(Tracking { tau, measured }));
    }
}

/// The calculated masses of the linear model: all tanks, the modal masses summed.
#[test]
fn linear_masses_are_the_modal_masses_of_all_tanks() {
    let p = StartValues::default()
        .with(vr::MODEL, LINEAR)
        .with(vr::MODES, 3.0)
        .with(vr::TANKS, 2.0);
    let d = damper(&p).derived();
    let slosh = 2.0 * (natural(1).0 + natural(2).0 + natural(3).0);
    assert!((d.mass_slosh - slosh).abs() <= 1e-12 * slosh, "{d:?}");
    assert!(
        (d.mass_liquid - 2.0 * liquid()).abs() <= 1e-12 * liquid(),
        "{d:?}"
    );
    assert!((d.mass_inactive - (2.0 * liquid() - slosh)).abs() <= 1e-12 * liquid());
    assert!((d.omega_f - natural(1).1).abs() <= 1e-12 * d.omega_f);
}
