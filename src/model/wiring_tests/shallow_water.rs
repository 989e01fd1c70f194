//! Model = ShallowWater in its linear limit: a small fundamental-mode slosh decays as the
//! linear mode of Eqs 2.1, 2.2 (mass m_1, frequency omega_1, damping zeta from the drag) in
//! closed form, and its outputs are that mode's; with the balances the model keeps exactly
//! (input = initial + work, dissipated = input - stored, h force.mean = -M_l int a dt -
//! m_1 dv per tank, base_shear = force with no inactive mass).

use super::*;

const SHALLOW_WATER: f64 = 5.0;

/// Free decay of a small fundamental-mode slosh (the waves 0.8 % of the depth): slosh.x,
/// slosh.v, force against the linear mode to 1 % of their largest values (the scheme's
/// dispersion and diffusion at 150 cells, the waves' nonlinearity: 0.35 % seen), energy and
/// wall heights to 5 %; the balances and the parameters' outputs to round-off. (A held input
/// would excite the higher modes, which the force and the wall heights show.)
#[test]
fn shallow_water_small_slosh_is_the_linear_mode() {
    let tanks = 2.0;
    let (zeta, x0, v0) = (0.03, 0.0005, 0.002);
    let p = StartValues::default()
        .with(vr::MODEL, SHALLOW_WATER)
        .with(vr::TANKS, tanks)
        .with(vr::DAMPING, CONSTANT)
        .with(vr::ZETA, zeta)
        .with(vr::AMPLITUDE, FIXED)
        .with(vr::A_E, 0.002)
        .with(vr::SLOSH_X0, x0)
        .with(vr::SLOSH_V0, v0);
    let mut sim = damper(&p);
    let (m1, w) = natural(1);
    let (mass, liquid) = (m1 * tanks, liquid() * tanks);
    let d = sim.derived();
    assert_eq!((d.mass_slosh, d.mass_inactive), (liquid, 0.0));
    let mut mode = Mode {
        w,
        x: x0,
        v: v0,
        work: 0.0,
    };
    let none = Inputs::default();
    // At the start: the fundamental mode with the first moment m_1 x0 and momentum m_1 v0.
    assert!((sim.output(Output::X, &none) - x0).abs() < 1e-4 * x0);
    assert!((sim.output(Output::V, &none) - v0).abs() < 1e-4 * v0);
    let initial = sim.output(Output::EnergyStored, &none);
    assert!(
        (initial - mass * mode.stored()).abs() < 5e-2 * initial,
        "{initial}"
    );
    let mut history = History::new("ShallowWater, linear limit");
    let mut shapes = History::new("ShallowWater, energy and wall heights");
    let mut exact = History::new("ShallowWater, balances");
    let h = 0.01;
    let mut t = 0.0;
    for k in 0..300 {
        let a = 0.0;
        let inputs = Inputs {
            a,
            ..Inputs::default()
        };
        let v_before = sim.output(Output::V, &none);
        sim.step(t, h, &inputs).expect("step");
        t += h;
        mode.held(zeta, a, h);
        let out = |o| sim.output(o, &inputs);
        let mut e = Expected::default();
        let mut shape = Expected::default();
        for which in OUTPUTS {
            e.set(which, out(which));
            shape.set(which, out(which));
        }
        let force = mass * mode.force(zeta);
        let surface = surface_per_x();
        for (which, value) in [
            (Output::Force, force),
            (Output::X, mode.x),
            (Output::V, mode.v),
            (Output::BaseShear, force),
            (Output::EnergyInput, initial),
            (Output::Amplitude, 0.002),
            (Output::Zeta, zeta),
            (Output::ImpactZ, 0.0),
            (Output::Impacts, 0.0),
        ] {
            e.set(which, value);
        }
        // The energy's modal mass is the shallow-water one, 8 M_l/pi^3, 2.2 % above Eq 2.1's
        // at this depth, and the wall heights are extrapolated from the cells: 5 %.
        for (which, value) in [
            (Output::EnergyStored, mass * mode.stored()),
            (Output::SurfaceLeft, surface * mode.x),
            (Output::SurfaceRight, -surface * mode.x),
        ] {
            shape.set(which, value);
        }
        shapes.compare(&sim, &inputs, &shape);
        history.compare(&sim, &inputs, &e);
        let mut balance = Expected::default();
        let v_now = out(Output::V);
        for which in OUTPUTS {
            balance.set(which, out(which));
        }
        let input = out(Output::EnergyInput);
        balance.set(Output::EnergyDissipated, input - out(Output::EnergyStored));
        balance.set(
            Output::ForceMean,
            (-liquid * a * h - mass * (v_now - v_before)) / h,
        );
        balance.set(Output::BaseShear, out(Output::Force));
        exact.compare(&sim, &inputs, &balance);
        if k == 150 {
            sim = reloaded(&sim, &p);
            exact.compare(&sim, &inputs, &balance);
            history.compare(&sim, &inputs, &e);
            shapes.compare(&sim, &inputs, &shape);
        }
    }
    history.assert(0.01);
    shapes.assert(0.05);
    exact.assert(1e-12);
}
