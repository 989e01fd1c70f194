//! The shear building's structure (structure.rs) against closed forms beyond the two-storey
//! cases of its own tests: a damper floor that the first mode hardly moves, and the first-order
//! system's layout and equation of motion for 1, 3 and 4 storeys (where 2 n and 2 + n differ).

use crate::structure::{Building, Design, Harmonic};
use nalgebra::DVector;

/// A damper floor that hardly moves in the first mode is refused, one that moves little is
/// taken: two storeys of mass m, the lower far stiffer (k1 >> k2), where the first mode has
/// phi_1/phi_2 = k2/(k1 + k2 - w^2 m), w^2 the smaller root of det(K - w^2 M) = 0 (written
/// out by hand). At k1/k2 = 1e8 floor 1 moves about 1e-8 of floor 2 (taken: the shape
/// normalised at floor 1 has floor 2 at the inverse ratio); at 1e10, 1e-10 (refused, below
/// 1e-9 of the largest component). Masses of 1e4 kg make the unnormalised shape's largest
/// component 1e-2, so that a threshold of 1e-9 / amax (for 1e-9 amax) refuses the first too.
#[test]
fn a_damper_floor_still_in_the_first_mode_is_refused() {
    let (m, k2) = (1.0e4, 1.0e6);
    let build = |k1: f64| {
        Building::new(&Design {
            masses: vec![m, m],
            stiffnesses: vec![k1, k2],
            zeta: [0.02, 0.03],
            damper_floor: 1,
            damper_mass: 0.0,
            ground: Harmonic::default(),
        })
        .expect("valid")
        .first_mode()
    };
    let ratio = |k1: f64| {
        // det = m^2 w^4 - m (k1 + 2 k2) w^2 + k1 k2 = 0, the smaller root.
        let (b, c) = (m * (k1 + 2.0 * k2), k1 * k2);
        let w2 = 2.0 * c / (b + (b * b - 4.0 * m * m * c).sqrt());
        k2 / (k1 + k2 - w2 * m)
    };
    let taken = build(1.0e14).expect("floor 1 moves 1e-8 of floor 2");
    let want = 1.0 / ratio(1.0e14);
    assert!((taken.shape[0] - 1.0).abs() < 1e-15);
    assert!(
        (taken.shape[1] / want - 1.0).abs() < 1e-6,
        "{} vs {want}",
        taken.shape[1]
    );
    let why = build(1.0e16).expect_err("floor 1 moves 1e-10 of floor 2");
    assert!(
        why.contains("floor 1 does not move in the first mode"),
        "{why}"
    );
}

/// The first-order state is [u, u', x_g, v_g, h, v_h] for any number of storeys: 2 n + 4
/// values, at rest but for the ground's velocity and the built-in motion's, both A w; the
/// ground acceleration reads h from it (w = 1.7: w^2 is not 2 w).
#[test]
fn the_state_holds_each_floor_twice_then_the_ground_and_its_motion() {
    let ground = Harmonic {
        amplitude: 0.03,
        omega: 1.7,
    };
    for n in [1, 3, 4] {
        let b = Building::new(&Design {
            masses: vec![1.0e4; n],
            stiffnesses: vec![2.0e6; n],
            zeta: [0.02, 0.03],
            damper_floor: n,
            damper_mass: 0.0,
            ground,
        })
        .expect("valid");
        assert_eq!(b.states(), 2 * n + 4);
        let mut want = vec![0.0; 2 * n + 4];
        want[2 * n + 1] = 0.03 * 1.7;
        want[2 * n + 3] = 0.03 * 1.7;
        assert_eq!(b.initial_state(), want, "{n} storeys");
        // a_g = the input's + the built-in motion's -w^2 h (h the state's 2n + 3rd).
        want[2 * n + 2] = 0.004;
        let a_g = b.ground_acceleration(&want, 0.25);
        assert!((a_g - (0.25 - 1.7 * 1.7 * 0.004)).abs() < 1e-15, "{a_g}");
    }
}

/// z' = A z + B p for 1, 3 and 4 equal storeys (mass m, stiffness k) against the equation
/// of motion written out: u' = v; m v_i' = F_i - (K u)_i - (C v)_i - m a_g with
/// (K u)_i = k (2 u_i - u_(i-1) - u_(i+1)) (u_0 = 0; the top floor k (u_n - u_(n-1))),
/// C = alpha M + beta K; x_g' = v_g, v_g' = a_g, h' = v_h, v_h' = -w^2 h, a_g = a_in - w^2 h.
/// (structure.rs's two-storey test cannot tell 2 n from 2 + n.)
#[test]
fn state_space_is_the_equation_of_motion_for_any_storeys() {
    let (m, k, w) = (1.0e4, 2.0e6, 1.7);
    for n in [1, 3, 4] {
        let b = Building::new(&Design {
            masses: vec![m; n],
            stiffnesses: vec![k; n],
            zeta: [0.02, 0.03],
            damper_floor: n,
            damper_mass: 0.0,
            ground: Harmonic {
                amplitude: 0.03,
                omega: w,
            },
        })
        .expect("valid");
        let z: Vec<f64> = (0..2 * n + 4)
            .map(|i| 0.01 * (i as f64 + 1.0).sqrt())
            .collect();
        let f: Vec<f64> = (0..n).map(|i| 300.0 - 170.0 * i as f64).collect();
        let a_in = 0.6;
        let (a, bm) = b.state_space();
        let mut p = vec![a_in];
        p.extend(&f);
        let dz = &a * DVector::from_column_slice(&z) + &bm * DVector::from_vec(p);
        let ku = |u: &[f64], i: usize| {
            let below = if i == 0 { 0.0 } else { u[i - 1] };
            let above = if i + 1 < n { u[i + 1] } else { u[i] };
            k * (2.0 * u[i] - below - above)
        };
        let (u, v) = (&z[..n], &z[n..2 * n]);
        let a_g = a_in - w * w * z[2 * n + 2];
        for i in 0..n {
            assert_eq!(dz[i], v[i], "{n} storeys: u'[{i}]");
            let c_v = b.alpha * m * v[i] + b.beta * ku(v, i);
            let want = (f[i] - ku(u, i) - c_v) / m - a_g;
            assert!((dz[n + i] - want).abs() < 1e-12, "{n} storeys: v'[{i}]");
        }
        let g = 2 * n;
        assert_eq!(dz[g], z[g + 1], "{n} storeys: x_g'");
        assert!((dz[g + 1] - a_g).abs() < 1e-15, "{n} storeys: v_g'");
        assert_eq!(dz[g + 2], z[g + 3], "{n} storeys: h'");
        assert!(
            (dz[g + 3] + w * w * z[g + 2]).abs() < 1e-15,
            "{n} storeys: v_h'"
        );
    }
}

/// Base shear 1^T (K u + C v) in closed form: K's columns sum to 0 but the first's, k_1, so
/// 1^T K u = k_1 u_1, and with C = alpha M + beta K, 1^T C v = alpha sum m_i v_i + beta k_1 v_1
/// (three storeys of their own masses and stiffnesses).
#[test]
fn base_shear_is_the_first_storeys_spring_and_the_damping_to_the_ground() {
    let (masses, stiffnesses) = (vec![3.0e4, 2.0e4, 1.5e4], vec![5.0e6, 3.0e6, 2.0e6]);
    let b = Building::new(&Design {
        masses: masses.clone(),
        stiffnesses: stiffnesses.clone(),
        zeta: [0.02, 0.03],
        damper_floor: 3,
        damper_mass: 0.0,
        ground: Harmonic::default(),
    })
    .expect("valid");
    let (u, v) = ([0.012, 0.019, 0.031], [-0.05, 0.02, 0.07]);
    let momentum: f64 = masses.iter().zip(v).map(|(m, v)| m * v).sum();
    let want = stiffnesses[0] * u[0] + b.alpha * momentum + b.beta * stiffnesses[0] * v[0];
    let got = b.base_shear(&u, &v);
    assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
    assert!(b.alpha * momentum != 0.0 && b.beta != 0.0);
}
