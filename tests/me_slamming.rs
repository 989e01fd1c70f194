//! model = SloshingSlamming (S^2) in Model Exchange through TLD.fmu's C entry points, driven by
//! an event-locating host written here: classical RK4 steps, the event indicators read after
//! each, a sign change located by bisection of the step (to 1e-15 s), then event mode and
//! fmi2NewDiscreteStates, where the FMU applies the impact law. Between impacts the impact mass
//! flies a parabola under the held input, which RK4 integrates exactly, so the impacts' times
//! and the impact mass's path are exact up to the bisection; the reference is the same model
//! in Co-Simulation, whose impacts are roots of the flight polynomial (and which
//! tests/python/test_slamming.py checks against a closed-form event-driven reference).

mod common;

use common::*;
use tld_fmu::fmi::vars::vr;

/// Continuous states: slosh.x, slosh.v, energy.input, energy.dissipated, impact.z, impact.v,
/// the Linear model's bank of higher modes (0 here).
/// All continuous states (the amplitude estimator's and the ShallowWater cells after these, 0 here).
const N: usize = tld_fmu::model::continuous::ALL_STATES;
/// Those S^2 uses.
const S2_STATES: usize = 6;
/// Event indicators: the contact functions of the walls +d/2 and -d/2.
const NZ: usize = 2;
const S2: i32 = 3;
const D: f64 = 0.1;
const E: f64 = 0.4;
const DT: f64 = 0.01;

/// An S^2 instance (ME or CS) with mass exchange `omega`, out of initialisation mode.
fn s2(name: &str, me: bool, omega: f64) -> Instance {
    let integers = [(vr::MODEL, S2), (vr::DAMPING, 1), (vr::AMPLITUDE, 1)];
    let reals = [
        (vr::ZETA, 0.02),
        (vr::SLAMMING_OMEGA, omega),
        (vr::SLAMMING_CLEARANCE, D),
        (vr::SLAMMING_RESTITUTION, E),
        (vr::SLAMMING_MASS_RATIO, 0.01),
    ];
    let inst = configured(name, me, &integers, &reals);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    inst
}

/// The host: its time, states, and the events it has handled.
struct Host {
    inst: Instance,
    t: f64,
    x: Vec<f64>,
    events: usize,
    changed: usize,
}

impl Host {
    fn new(inst: Instance) -> Self {
        let (s, info) = inst.new_discrete_states();
        assert_eq!((s, info.newDiscreteStatesNeeded), (OK, 0));
        assert_eq!(inst.enter_continuous_time_mode(), OK);
        let (s, x) = inst.states(N);
        assert_eq!(s, OK);
        Host {
            inst,
            t: 0.0,
            x,
            events: 0,
            changed: 0,
        }
    }

    fn derivatives(&self, t: f64, x: &[f64]) -> Vec<f64> {
        assert_eq!(self.inst.set_time(t), OK);
        assert_eq!(self.inst.set_states(x), OK, "{:?}", self.inst.logs());
        let (s, d) = self.inst.derivatives(N);
        assert_eq!(s, OK, "{:?}", self.inst.logs());
        d
    }

    /// One RK4 step of `h` from (t, x).
    fn rk4(&self, t: f64, x: &[f64], h: f64) -> Vec<f64> {
        let axpy =
            |k: &[f64], a: f64| -> Vec<f64> { x.iter().zip(k).map(|(x, k)| x + a * k).collect() };
        let k1 = self.derivatives(t, x);
        let k2 = self.derivatives(t + h / 2.0, &axpy(&k1, h / 2.0));
        let k3 = self.derivatives(t + h / 2.0, &axpy(&k2, h / 2.0));
        let k4 = self.derivatives(t + h, &axpy(&k3, h));
        (0..N)
            .map(|j| x[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]))
            .collect()
    }

    fn indicators(&self, t: f64, x: &[f64]) -> Vec<f64> {
        assert_eq!(self.inst.set_time(t), OK);
        assert_eq!(self.inst.set_states(x), OK);
        let (s, z) = self.inst.event_indicators(NZ);
        assert_eq!(s, OK, "{:?}", self.inst.logs());
        z
    }

    /// Event mode at the current time: `input` set there (an input event), then the event
    /// iteration; the states re-read if the FMU changed them.
    fn event(&mut self, input: Option<f64>) {
        assert_eq!(self.inst.set_time(self.t), OK);
        assert_eq!(self.inst.set_states(&self.x), OK);
        assert_eq!(self.inst.enter_event_mode(), OK);
        if let Some(a) = input {
            assert_eq!(self.inst.set_real(vr::BASE_A, a), OK);
        }
        let (s, info) = self.inst.new_discrete_states();
        assert_eq!((s, info.newDiscreteStatesNeeded), (OK, 0));
        if info.valuesOfContinuousStatesChanged != 0 {
            self.changed += 1;
            self.x = self.inst.states(N).1;
        }
        assert_eq!(self.inst.enter_continuous_time_mode(), OK);
    }

    /// Integrate to `t1` in steps of at most `h`, locating every state event.
    fn advance(&mut self, t1: f64, h: f64) {
        let crossed =
            |z0: &[f64], z1: &[f64]| z0.iter().zip(z1).any(|(a, b)| *a > 0.0 && *b <= 0.0);
        while self.t < t1 {
            let step = h.min(t1 - self.t);
            let z0 = self.indicators(self.t, &self.x);
            let y = self.rk4(self.t, &self.x, step);
            if !crossed(&z0, &self.indicators(self.t + step, &y)) {
                (self.t, self.x) = (self.t + step, y);
                let (s, (enter, _)) = self.inst.completed_integrator_step();
                assert_eq!((s, enter), (OK, 0));
                continue;
            }
            // The first crossing: bisect the step's length.
            let (mut lo, mut hi) = (0.0, step);
            while hi - lo > 1e-15 {
                let mid = 0.5 * (lo + hi);
                let ym = self.rk4(self.t, &self.x, mid);
                if crossed(&z0, &self.indicators(self.t + mid, &ym)) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            self.x = self.rk4(self.t, &self.x, hi);
            self.t += hi;
            self.events += 1;
            if std::env::var("ME_TRACE").is_ok() {
                eprintln!(
                    "event at {:.15} z {:e} v {:e}",
                    self.t, self.x[4], self.x[5]
                );
            }
            self.event(None);
        }
    }

    /// Run the held input `a` (one sample per DT, each an input event); at each sample time
    /// returns (slosh.x, impact.z, impacts, energy balance, energy.input).
    fn run(&mut self, a: &[f64]) -> Vec<[f64; 5]> {
        let mut out = vec![];
        for &ak in a {
            self.event(Some(ak));
            let next = ((self.t / DT).round() + 1.0) * DT;
            self.advance(next, DT / 10.0);
            let r = |v| self.inst.real(v);
            let balance = r(vr::ENERGY_INPUT) - r(vr::ENERGY_STORED) - r(vr::ENERGY_DISSIPATED);
            let (_, impacts) = get_integer(&self.inst, vr::IMPACTS);
            out.push([
                r(vr::SLOSH_X),
                r(vr::IMPACT_Z),
                f64::from(impacts),
                balance,
                r(vr::ENERGY_INPUT),
            ]);
        }
        out
    }
}

fn get_integer(inst: &Instance, r: u32) -> (u32, i32) {
    let mut v = -1;
    let s = unsafe { inst.lib.fmi2GetInteger(inst.c, &r, 1, &mut v) };
    (s, v)
}

/// The CS reference under the same held input: the same numbers at each sample time.
fn co_simulation(name: &str, omega: f64, a: &[f64]) -> Vec<[f64; 5]> {
    let mut cs = s2(name, false, omega);
    a.iter()
        .map(|&ak| {
            assert_eq!(cs.set_real(vr::BASE_A, ak), OK);
            assert_eq!(cs.do_step(DT), OK, "{:?}", cs.logs());
            let (_, impacts) = get_integer(&cs, vr::IMPACTS);
            [
                cs.real(vr::SLOSH_X),
                cs.real(vr::IMPACT_Z),
                f64::from(impacts),
                0.0,
                0.0,
            ]
        })
        .collect()
}

/// Harmonic base motion at 0.9 times the sloshing frequency, 20 mm, over 10 s: the impact mass
/// slams the walls many times. Every impact the host located is an
/// event at which the FMU changed the states; the count, the impact mass's path and the
/// sloshing mode agree with Co-Simulation at every sample; energy balances.
#[test]
fn a_host_locating_the_events_follows_co_simulation() {
    for omega in [1.0, 0.9] {
        let me = s2(&format!("me-s2-{omega}"), true, omega);
        let w = 0.9 * me.real(vr::OMEGA_F);
        let a: Vec<f64> = (0..2000)
            .map(|k| -w * w * 0.02 * (w * k as f64 * DT).sin())
            .collect();
        let mut host = Host::new(me);
        let got = host.run(&a);
        let want = co_simulation(&format!("cs-s2-{omega}"), omega, &a);
        let peak = |j: usize| want.iter().map(|r| r[j].abs()).fold(0.0, f64::max);
        let err = |j: usize| {
            got.iter()
                .zip(&want)
                .map(|(g, w)| (g[j] - w[j]).abs())
                .fold(0.0, f64::max)
        };
        let impacts = want.last().map_or(0.0, |r| r[2]);
        let input = got.iter().map(|r| r[4].abs()).fold(0.0, f64::max);
        let balance = got.iter().map(|r| r[3].abs()).fold(0.0, f64::max) / input;
        println!(
            "Omega {omega}: {} state events located ({} changed the states), {impacts} impacts \
             (CS {impacts}); slosh.x error {:.1e} of peak, impact.z {:.1e} m; energy balance {balance:.1e} of the peak input",
            host.events,
            host.changed,
            err(0) / peak(0),
            err(1),
        );
        assert!(impacts > 20.0, "{impacts}");
        assert_eq!(
            got.iter().map(|r| r[2]).collect::<Vec<_>>(),
            want.iter().map(|r| r[2]).collect::<Vec<_>>(),
            "impact counts at each sample"
        );
        assert_eq!(host.events as f64, impacts, "every located event an impact");
        assert_eq!(host.changed, host.events);
        // RK4 at 1 ms on the sloshing mode (w h = 0.006): ~1e-11 of the peak over 10 s.
        assert!(err(0) < 1e-9 * peak(0), "slosh.x {}", err(0));
        // The flights are exact; the bisection locates each impact to 1e-15 s.
        assert!(err(1) < 1e-10, "impact.z {}", err(1));
        // RK4's error in the energy states against the energy of the states.
        assert!(balance < 1e-9, "{balance}");
    }
}

/// A steady push presses the impact mass onto a wall: the bounces (each a located event)
/// shrink by e until the rebound is slower than the rest speed, then the mass rests (finitely
/// many events, the host is not stalled) with its derivatives 0; when the push turns the input
/// event releases it and it flies to the other wall. The same count as Co-Simulation.
#[test]
fn chattering_ends_at_rest_and_the_push_turning_releases_it() {
    let a: Vec<f64> = (0..200).map(|k| if k < 100 { -2.0 } else { 2.0 }).collect();
    let mut host = Host::new(s2("me-s2-chatter", true, 0.8));
    let got = host.run(&a[..100]);
    let rested = host.events;
    assert!(rested > 3 && rested < 40, "{rested} events");
    assert_eq!(got[99][1], 0.5 * D, "resting on +d/2");
    let (_, d) = host.inst.derivatives(N);
    assert_eq!(
        (d[4], d[5]),
        (0.0, 0.0),
        "at rest the impact mass moves with the tank"
    );
    let got = [got, host.run(&a[100..])].concat();
    let want = co_simulation("cs-s2-chatter", 0.8, &a);
    println!(
        "pressed: {rested} events to rest; {} in all, impacts {} (CS {})",
        host.events, got[199][2], want[199][2]
    );
    for (k, (g, w)) in got.iter().zip(&want).enumerate() {
        assert_eq!(g[2], w[2], "impacts at sample {k}");
        assert!(
            (g[1] - w[1]).abs() < 1e-12,
            "impact.z at sample {k}: {} vs {}",
            g[1],
            w[1]
        );
    }
    assert!(got[199][1] < 0.0, "flew to the other wall");
}

/// The derivative variables of S^2's states, and the Real outputs: the unknowns of J.
fn unknowns() -> Vec<u32> {
    let derivatives = S2_NAMES.map(|n| vr_of(&format!("der({n})")));
    derivatives.into_iter().chain(real_outputs()).collect()
}

/// The unknowns' values at the states `x` and base acceleration `a`.
fn unknown_values(inst: &Instance, x: &[f64], a: f64) -> Vec<f64> {
    assert_eq!(inst.set_states(x), OK, "{:?}", inst.logs());
    assert_eq!(inst.set_real(vr::BASE_A, a), OK);
    let (s, mut v) = inst.derivatives(N);
    assert_eq!(s, OK);
    v.truncate(S2_STATES);
    v.extend(unknowns()[S2_STATES..].iter().map(|&r| inst.real(r)));
    v
}

/// fmi2GetDirectionalDerivative for S^2, every column (the six states and base.a) of J for the
/// six derivatives and every Real output, against central differences of fmi2GetDerivatives and
/// fmi2GetReal (S^2 is linear in them within a mode: the differences are exact but for
/// rounding), with the impact mass in flight and resting on a wall.
#[test]
fn directional_derivatives_in_flight_and_at_rest_are_the_differences() {
    // In flight: a state with everything moving; at rest: pressed onto +d/2 until the bounces
    // end, and a velocity the host set there (which the stored energy reads, the rates not).
    let flying = s2("me-s2-jacobian-flying", true, 0.8);
    let mut resting = Host::new(s2("me-s2-jacobian-resting", true, 0.8));
    resting.run(&[-2.0; 100]);
    let mut at_rest = resting.x.clone();
    at_rest[5] = 0.1;
    let cases = [
        (
            &Host::new(flying).inst,
            [
                vec![0.012, -0.03, 0.4, 0.1, 0.02, 0.15],
                vec![0.0; N - S2_STATES],
            ]
            .concat(),
            -0.3,
            "in flight",
        ),
        (&resting.inst, at_rest, -2.0, "at rest"),
    ];
    let u = unknowns();
    for (inst, x, a, what) in cases {
        let knowns: Vec<u32> = S2_NAMES
            .map(vr_of)
            .into_iter()
            .chain([vr::BASE_A])
            .collect();
        for (k, &known) in knowns.iter().enumerate() {
            unknown_values(inst, &x, a);
            let j = jacobian_column(inst, &u, known);
            let h = 1e-6;
            let (mut xp, mut xm, mut ap, mut am) = (x.clone(), x.clone(), a, a);
            if k < S2_STATES {
                xp[k] += h;
                xm[k] -= h;
            } else {
                ap += h;
                am -= h;
            }
            let (up, down) = (unknown_values(inst, &xp, ap), unknown_values(inst, &xm, am));
            for i in 0..u.len() {
                let fd = (up[i] - down[i]) / (2.0 * h);
                let tol = 1e-7 * (1.0 + fd.abs()) + 1e3 * f64::EPSILON * up[i].abs() / h;
                assert!(
                    (j[i] - fd).abs() <= tol,
                    "{what}: d[{}]/d[{known}] = {} by J d, {fd} by differences",
                    u[i],
                    j[i]
                );
            }
        }
    }
}

/// An FMU state saved with the impact mass resting on a wall (a discrete mode, not a
/// continuous state) restores into a new ME instance from its serialised bytes: the same
/// states, and the same continuation through the release and the flight to the other wall,
/// bit for bit, with the same events.
#[test]
fn a_resting_mass_saves_and_restores_with_its_mode() {
    let mut a = vec![-2.0; 100];
    // Still pressed for 0.1 s (a mass restored as flying would hit the wall again), then pulled.
    a.extend([-2.0; 10]);
    a.extend([2.0; 100]);
    let mut first = Host::new(s2("me-s2-save", true, 0.8));
    first.run(&a[..100]);
    let bytes = first.inst.serialised();
    let (saved, t) = (first.x.clone(), first.t);
    let events = first.events;
    let end = first.run(&a[100..]);

    let mut second = Host::new(s2("me-s2-restored", true, 0.8));
    let mut s = restore(&second.inst, &bytes);
    let (_, x) = second.inst.states(N);
    assert_eq!(x, saved);
    (second.t, second.x) = (t, x);
    let again = second.run(&a[100..]);
    assert_eq!(
        again
            .iter()
            .map(|r| r.map(f64::to_bits))
            .collect::<Vec<_>>(),
        end.iter().map(|r| r.map(f64::to_bits)).collect::<Vec<_>>()
    );
    assert_eq!(second.events, first.events - events);
    assert!(
        second.events > 3,
        "the release and new impacts: {}",
        second.events
    );
    assert_eq!(
        unsafe { second.inst.lib.fmi2FreeFMUstate(second.inst.c, &mut s) },
        OK
    );
}
