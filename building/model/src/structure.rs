//! The linear shear building: storey masses and stiffnesses, the damper's inactive mass on its
//! floor, Rayleigh damping fixed at the first two modes, and its first-order form. Nothing here
//! knows FMI.
//!
//! Displacements `u` are relative to the ground; the equation of motion, with `a_g` the ground
//! acceleration and `F` the floor forces (wind, the damper's force on its floor):
//!
//! ```text
//! M u'' + C u' + K u = F - M 1 a_g,      absolute accelerations  a = u'' + 1 a_g = M^-1 (F - C u' - K u)
//! ```
//! K is tridiagonal (storey i joins floor i-1 to floor i, floor 0 being the ground) and
//! C = alpha M + beta K with zeta_i = alpha / (2 omega_i) + beta omega_i / 2 at modes 1 and 2.
//! The state adds the ground's velocity and displacement (x_g' = v_g, v_g' = a_g) so that the
//! damper's floor can report its absolute motion.
//!
//! The ground acceleration is the input's plus a built-in harmonic motion, the ground
//! displacement A sin(w t) (velocity A w cos(w t), acceleration -A w^2 sin(w t)): a second
//! oscillator in the state, h' = v_h, v_h' = -w^2 h, from h = 0, v_h = A w, so that
//! a_g = a_in - w^2 h. Being part of the linear system it is advanced by the same exact step as
//! the building: its response has no time-stepping error. x_g, v_g are the ground's whole
//! motion (the input's, integrated from rest, plus the harmonic's): v_g starts at A w.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Most storeys a building may have.
pub const MAX_STOREYS: usize = 20;

/// What a building is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// Floor masses, ground up (kg).
    pub masses: Vec<f64>,
    /// Storey stiffnesses, ground up (N/m): storey i joins floor i-1 (0: ground) and floor i.
    pub stiffnesses: Vec<f64>,
    /// Damping ratios of modes 1 and 2.
    pub zeta: [f64; 2],
    /// The floor carrying the damper, 1-based.
    pub damper_floor: usize,
    /// The damper's mass moving rigidly with its floor (TLD.fmu's mass.inactive, kg).
    pub damper_mass: f64,
    /// The built-in ground motion.
    pub ground: Harmonic,
}

/// The first mode, normalised to 1 at the damper's floor (Building::first_mode).
#[derive(Clone, Debug, PartialEq)]
pub struct FirstMode {
    pub shape: Vec<f64>,
    /// Generalised mass [kg], circular frequency [rad/s], damping ratio, participation [kg].
    pub mass: f64,
    pub omega: f64,
    pub damping: f64,
    pub participation: f64,
}

/// A harmonic ground displacement x_g = amplitude sin(omega t).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Harmonic {
    /// m (0: none).
    pub amplitude: f64,
    /// rad/s.
    pub omega: f64,
}

/// A configured building: its matrices, modes and damping.
#[derive(Clone, Debug)]
pub struct Building {
    pub n: usize,
    /// Floor masses with the damper's inactive mass added to its floor.
    pub mass: DVector<f64>,
    pub stiffness: DMatrix<f64>,
    pub damping: DMatrix<f64>,
    /// The storey stiffnesses as given (storey 1 is the base shear's spring).
    pub storeys: Vec<f64>,
    /// Circular frequencies of all modes, ascending (rad/s).
    pub omega: Vec<f64>,
    /// Rayleigh coefficients: C = alpha M + beta K.
    pub alpha: f64,
    pub beta: f64,
    /// 0-based index of the damper's floor.
    pub damper: usize,
    /// The built-in ground motion.
    pub ground: Harmonic,
}

impl Building {
    pub fn new(d: &Design) -> Result<Self, String> {
        let n = d.masses.len();
        if n == 0 || n > MAX_STOREYS || d.stiffnesses.len() != n {
            return Err(format!(
                "{n} storeys: 1 to {MAX_STOREYS}, with a mass and a stiffness each"
            ));
        }
        if !(1..=n).contains(&d.damper_floor) {
            return Err(format!(
                "tld.floor = {} is not a floor of the {n}-storey building (1..{n})",
                d.damper_floor
            ));
        }
        let positive = |x: &f64| x.is_finite() && *x > 0.0;
        if !d.masses.iter().all(positive) || !d.stiffnesses.iter().all(positive) {
            return Err("storey masses and stiffnesses must be positive and finite".into());
        }
        if !(d.damper_mass.is_finite() && d.damper_mass >= 0.0) {
            return Err(format!("tld.mass = {} must be >= 0", d.damper_mass));
        }
        let Harmonic { amplitude, omega } = d.ground;
        if !(amplitude.is_finite() && omega.is_finite() && omega >= 0.0) {
            return Err(format!(
                "ground.amplitude = {amplitude}, ground.omega = {omega}: finite, omega >= 0"
            ));
        }
        let mut mass = DVector::from_column_slice(&d.masses);
        mass[d.damper_floor - 1] += d.damper_mass;
        let k = &d.stiffnesses;
        let stiffness = DMatrix::from_fn(n, n, |i, j| {
            let above = if i + 1 < n { k[i + 1] } else { 0.0 };
            match (i, j) {
                _ if i == j => k[i] + above,
                _ if j == i + 1 => -k[j],
                _ if i == j + 1 => -k[i],
                _ => 0.0,
            }
        });
        let omega = frequencies(&mass, &stiffness);
        let (alpha, beta) = rayleigh(&omega, d.zeta)?;
        let damping = DMatrix::from_diagonal(&mass) * alpha + &stiffness * beta;
        Ok(Building {
            n,
            mass,
            stiffness,
            damping,
            storeys: d.stiffnesses.clone(),
            omega,
            alpha,
            beta,
            damper: d.damper_floor - 1,
            ground: d.ground,
        })
    }

    /// The first mode as a damper designer sees it from the damper's floor: the shape
    /// normalised to 1 there, the generalised (modal) mass phi^T M phi, the frequency, the
    /// damping ratio phi^T C phi / (2 omega phi^T M phi) and the participation factor
    /// L = phi^T M 1 (the modal force of a ground acceleration a_g is -L a_g).
    pub fn first_mode(&self) -> Result<FirstMode, String> {
        let n = self.n;
        let s = self.mass.map(|m| 1.0 / m.sqrt());
        let scaled = DMatrix::from_fn(n, n, |i, j| self.stiffness[(i, j)] * s[i] * s[j]);
        let eig = SymmetricEigen::new(scaled);
        let k = (0..n)
            .min_by(|a, b| eig.eigenvalues[*a].total_cmp(&eig.eigenvalues[*b]))
            .ok_or("no storeys")?;
        let shape = eig.eigenvectors.column(k).component_mul(&s);
        let at = shape[self.damper];
        if at.abs() < 1e-9 * shape.amax() {
            return Err(format!(
                "floor {} does not move in the first mode: no damper works there",
                self.damper + 1
            ));
        }
        let shape = shape / at;
        let mass = shape.dot(&shape.component_mul(&self.mass));
        let omega = eig.eigenvalues[k].max(0.0).sqrt();
        let damping = shape.dot(&(&self.damping * &shape)) / (2.0 * omega * mass);
        let participation = shape.dot(&self.mass);
        Ok(FirstMode {
            shape: shape.iter().copied().collect(),
            mass,
            omega,
            damping,
            participation,
        })
    }

    /// Dimension of the first-order state [u, u', x_g, v_g, h, v_h].
    pub fn states(&self) -> usize {
        2 * self.n + 4
    }

    /// The state at t = 0: the building at rest relative to the ground, the ground at its
    /// place, moving with the built-in motion's velocity A w.
    pub fn initial_state(&self) -> Vec<f64> {
        let n = self.n;
        let mut z = vec![0.0; self.states()];
        let v0 = self.ground.amplitude * self.ground.omega;
        z[2 * n + 1] = v0;
        z[2 * n + 3] = v0;
        z
    }

    /// The ground's acceleration in the state `z` with `input` the input's (ground.a): the
    /// input's plus the built-in motion's, -w^2 h.
    pub fn ground_acceleration(&self, z: &[f64], input: f64) -> f64 {
        let w = self.ground.omega;
        input - w * w * z[2 * self.n + 2]
    }

    /// Number of input channels [a_g, F_1..F_n].
    pub fn channels(&self) -> usize {
        self.n + 1
    }

    /// The first-order system z' = A z + B p with z = [u, u', x_g, v_g, h, v_h], p = [a_in, F]:
    /// the ground acceleration a_g = a_in - w^2 h enters u'' and v_g', the oscillator
    /// h'' = -w^2 h is free.
    pub fn state_space(&self) -> (DMatrix<f64>, DMatrix<f64>) {
        let n = self.n;
        let (s, m) = (self.states(), self.channels());
        let mut a = DMatrix::zeros(s, s);
        let mut b = DMatrix::zeros(s, m);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for j in 0..n {
                a[(n + i, j)] = -self.stiffness[(i, j)] / self.mass[i];
                a[(n + i, n + j)] = -self.damping[(i, j)] / self.mass[i];
            }
            b[(n + i, 0)] = -1.0;
            b[(n + i, 1 + i)] = 1.0 / self.mass[i];
        }
        let (h, w2) = (2 * n + 2, self.ground.omega * self.ground.omega);
        // a_g = a_in - w^2 h: -a_g in every u'', +a_g in v_g'
        for i in 0..n {
            a[(n + i, h)] = w2;
        }
        a[(2 * n, 2 * n + 1)] = 1.0;
        b[(2 * n + 1, 0)] = 1.0;
        a[(2 * n + 1, h)] = -w2;
        a[(h, h + 1)] = 1.0;
        a[(h + 1, h)] = -w2;
        (a, b)
    }

    /// Absolute floor accelerations M^-1 (F - C u' - K u) for the state `z` and floor forces `f`.
    pub fn accelerations(&self, z: &[f64], f: &[f64]) -> Vec<f64> {
        let n = self.n;
        (0..n)
            .map(|i| {
                let inner: f64 = (0..n)
                    .map(|j| self.damping[(i, j)] * z[n + j] + self.stiffness[(i, j)] * z[j])
                    .sum();
                (f[i] - inner) / self.mass[i]
            })
            .collect()
    }

    /// Base shear: the force of storey 1's spring and of the damping forces to the ground,
    /// 1^T (K u + C u') = k_1 u_1 + 1^T C u' (linear: its rate is this of u' and u'').
    pub fn base_shear(&self, u: &[f64], v: &[f64]) -> f64 {
        let damping: f64 = (0..self.n)
            .map(|j| self.damping.column(j).sum() * v[j])
            .sum();
        self.storeys[0] * u[0] + damping
    }
}

/// Circular frequencies of K phi = omega^2 M phi, ascending: the eigenvalues of the symmetric
/// M^-1/2 K M^-1/2.
fn frequencies(mass: &DVector<f64>, stiffness: &DMatrix<f64>) -> Vec<f64> {
    let n = mass.len();
    let scaled = DMatrix::from_fn(n, n, |i, j| stiffness[(i, j)] / (mass[i] * mass[j]).sqrt());
    let mut w: Vec<f64> = SymmetricEigen::new(scaled)
        .eigenvalues
        .iter()
        .map(|l| l.max(0.0).sqrt())
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

/// Rayleigh coefficients (alpha, beta) giving damping ratios `zeta` at the first two modes; a
/// one-storey building has one mode, damped by zeta[0] half through its mass and half through
/// its stiffness.
pub fn rayleigh(omega: &[f64], zeta: [f64; 2]) -> Result<(f64, f64), String> {
    let [z1, z2] = zeta;
    let (alpha, beta) = match omega {
        [w] => (z1 * w, z1 / w),
        [w1, w2, ..] => {
            let d = w2 * w2 - w1 * w1;
            (
                2.0 * w1 * w2 * (z1 * w2 - z2 * w1) / d,
                2.0 * (z2 * w2 - z1 * w1) / d,
            )
        }
        [] => return Err("no storeys".into()),
    };
    if !(alpha >= 0.0 && beta >= 0.0 && alpha.is_finite() && beta.is_finite()) {
        return Err(format!(
            "Rayleigh damping with zeta1 = {z1} and zeta2 = {z2} at {:.4} and {:.4} rad/s would \
             need a negative coefficient (alpha = {alpha:.4e}, beta = {beta:.4e}): higher modes \
             would be undamped or excited; choose zeta2/zeta1 between omega1/omega2 and omega2/omega1",
            omega[0],
            omega.get(1).copied().unwrap_or(omega[0])
        ));
    }
    Ok((alpha, beta))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_storeys(zeta: [f64; 2]) -> Building {
        Building::new(&Design {
            masses: vec![2.0, 1.0],
            stiffnesses: vec![300.0, 100.0],
            zeta,
            damper_floor: 2,
            damper_mass: 0.5,
            ground: Harmonic {
                amplitude: 0.02,
                omega: 3.0,
            },
        })
        .expect("a valid design")
    }

    /// The first mode from the damper's floor against closed forms: one storey (M = m,
    /// omega^2 = k/m, L = m); two equal storeys (m, k): omega^2 = (3 - sqrt 5)/2 k/m, roof
    /// normalised shape [(sqrt 5 - 1)/2, 1], M = m (1 + 0.382), L = m (1.618); normalised at
    /// floor 1 instead, everything scales by 1/0.618 (M by its square).
    #[test]
    fn first_mode_against_closed_forms() {
        let one = |floor: usize, masses: Vec<f64>, stiffnesses: Vec<f64>| {
            Building::new(&Design {
                masses,
                stiffnesses,
                zeta: [0.02, 0.03],
                damper_floor: floor,
                damper_mass: 0.0,
                ground: Harmonic::default(),
            })
            .expect("valid")
            .first_mode()
            .expect("mode")
        };
        let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-12;
        let m = one(1, vec![3.0e5], vec![2.0e7]);
        assert!(close(m.mass, 3.0e5) && close(m.participation, 3.0e5));
        assert!(close(m.omega, (2.0e7_f64 / 3.0e5).sqrt()) && close(m.damping, 0.02));
        let (mm, kk) = (5.0e4, 8.0e6);
        let r = (5.0_f64.sqrt() - 1.0) / 2.0;
        let roof = one(2, vec![mm, mm], vec![kk, kk]);
        assert!(close(
            roof.omega,
            ((3.0 - 5.0_f64.sqrt()) / 2.0 * kk / mm).sqrt()
        ));
        assert!(close(roof.shape[0], r) && close(roof.shape[1], 1.0));
        assert!(close(roof.mass, mm * (1.0 + r * r)));
        assert!(close(roof.participation, mm * (1.0 + r)));
        // Rayleigh damping fixed at mode 1: its ratio comes back.
        assert!(close(roof.damping, 0.02), "{}", roof.damping);
        let low = one(1, vec![mm, mm], vec![kk, kk]);
        assert!(close(low.mass, roof.mass / (r * r)));
        assert!(close(low.participation, roof.participation / r));
        assert!(close(low.omega, roof.omega));
    }

    /// Two storeys: omega^2 are the roots of det(K - w^2 M) = 0, written out by hand.
    #[test]
    fn two_storey_frequencies_are_the_roots_of_the_characteristic_polynomial() {
        let b = two_storeys([0.02, 0.02]);
        let (m1, m2, k1, k2) = (2.0_f64, 1.5, 300.0, 100.0);
        // m1 m2 w^4 - (m1 k2 + m2 (k1 + k2)) w^2 + k1 k2 = 0
        let (qa, qb, qc) = (m1 * m2, -(m1 * k2 + m2 * (k1 + k2)), k1 * k2);
        let disc = (qb * qb - 4.0 * qa * qc).sqrt();
        let want = [(-qb - disc) / (2.0 * qa), (-qb + disc) / (2.0 * qa)].map(f64::sqrt);
        for (w, want) in b.omega.iter().zip(want) {
            assert!((w - want).abs() < 1e-12 * want, "{w} vs {want}");
        }
    }

    /// Rayleigh damping gives each of the first two modes its ratio: phi^T C phi /
    /// (2 w phi^T M phi) = zeta_i for the mode shapes phi.
    #[test]
    fn rayleigh_damping_gives_each_mode_its_ratio() {
        let zeta = [0.02, 0.035];
        let b = two_storeys(zeta);
        let m = DMatrix::from_diagonal(&b.mass);
        for (i, w) in b.omega.iter().enumerate() {
            // (K - w^2 M) phi = 0 with phi = [1, x]: first row gives x.
            let x = (b.stiffness[(0, 0)] - w * w * b.mass[0]) / -b.stiffness[(0, 1)];
            let phi = DVector::from_vec(vec![1.0, x]);
            let c = (phi.transpose() * &b.damping * &phi)[0];
            let mm = (phi.transpose() * &m * &phi)[0];
            let got = c / (2.0 * w * mm);
            assert!((got - zeta[i]).abs() < 1e-12, "mode {}: {got}", i + 1);
        }
    }

    /// The first-order system's acceleration rows are the absolute accelerations less a_g,
    /// the ground's a_in plus the built-in motion's -w^2 h, and the oscillator is free.
    #[test]
    fn state_space_agrees_with_the_accelerations() {
        let b = two_storeys([0.02, 0.03]);
        let (a, bm) = b.state_space();
        let z = [0.01, -0.02, 0.3, 0.1, 0.5, -0.2, 0.004, -0.05];
        let (a_in, f) = (0.7, [3.0, -1.0]);
        let p = DVector::from_vec(vec![a_in, f[0], f[1]]);
        let dz = &a * DVector::from_column_slice(&z) + &bm * &p;
        let acc = b.accelerations(&z, &f);
        let ag = b.ground_acceleration(&z, a_in);
        assert_eq!(ag, a_in - 9.0 * 0.004);
        for i in 0..2 {
            assert!((dz[2 + i] - (acc[i] - ag)).abs() < 1e-12);
            assert_eq!(dz[i], z[2 + i]);
        }
        assert_eq!((dz[4], dz[5]), (z[5], ag));
        assert_eq!((dz[6], dz[7]), (z[7], -9.0 * z[6]));
    }

    /// The built-in ground motion alone, stepped exactly: the ground's state is
    /// x_g = A sin(w t), v_g = A w cos(w t) at every step (the building's response to it is
    /// the slave's tests').
    #[test]
    fn the_built_in_ground_motion_is_a_sine_from_its_initial_state() {
        let b = two_storeys([0.02, 0.03]);
        let (a, bm) = b.state_space();
        let (amp, w, h) = (b.ground.amplitude, b.ground.omega, 0.037);
        let prop = crate::propagator::Propagator::new(&a, &bm, h);
        let mut z = b.initial_state();
        let mut next = z.clone();
        let p = vec![0.0; 3 * b.channels()];
        for k in 1..=400 {
            prop.advance(&z, &p, &mut next);
            std::mem::swap(&mut z, &mut next);
            let t = k as f64 * h;
            let (x, v) = (amp * (w * t).sin(), amp * w * (w * t).cos());
            assert!((z[4] - x).abs() < 1e-14 && (z[6] - x).abs() < 1e-14, "{k}");
            assert!((z[5] - v).abs() < 1e-13 && (z[7] - v).abs() < 1e-13, "{k}");
        }
    }

    #[test]
    fn designs_that_cannot_be_built_say_why() {
        let bad = |d: Design| Building::new(&d).err().unwrap_or_default();
        let good = Design {
            masses: vec![1.0, 1.0],
            stiffnesses: vec![10.0, 10.0],
            zeta: [0.02, 0.02],
            damper_floor: 2,
            damper_mass: 0.0,
            ground: Harmonic::default(),
        };
        assert!(
            bad(Design {
                damper_floor: 3,
                ..good.clone()
            })
            .contains("tld.floor = 3")
        );
        assert!(
            bad(Design {
                masses: vec![1.0, 0.0],
                ..good.clone()
            })
            .contains("positive")
        );
        assert!(
            bad(Design {
                zeta: [0.01, 0.5],
                ..good.clone()
            })
            .contains("negative coefficient")
        );
        assert!(
            bad(Design {
                ground: Harmonic {
                    amplitude: 1e-3,
                    omega: -1.0
                },
                ..good.clone()
            })
            .contains("ground.omega = -1")
        );
        assert!(Building::new(&good).is_ok());
    }
}
