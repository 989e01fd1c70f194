//! The exact step of a linear system z' = A z + B p(t) whose input is a polynomial over the
//! step, p(t0 + s) = p0 + p1 s + p2 s^2/2: z(t0 + h) = Phi z0 + G0 p0 + G1 p1 + G2 p2 with
//! Phi = e^{Ah} and Gk = int_0^h e^{A(h-s)} B s^k/k! ds. All four come from one matrix
//! exponential of the augmented (Van Loan) matrix
//!
//! ```text
//!     | A  B  0  0 |
//! E = | 0  0  I  0 |  h,     e^E = | Phi G0 G1 G2 |  in its first block row,
//!     | 0  0  0  I |                    | ...          |
//!     | 0  0  0  0 |
//! ```
//! the system's state augmented by the input and its derivatives (q0' = q1, q1' = q2,
//! q2' = 0). Exact up to the rounding of the exponential (scaling and squaring with a Pade
//! approximant): a coupled run's error is its coupling's alone.

use nalgebra::{DMatrix, DVectorView, DVectorViewMut};

/// Derivatives of the input beyond its value that a step uses (orders 1 and 2).
pub const ORDERS: usize = 2;

/// The exact step over one step size.
#[derive(Clone, Debug)]
pub struct Propagator {
    pub h: f64,
    phi: DMatrix<f64>,
    /// G0, G1, G2 side by side: states x (ORDERS + 1) channels.
    gamma: DMatrix<f64>,
}

impl Propagator {
    pub fn new(a: &DMatrix<f64>, b: &DMatrix<f64>, h: f64) -> Self {
        let (s, m) = (a.nrows(), b.ncols());
        let size = s + (ORDERS + 1) * m;
        let mut e = DMatrix::zeros(size, size);
        e.view_mut((0, 0), (s, s)).copy_from(&(a * h));
        e.view_mut((0, s), (s, m)).copy_from(&(b * h));
        for k in 0..ORDERS {
            for c in 0..m {
                e[(s + k * m + c, s + (k + 1) * m + c)] = h;
            }
        }
        let x = e.exp();
        Propagator {
            h,
            phi: x.view((0, 0), (s, s)).into_owned(),
            gamma: x.view((0, s), (s, (ORDERS + 1) * m)).into_owned(),
        }
    }

    /// z at the end of the step from `z` at its start and the input's Taylor coefficients
    /// `p` = [p0, p1, p2] (each one value per channel), into `out` (matrix-vector products
    /// down the columns, the matrices' storage order).
    pub fn advance(&self, z: &[f64], p: &[f64], out: &mut [f64]) {
        let mut out = DVectorViewMut::from_slice(out, self.phi.nrows());
        out.gemv(1.0, &self.phi, &DVectorView::from_slice(z, z.len()), 0.0);
        out.gemv(1.0, &self.gamma, &DVectorView::from_slice(p, p.len()), 1.0);
    }
}

/// The largest scaled norm h max(|A|, |B|, 1) (1-norms) whose exponential is formed: scaling and
/// squaring takes about log2 of it squarings, some 60 here, where a step of 1e300 s took a
/// thousand (over a second for a 20-storey building, and NaN in the end). A step that long
/// (1e18 s is 30 times the age of the universe at unit rates) is refused instead.
pub const MAX_SCALED_NORM: f64 = 1e18;

/// Whether the exponential over `h` can be formed for (A, B) (see [`MAX_SCALED_NORM`]).
pub fn formable(a: &DMatrix<f64>, b: &DMatrix<f64>, h: f64) -> Result<(), String> {
    let norm = |m: &DMatrix<f64>| {
        m.column_iter()
            .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let scaled = h * norm(a).max(norm(b)).max(1.0);
    if scaled <= MAX_SCALED_NORM {
        Ok(())
    } else {
        Err(format!(
            "a step of {h:e} s is beyond what the exact propagator can form for this building (h times its largest rate {scaled:e} > {MAX_SCALED_NORM:e})"
        ))
    }
}

/// The propagators of the step sizes used last: hosts keep one step size or alternate a few
/// (rounding of accumulated time), so a handful spares recomputing the exponential.
#[derive(Clone, Debug, Default)]
pub struct Cache {
    entries: Vec<Propagator>,
}

const CACHED: usize = 4;

impl Cache {
    /// The propagator over `h`, made from (A, B) if it is not cached; refused for a step too
    /// long to form ([`formable`]).
    pub fn get(
        &mut self,
        h: f64,
        a: &DMatrix<f64>,
        b: &DMatrix<f64>,
    ) -> Result<&Propagator, String> {
        let found = self
            .entries
            .iter()
            .position(|p| p.h.to_bits() == h.to_bits());
        let k = match found {
            Some(k) => k,
            None => {
                formable(a, b, h)?;
                if self.entries.len() == CACHED {
                    self.entries.remove(0);
                }
                self.entries.push(Propagator::new(a, b, h));
                self.entries.len() - 1
            }
        };
        Ok(&self.entries[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scalar system x' = -c x + p(t) against its closed form, for a held, a ramped and a
    /// quadratic input.
    #[test]
    fn scalar_system_matches_its_closed_form() {
        let (c, h, x0) = (1.7_f64, 0.3_f64, 0.4_f64);
        let a = DMatrix::from_element(1, 1, -c);
        let b = DMatrix::from_element(1, 1, 1.0);
        let prop = Propagator::new(&a, &b, h);
        let (p0, p1, p2) = (0.9, -2.0, 5.0);
        let mut out = [0.0];
        prop.advance(&[x0], &[p0, p1, p2], &mut out);
        // x = x0 e^{-ch} + int_0^h e^{-c(h-s)} (p0 + p1 s + p2 s^2/2) ds
        let e = (-c * h).exp();
        let i0 = (1.0 - e) / c;
        let i1 = h / c - (1.0 - e) / (c * c);
        let i2 = h * h / (2.0 * c) - h / (c * c) + (1.0 - e) / (c * c * c);
        let want = x0 * e + p0 * i0 + p1 * i1 + p2 * i2;
        assert!((out[0] - want).abs() < 1e-14, "{} vs {want}", out[0]);
    }

    /// The cache returns the propagator of the step size asked for, and keeps a few.
    #[test]
    fn cache_keys_on_the_step_size() {
        let a = DMatrix::from_element(1, 1, -1.0);
        let b = DMatrix::from_element(1, 1, 1.0);
        let mut cache = Cache::default();
        for h in [0.1, 0.2, 0.1, 0.3, 0.4, 0.5, 0.1] {
            assert_eq!(cache.get(h, &a, &b).map(|p| p.h), Ok(h));
        }
        assert!(cache.entries.len() <= CACHED);
    }
}
