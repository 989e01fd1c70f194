//! Damping screens in the finite-volume scheme (MODEL.md section 9).
//!
//! A screen at x_s takes the pressure drop (rho/2) C_l u|u|: per unit breadth and density a
//! force (C_l/2) H u|u| = (C_l/2) q|q|/H against the flow, concentrated at x_s. Here it is
//! shared between the two cells whose centres bracket x_s, with the linear-interpolation
//! weights w (so that the loss acts at x_s to second order however the grid falls), as a
//! source in each: dq_i/dt = -l_i |u_i| q_i with l_i = w_i C_l/(2 dx). The depths do not
//! change (mass stays exact); the source is integrated exactly with the depth frozen,
//! q(t) = q(0)/(1 + l_i |u_i(0)| t), in the same Strang halves as the linear drag: it never
//! reverses a flow, never limits the step, and lowers every cell's kinetic energy (the energy
//! taken is >= 0 and part of energy.dissipated). The momentum it takes from the liquid is the
//! screens' impulse on the tank (they are fixed to it), so the momentum balance keeps closing.

use super::scheme::velocity;
use crate::physics::screens::MOST;

/// The cells the screens act in and their loss rates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenCells {
    len: usize,
    cell: [usize; 2 * MOST],
    /// l_i = sum of w C_l/(2 dx) of the screens acting in the cell [1/m].
    loss: [f64; 2 * MOST],
}

impl ScreenCells {
    pub const NONE: ScreenCells = ScreenCells {
        len: 0,
        cell: [0; 2 * MOST],
        loss: [0.0; 2 * MOST],
    };

    /// Screens of loss coefficient `c_l` at `positions` [m from the left wall] in a channel of
    /// `cells` cells of width `dx` (at most [`MOST`] screens: those beyond are ignored).
    pub fn new(positions: &[f64], c_l: f64, dx: f64, cells: usize) -> Self {
        let mut s = ScreenCells::NONE;
        let mut add = |cell: usize, weight: f64| {
            if weight <= 0.0 {
                return;
            }
            let loss = weight * c_l / (2.0 * dx);
            if let Some(k) = s.cell[..s.len].iter().position(|&c| c == cell) {
                s.loss[k] += loss;
            } else {
                s.cell[s.len] = cell;
                s.loss[s.len] = loss;
                s.len += 1;
            }
        };
        let last = cells.saturating_sub(1);
        for &x in positions.iter().take(MOST) {
            // Cell centres at (i + 1/2) dx: x lies between centres i and i + 1 at fraction
            // `frac` (held at the first and last centres near the walls).
            let at = (x / dx - 0.5).clamp(0.0, last as f64);
            let i = (at.floor() as usize).min(last);
            let frac = at - i as f64;
            add(i, 1.0 - frac);
            if i < last {
                add(i + 1, frac);
            }
        }
        s
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The cells and their loss rates l_i [1/m].
    pub fn entries(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.cell[..self.len]
            .iter()
            .copied()
            .zip(self.loss[..self.len].iter().copied())
    }

    /// The screens' source over a time `dt` at depths `h`, integrated exactly with the depths
    /// frozen: q_i <- q_i/(1 + l_i |u_i| dt). Returns the discharge taken, sum of q_i before
    /// minus after (times dx: the impulse on the tank per unit breadth and density).
    #[inline]
    pub fn apply(&self, h: &[f64], q: &mut [f64], dt: f64, dry: f64) -> f64 {
        let mut taken = 0.0;
        for (i, l) in self.entries() {
            let before = q[i];
            let after = before / (1.0 + l * velocity(before, h[i], dry).abs() * dt);
            q[i] = after;
            taken += before - after;
        }
        taken
    }

    /// The screens' drag on the liquid, sum of l_i q_i |u_i| (times dx: the force on the tank
    /// per unit breadth and density) [m^2/s^2].
    pub fn drag(&self, h: &[f64], q: &[f64], dry: f64) -> f64 {
        self.entries()
            .map(|(i, l)| l * q[i] * velocity(q[i], h[i], dry).abs())
            .sum()
    }

    /// The rate of [`ScreenCells::drag`] along the rates `dh`, `dq` (where the cells are wet:
    /// d(q|q|/H) = 2|u| dq - u|u| dH).
    pub fn drag_rate(&self, h: &[f64], q: &[f64], dh: &[f64], dq: &[f64], dry: f64) -> f64 {
        self.entries()
            .map(|(i, l)| {
                let u = velocity(q[i], h[i], dry);
                l * (2.0 * u.abs() * dq[i] - u * u.abs() * dh[i])
            })
            .sum()
    }

    /// Add the screens' source -l_i |u_i| q_i to the discharge rates `dq`.
    pub fn add_rates(&self, h: &[f64], q: &[f64], dq: &mut [f64], dry: f64) {
        for (i, l) in self.entries() {
            dq[i] -= l * velocity(q[i], h[i], dry).abs() * q[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A screen's loss is shared by the two cells whose centres bracket it, with the linear
    /// weights (all of it in the wall cell beyond the first centre); two screens in one cell
    /// add up.
    #[test]
    fn screens_are_shared_between_the_bracketing_cells() {
        let (dx, c_l) = (0.1, 2.0);
        let unit = c_l / (2.0 * dx);
        let near = |got: f64, want: f64| (got - want).abs() < 1e-12 * want;
        let s = ScreenCells::new(&[0.27], c_l, dx, 10);
        let e: Vec<_> = s.entries().collect();
        assert_eq!(e.len(), 2);
        assert!(e[0].0 == 2 && near(e[0].1, 0.8 * unit), "{e:?}");
        assert!(e[1].0 == 3 && near(e[1].1, 0.2 * unit), "{e:?}");
        let s = ScreenCells::new(&[0.01, 0.02, 0.97], c_l, dx, 10);
        let e: Vec<_> = s.entries().collect();
        assert_eq!(e.len(), 2, "{e:?}");
        assert!(e[0].0 == 0 && near(e[0].1, 2.0 * unit), "{e:?}");
        assert!(e[1].0 == 9 && near(e[1].1, unit), "{e:?}");
        assert!(ScreenCells::NONE.is_empty() && !s.is_empty());
    }
}
