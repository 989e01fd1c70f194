//! TLD.fmu as a slave of the shared FMI layer (`fmi2_slave`): the values the host set, the
//! derivatives of base.a for the next step, and the damper once initialised. The shared layer
//! has checked the call's phase and the host's pointers before any method here runs; every
//! refusal leaves the slave as it was.

use fmi2_slave::description::Table;
use fmi2_slave::{Context, Refusal, Slave, refuse};

use super::params::{Configuration, Values, output_of};
use super::vars::{self, VARIABLES, finite, index_of, vr};
use crate::model::{Damper, StepError};
use crate::solver::SolveError;

/// Who asks for a value that is no load: the instance's context and the calling function, one
/// pointer (the out-of-line path then takes all its arguments in registers). Here, beside the
/// loops that make it, so that access.rs (which answers it) depends on this file and not back.
#[derive(Clone, Copy)]
pub(super) struct Ask<'a> {
    pub context: &'a Context,
    pub function: &'a str,
}

/// The model description as the shared layer reads it.
pub static TABLE: Table = vars::TABLE;

pub struct Tld {
    pub(super) values: Values,
    /// Whether the host set solver.tolerance itself (then fmi2SetupExperiment's tolerance does
    /// not replace it).
    pub(super) user_tolerance: bool,
    /// Derivatives of base.a (orders 1 and 2) for the next step only.
    pub(super) a_derivatives: [f64; 2],
    pub(super) sim: Option<Damper>,
    /// The value of the discrete input base.v.jump the model has taken (Model Exchange): an
    /// event hands the model the change since.
    pub(super) v_jump_taken: f64,
}

impl Tld {
    pub(super) fn build(&self, context: &Context) -> Result<(Damper, Vec<String>), Refusal> {
        Damper::configure(&self.configuration(context))
            .map_err(|e| refuse(format!("the parameters are inconsistent: {e}")))
    }

    /// The parameters as the models read them.
    fn configuration<'a>(&'a self, context: &Context) -> Configuration<'a> {
        Configuration {
            values: &self.values,
            tolerance: context.experiment.tolerance,
            user_tolerance: self.user_tolerance,
        }
    }

    /// The running simulation, or during initialisation one built on the parameters set so
    /// far (kept in `provisional` for the rest of the call).
    pub(super) fn simulation<'a>(
        &'a self,
        context: &Context,
        provisional: &'a mut Option<Damper>,
    ) -> Result<&'a Damper, Refusal> {
        if let Some(sim) = &self.sim {
            return Ok(sim);
        }
        if provisional.is_none() {
            *provisional = Some(self.build(context)?.0);
        }
        provisional.as_ref().ok_or_else(|| refuse("no simulation"))
    }
}

impl Slave for Tld {
    const TABLE: &'static Table = &TABLE;
    const MARK: u64 = 0x544c_445f_464d_5532;
    const STATE_TAG: [u8; 4] = *b"TLDs";
    const STATE_VERSION: u16 = 1;

    fn new() -> Self {
        Tld {
            values: Values::start(),
            user_tolerance: false,
            a_derivatives: [0.0; 2],
            v_jump_taken: 0.0,
            sim: None,
        }
    }

    /// Kept inside the range the solver.tolerance parameter declares.
    fn tolerance(t: f64) -> f64 {
        let range = index_of(vr::SOLVER_TOLERANCE).and_then(|i| VARIABLES.get(i));
        let lo = range.and_then(|v| v.min).unwrap_or(t);
        let hi = range.and_then(|v| v.max).unwrap_or(t);
        t.clamp(lo, hi)
    }

    fn initialise(&mut self, context: &Context) -> Result<Vec<String>, Refusal> {
        let (sim, warnings) = self.build(context)?;
        self.sim = Some(sim);
        // The start is the host's: only later changes of base.v.jump move the tank.
        self.v_jump_taken = self.values.get(vr::BASE_V_JUMP);
        Ok(warnings)
    }

    fn uninitialise(&mut self) {
        self.sim = None;
    }

    #[inline]
    fn step(&mut self, _: &Context, t: f64, h: f64) -> Result<bool, Refusal> {
        debug_assert!(finite(t) && h > 0.0);
        let input = self.values.input_at();
        let sim = self
            .sim
            .as_mut()
            .ok_or_else(|| refuse("fmi2DoStep: no simulation (not initialised)"))?;
        match sim.step_at(t, h, self.a_derivatives, input) {
            Ok(report) => {
                // Input derivatives describe one communication step. Reset only when set (any
                // bit, -0 included): a store on every step otherwise.
                if self.a_derivatives.iter().any(|d| d.to_bits() != 0) {
                    self.a_derivatives = [0.0; 2];
                }
                Ok(report.implausible)
            }
            Err(e) => Err(step_failed(t, h, e)),
        }
    }

    #[inline(always)]
    fn get<T>(
        &self,
        context: &Context,
        vrs: &[u32],
        out: &mut [T],
        ty: vars::VarType,
        function: &str,
        to: fn(f64) -> T,
    ) -> fmi2_slave::Reply {
        // Whether the simulation exists is asked once, not per value.
        let sim = self.sim.as_ref();
        for (slot, &r) in out.iter_mut().zip(vrs) {
            let value = match self.loaded(sim, r, ty) {
                Some(v) => v,
                None => self.value_in_full(r, ty, &Ask { context, function })?,
            };
            *slot = to(value);
        }
        Ok(fmi2_slave::Status::Ok)
    }

    /// All are checked before any is changed.
    #[inline(always)]
    fn set<T: Copy>(
        &mut self,
        context: &Context,
        vrs: &[u32],
        values: &[T],
        ty: vars::VarType,
        function: &str,
        from: fn(T) -> f64,
    ) -> fmi2_slave::Reply {
        // One variable (an input per step, the usual call): checked and set in one pass.
        if let ([r], [v]) = (vrs, values) {
            let v = from(*v);
            let index = Self::check_set(context, *r, v, ty, function)?;
            self.put(*r, index, v);
            return Ok(fmi2_slave::Status::Ok);
        }
        for (&r, &v) in vrs.iter().zip(values) {
            Self::check_set(context, r, from(v), ty, function)?;
        }
        for (&r, &v) in vrs.iter().zip(values) {
            if let Some(index) = index_of(r) {
                self.put(r, index, from(v));
            }
        }
        Ok(fmi2_slave::Status::Ok)
    }

    /// The per-step inputs (Real inputs without bounds) take any finite value: one table
    /// look-up, as in [`Slave::set`].
    #[inline(always)]
    fn set_quietly(&mut self, r: u32, value: f64, ty: vars::VarType) -> bool {
        match Self::free_input(r, value, ty) {
            Some(index) => {
                // An input, not solver.tolerance: no flag to set (`Tld::put`).
                self.values.set_at(index, value);
                true
            }
            None => false,
        }
    }

    /// The stored values and the outputs kept with the state, as in [`Slave::get`].
    #[inline(always)]
    fn get_quietly<T>(
        &self,
        vrs: &[u32],
        out: &mut [T],
        ty: vars::VarType,
        to: fn(f64) -> T,
    ) -> bool {
        if ty == vars::VarType::Real {
            return self.quick_reals(vrs, out, to);
        }
        let sim = self.sim.as_ref();
        for (slot, &r) in out.iter_mut().zip(vrs) {
            match self.loaded(sim, r, ty) {
                Some(v) if finite(v) => *slot = to(v),
                _ => return false,
            }
        }
        true
    }

    fn set_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> fmi2_slave::Reply {
        self.input_derivatives(vrs, orders, values)
    }

    fn output_derivatives(
        &self,
        _: &Context,
        vrs: &[u32],
        orders: &[i32],
        put: impl FnMut(usize, f64),
    ) -> fmi2_slave::Reply {
        // Exact first derivatives of the outputs.
        let inputs = self.values.inputs(self.a_derivatives);
        let rate = |sim: &Damper, which| sim.output_derivative(which, &inputs);
        TABLE.first_output_derivatives(self.sim.as_ref(), vrs, orders, output_of, rate, put)
    }

    /// The damper's notice of implausible motion, to the host as a warning once per run.
    fn notice(&mut self, context: &Context) -> Option<String> {
        let a = self.values.get(vr::BASE_A);
        let notice = self.sim.as_mut()?.notice(a)?;
        Some(format!("fmi2DoStep to t = {}: {notice}", context.time))
    }

    fn flag(&self) -> bool {
        self.user_tolerance
    }

    fn save(&self, out: &mut Vec<u8>) {
        self.save_part(out)
    }

    fn load(
        context: &Context,
        flag: bool,
        part: &mut fmi2_slave::frame::Reader,
    ) -> Result<Self, String> {
        Self::load_part(context, flag, part)
    }
}

#[cfg(test)]
#[path = "slave_tests.rs"]
mod tests;

/// Why a step failed, as the host is told: fmi2Discard when a smaller step may succeed.
#[cold]
#[inline(never)]
fn step_failed(t: f64, h: f64, e: StepError) -> Refusal {
    let status = match e {
        StepError::Solver(SolveError::TooManySteps { .. }) => fmi2_slave::Status::Discard,
        _ => fmi2_slave::Status::Error,
    };
    let hint = if status == fmi2_slave::Status::Discard {
        " The state is left at the start of the step; retry with a smaller communication step."
    } else {
        " The state is left at the start of the step."
    };
    Refusal::new(
        status,
        format!("fmi2DoStep from t = {t} by {h}: {e}.{hint}"),
    )
}
