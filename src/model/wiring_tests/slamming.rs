//! Model = SloshingSlamming (S^2) against closed forms: the sloshing mode (mass Omega m_1,
//! frequency omega_1/sqrt(Omega)) as a linear oscillator, and the impact mass's flights between
//! impacts (straight lines with no input, parabolas under a held one) with restitution e, until
//! it rests on a wall, presses on it and is pulled off it again.

use super::*;

const CLEARANCE: f64 = 0.1;
const E: f64 = 0.4;
const MASS_RATIO: f64 = 0.01;

/// The impact mass per unit mass: position, velocity, contact, impacts, work, dissipated.
#[derive(Clone, Copy, Debug, Default)]
struct Impact {
    z: f64,
    v: f64,
    contact: i8,
    impacts: u64,
    work: f64,
    dissipated: f64,
}

impl Impact {
    /// Flight from the centre under a held `a` for `h`, reaching no wall: z = -a h^2/2.
    fn kick(&mut self, a: f64, h: f64) {
        let z = self.z + self.v * h - 0.5 * a * h * h;
        assert!(z.abs() < 0.5 * CLEARANCE);
        self.work += -a * (z - self.z);
        self.v -= a * h;
        self.z = z;
    }

    /// `h` with no input: straight flights from wall to wall, each impact reversing the
    /// velocity and keeping e of it.
    fn coast(&mut self, mut h: f64) {
        let half = 0.5 * CLEARANCE;
        while self.v != 0.0 {
            let wall = half.copysign(self.v);
            let t = (wall - self.z) / self.v;
            if t > h {
                self.z += self.v * h;
                return;
            }
            h -= t;
            self.z = wall;
            self.dissipated += 0.5 * self.v * self.v * (1.0 - E * E);
            self.v *= -E;
            self.impacts += 1;
        }
    }

    /// A held `a` that presses the mass onto a wall for long enough that it comes to rest
    /// there: it hits the wall at v1 (v1^2 = v^2 + 2|a| distance), and rebounds at e^k v1 until
    /// a rebound is slower than `rest` (1e-6 of the clearance per 1/omega_1), then rests. The
    /// base's work is -a dz, all the kinetic energy is dissipated.
    fn pressed(&mut self, a: f64, h: f64, rest: f64) {
        let wall = -a.signum();
        let half = 0.5 * CLEARANCE;
        let v1 = (self.v * self.v + 2.0 * a.abs() * (wall * half - self.z).abs()).sqrt();
        // Time to the first impact and the flights after it (each 2 e^k v1 / |a|).
        let t1 = (self.v - wall * v1) / a;
        let mut speed = E * v1;
        let mut k = 1;
        let mut time = t1;
        while speed >= rest {
            time += 2.0 * speed / a.abs();
            speed *= E;
            k += 1;
        }
        assert!(time < h, "not at rest within the step");
        self.work += -a * (wall * half - self.z);
        self.dissipated += 0.5 * self.v * self.v + -a * (wall * half - self.z);
        self.z = wall * half;
        self.v = 0.0;
        self.contact = wall as i8;
        self.impacts += k;
    }

    /// Pulled off the wall it may rest on by a held `a`, reaching no other wall within `h`.
    fn pulled(&mut self, a: f64, h: f64) {
        assert!(a * f64::from(self.contact) >= 0.0);
        self.contact = 0;
        self.kick(a, h);
    }
}

/// Run S^2 with `omega` (the parameter: 0 for the NSD law's) over a kick, a coast, a press to
/// rest, a pull off the wall and another coast, saving and restoring in flight and at rest.
fn slamming_run(omega_parameter: f64, omega: f64, tanks: f64) {
    let a_e = 0.004;
    let p = StartValues::default()
        .with(vr::MODEL, SLAMMING)
        .with(vr::TANKS, tanks)
        .with(vr::AMPLITUDE, FIXED)
        .with(vr::A_E, a_e)
        .with(vr::SLAMMING_OMEGA, omega_parameter)
        .with(vr::SLAMMING_RESTITUTION, E)
        .with(vr::SLAMMING_CLEARANCE, CLEARANCE)
        .with(vr::SLAMMING_MASS_RATIO, MASS_RATIO)
        .with(vr::SLOSH_X0, 0.004)
        .with(vr::SLOSH_V0, -0.01);
    let mut sim = damper(&p);
    let (m1, w1) = natural(1);
    let zeta = nsd_zeta(a_e);
    let slosh_mass = omega * m1 * tanks;
    let impact_mass = (MASS_RATIO + 1.0 - omega) * m1 * tanks;
    let inactive = (liquid() - (1.0 + MASS_RATIO) * m1) * tanks;
    let d = sim.derived();
    assert!((d.mass_slosh - (1.0 + MASS_RATIO) * m1 * tanks).abs() < 1e-12 * m1);
    assert!((d.mass_inactive - inactive).abs() < 1e-12 * m1);
    let rest = 1e-6 * CLEARANCE * w1;
    let mut mode = Mode {
        w: w1 / omega.sqrt(),
        x: 0.004,
        v: -0.01,
        ..Mode::default()
    };
    let mut imp = Impact::default();
    let initial = slosh_mass * mode.stored();
    // (step, held input, what the impact mass does, restore after).
    let mut plan: Vec<(f64, f64, u8, bool)> = vec![(0.05, 2.0, 0, false)];
    plan.extend((0..80).map(|k| (0.05, 0.0, 1, k == 40)));
    plan.push((2.0, -3.0, 2, true));
    plan.extend((0..4).map(|_| (0.05, 3.0, 3, false)));
    plan.extend((0..20).map(|_| (0.05, 0.0, 1, false)));
    let what = format!("S^2 Omega {omega_parameter}, {tanks} tanks");
    let mut history = History::new(&what);
    let mut t = 0.0;
    for (h, a, kind, restore) in plan {
        let inputs = Inputs {
            a,
            ..Inputs::default()
        };
        let impulse_before = sim.output(Output::ImpactImpulse, &inputs);
        sim.step(t, h, &inputs).expect("step");
        t += h;
        let (vs0, vi0) = (mode.v, imp.v);
        mode.held(zeta, a, h);
        match kind {
            0 => imp.kick(a, h),
            1 => imp.coast(h),
            2 => imp.pressed(a, h, rest),
            _ => imp.pulled(a, h),
        }
        let impulse =
            slosh_mass * (-(mode.v - vs0) - a * h) + impact_mass * (-(imp.v - vi0) - a * h);
        // impact.impulse: in a step without rest on a wall, the impact mass's part of the
        // step's impulse (force.mean h) is all the impacts'.
        if kind != 2 {
            let impacts = sim.output(Output::ImpactImpulse, &inputs) - impulse_before;
            let expected = impact_mass * (-(imp.v - vi0) - a * h);
            assert!(
                (impacts - expected).abs() <= 1e-12 * impact_mass,
                "{what} at t = {t}: impact.impulse grew by {impacts}, expected {expected}"
            );
        }
        let force = slosh_mass * mode.force(zeta);
        let work = slosh_mass * mode.work + impact_mass * imp.work;
        let stored = slosh_mass * mode.stored() + impact_mass * 0.5 * imp.v * imp.v;
        let dissipated = initial + work - stored;
        let rigid = if imp.contact != 0 { impact_mass } else { 0.0 };
        let read = Inputs {
            a: 0.4 - a,
            a_derivatives: [2.1, 0.0],
            ..Inputs::default()
        };
        let surface = surface_per_x();
        let mut e = Expected::default();
        for (which, value) in [
            (Output::Force, force),
            (Output::X, mode.x),
            (Output::V, mode.v),
            (Output::ForceMean, impulse / h),
            (Output::BaseShear, force - (inactive + rigid) * read.a),
            (Output::EnergyInput, initial + work),
            (Output::EnergyDissipated, dissipated),
            (Output::EnergyStored, stored),
            (Output::Amplitude, a_e),
            (Output::Zeta, zeta),
            (Output::ImpactZ, imp.z),
            (Output::Impacts, imp.impacts as f64),
            (Output::SurfaceLeft, surface * mode.x),
            (Output::SurfaceRight, -surface * mode.x),
        ] {
            e.set(which, value);
        }
        let c = 2.0 * zeta * mode.w;
        let acc = mode.acceleration(zeta, read.a);
        let rate_force = slosh_mass * (c * acc + mode.w * mode.w * mode.v);
        // The impact mass in flight is a free mass; resting, it moves with the tank.
        let free_v = if imp.contact == 0 { imp.v } else { 0.0 };
        let mut rates = [0.0; 14];
        for (which, value) in [
            (Output::Force, rate_force),
            (Output::X, mode.v),
            (Output::V, acc),
            (Output::BaseShear, rate_force - (inactive + rigid) * 2.1),
            (
                Output::EnergyInput,
                -read.a * (slosh_mass * mode.v + impact_mass * free_v),
            ),
            (Output::EnergyDissipated, slosh_mass * c * mode.v * mode.v),
            (
                Output::EnergyStored,
                slosh_mass * mode.v * (acc + mode.w * mode.w * mode.x)
                    - read.a * impact_mass * free_v,
            ),
            (Output::SurfaceLeft, surface * mode.v),
            (Output::SurfaceRight, -surface * mode.v),
        ] {
            rates[index(which)] = value;
        }
        e.rates = Some(rates);
        history.compare(&sim, &read, &e);
        // The impacts' dissipation is the impact mass's kinetic energy lost.
        let lost = impact_mass * imp.dissipated;
        let slosh_lost = dissipated - lost;
        assert!(
            slosh_lost > -1e-12 * initial.max(lost),
            "{what}: {slosh_lost}"
        );
        if restore {
            sim = reloaded(&sim, &p);
            history.compare(&sim, &read, &e);
        }
    }
    assert!(
        imp.impacts > 6,
        "{what}: the run has impacts ({})",
        imp.impacts
    );
    history.assert(1e-9);
}

/// Omega given, from the NSD law (Omega = 1/kappa^2, kappa = 1.075 Lambda^0.007 below
/// Lambda = 0.03), and above 1 (taken as 1).
#[test]
fn slamming_outputs_are_the_closed_form_flights() {
    slamming_run(0.9, 0.9, 1.0);
    let kappa = 1.075 * (0.004 / A).powf(0.007);
    slamming_run(0.0, 1.0 / (kappa * kappa), 2.0);
    slamming_run(1.5, 1.0, 1.0);
}

/// A saved S^2 state whose impact mass is out of range is refused; one at the walls' limits is
/// taken.
#[test]
fn slamming_states_out_of_range_are_refused() {
    let p = StartValues::default()
        .with(vr::MODEL, SLAMMING)
        .with(vr::SLAMMING_OMEGA, 0.9)
        .with(vr::SLAMMING_CLEARANCE, CLEARANCE);
    let sim = damper(&p);
    let good = sim.snapshot();
    // The impact mass's numbers follow the sloshing mode's four: z, v, contact, impacts, ...
    let with = |i: usize, value: f64| {
        let mut s = good.clone();
        s[4 + i] = value;
        Damper::restore(&p, &s)
    };
    for (i, value) in [
        (0, 0.05),
        (0, -0.05),
        (2, 1.0),
        (2, -1.0),
        (3, 0.0),
        (3, 7.0),
    ] {
        let r = with(i, value);
        assert!(r.is_ok(), "z/contact/impacts {i} = {value}: {r:?}");
    }
    for (i, value) in [
        (0, 0.0501),
        (0, -0.0501),
        (2, 0.5),
        (2, 2.0),
        (3, -1.0),
        (3, 2.5),
    ] {
        assert!(with(i, value).is_err(), "{i} = {value} taken");
    }
    let restored = with(0, 0.05).expect("at the wall");
    assert_eq!(restored.output(Output::ImpactZ, &Inputs::default()), 0.05);
    let restored = with(3, 7.0).expect("impacts");
    assert_eq!(restored.output(Output::Impacts, &Inputs::default()), 7.0);
}
