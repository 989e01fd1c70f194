//! model = ShallowWater in Model Exchange: the semi-discrete scheme (the finite-volume spatial
//! operator with the drag and the screens, [`Channel::semi_discrete`], without the MUSCL-Hancock
//! substeps) as an ODE in the cells' depths and discharges, which a host's solver integrates.
//!
//! The number of continuous states is fixed by the model description (FMI 2.0) while
//! swe.cells is a parameter: a bank of [`ME_CELLS`] cells is declared, cell i's depth and
//! discharge (per unit breadth) at positions i and [`ME_CELLS`] + i of the bank. Cells beyond
//! swe.cells are frozen (read as 0, derivative 0, whatever the host sets is ignored);
//! swe.cells > [`ME_CELLS`] is refused in Model Exchange.
//!
//! [`Channel::semi_discrete`]: crate::physics::shallow_water::Channel::semi_discrete

use super::ShallowWater;

/// Cells of the Model Exchange bank: none in the shipped archive, so ShallowWater is refused in
/// Model Exchange (a bank is integrated by every other model's host too: docs/MODEL_EXCHANGE.md).
/// A bank of 200 was built and verified; scripts/me-cells-xml writes the description's 4 x N
/// variables for N cells, and the two numbers must agree, which the tests check.
pub const ME_CELLS: usize = 0;

/// Continuous states of the bank: depths, then discharges.
pub const CELL_STATES: usize = 2 * ME_CELLS;

/// Why continuous states were refused.
#[derive(Clone, Debug, PartialEq)]
pub enum StatesRefused {
    /// A depth below 0: the host's step was too long (a shorter one may succeed).
    Step(String),
    /// Not a state of this damper (a runaway displacement, ...).
    Invalid(String),
}

impl ShallowWater {
    /// Ok if the cells fit the bank; Err: why not.
    pub(in crate::model) fn fits_model_exchange(&self) -> Result<(), String> {
        let n = self.channel.cells;
        if n > ME_CELLS {
            return Err(format!(
                "model = ShallowWater (swe.cells = {n}) is not offered in Model Exchange: its \
                 2 x swe.cells states cannot be declared, FMI 2.0 fixes the number of states \
                 in the model description while swe.cells is a parameter, and a declared bank \
                 of cells would be integrated by every other model's host too \
                 (docs/MODEL_EXCHANGE.md); use Co-Simulation"
            ));
        }
        Ok(())
    }

    /// The depths and discharges into the bank `out` (frozen cells 0).
    pub(in crate::model) fn cell_states(&self, out: &mut [f64; CELL_STATES]) {
        let n = self.channel.cells;
        out.fill(0.0);
        out[..n].copy_from_slice(&self.flow.depth);
        out[ME_CELLS..ME_CELLS + n].copy_from_slice(&self.flow.discharge);
    }

    /// The semi-discrete equations' rates of the bank under base acceleration `a` (frozen
    /// cells 0).
    pub(in crate::model) fn cell_derivatives(&self, a: f64, out: &mut [f64; CELL_STATES]) {
        let n = self.channel.cells;
        let r = self.channel.semi_discrete(&self.flow, a, self.drag());
        out.fill(0.0);
        out[..n].copy_from_slice(&r.depth);
        out[ME_CELLS..ME_CELLS + n].copy_from_slice(&r.discharge);
    }

    /// Nominal magnitudes: the still depth and the discharge of a wave of that height,
    /// h sqrt(g_e h) (1 for frozen cells).
    pub(in crate::model) fn cell_nominals(&self, out: &mut [f64; CELL_STATES]) {
        let (n, h) = (self.channel.cells, self.channel.depth);
        out.fill(1.0);
        out[..n].fill(h);
        out[ME_CELLS..ME_CELLS + n].fill(h * (self.channel.g_e * h).sqrt());
    }

    /// Take the bank's depths and discharges and the work done on the liquid `work` [J]; all
    /// or nothing. A negative depth is [`StatesRefused::Step`]. The volume is not checked
    /// (unlike a restored FMU state's): the semi-discrete equations conserve it exactly and a
    /// host's integration to round-off, but a host's difference-quotient Jacobian perturbs
    /// single cells, and those states are legitimate.
    pub(in crate::model) fn set_cell_states(
        &mut self,
        cells: &[f64; CELL_STATES],
        work: f64,
    ) -> Result<(), StatesRefused> {
        let n = self.channel.cells;
        if let Some(i) = cells[..n].iter().position(|&h| h < 0.0) {
            return Err(StatesRefused::Step(format!(
                "swe.h[{}] = {:e} m: the host's step drove a depth below 0 (a shorter step \
                 keeps it >= 0)",
                i + 1,
                cells[i]
            )));
        }
        self.flow.depth.copy_from_slice(&cells[..n]);
        self.flow
            .discharge
            .copy_from_slice(&cells[ME_CELLS..ME_CELLS + n]);
        self.work = work;
        Ok(())
    }
}

impl crate::model::AnyModel {
    fn shallow_water(&self) -> Option<&ShallowWater> {
        match self {
            crate::model::AnyModel::ShallowWater(m) => Some(m),
            _ => None,
        }
    }

    /// The bank's states (all 0 for a model without cells).
    pub fn cell_states(&self, out: &mut [f64; CELL_STATES]) {
        match self.shallow_water() {
            Some(m) => m.cell_states(out),
            None => out.fill(0.0),
        }
    }

    /// The bank's derivatives under base acceleration `a` (all 0 for a model without cells).
    pub fn cell_derivatives(&self, a: f64, out: &mut [f64; CELL_STATES]) {
        match self.shallow_water() {
            Some(m) => m.cell_derivatives(a, out),
            None => out.fill(0.0),
        }
    }

    /// The bank's nominal magnitudes (1 for a model without cells).
    pub fn cell_nominals(&self, out: &mut [f64; CELL_STATES]) {
        match self.shallow_water() {
            Some(m) => m.cell_nominals(out),
            None => out.fill(1.0),
        }
    }

    /// Take the continuous states of a model with cells: the bank and energy.input `input`
    /// (the work done plus `initial_energy`); slosh.x, slosh.v and energy.dissipated are
    /// functions of the cells, read from them, and the host's values of them are not used.
    /// Ok(false): the model has no cells (nothing done).
    pub fn set_cell_states(
        &mut self,
        cells: &[f64; CELL_STATES],
        input: f64,
        initial_energy: f64,
    ) -> Result<bool, StatesRefused> {
        match self {
            crate::model::AnyModel::ShallowWater(m) => {
                m.set_cell_states(cells, input - initial_energy)?;
                Ok(true)
            }
            _ => Ok(false),
        }
    }
}
