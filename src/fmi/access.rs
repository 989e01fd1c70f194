//! Variable access of TLD.fmu: where a value comes from (`params::source_of`) for its typed
//! getters, the checks of its setters, and the input derivatives (the loops over the value
//! references are its `Slave` methods, fmi/slave.rs). Integer and Boolean values travel as f64
//! inside. The checks every FMU makes of a set (type, causality, variability, range) are the
//! shared layer's (`Table::settable`), after TLD's quick path for its per-step inputs.

use fmi2_slave::{Context, Refusal, Reply, Status};

use super::params::{
    QUICK_NONE, QUICK_OUTPUT, QUICK_REALS, Source, derived_value, free_real_input, source_of,
};
use super::slave::{Ask, TABLE, Tld};
use super::vars::{VARIABLES, VarType, finite, vr};
use crate::model::{Damper, Output, PER_STEP};

/// The per-step outputs before initialisation: not finite, which sends them the full path.
static NO_OUTPUTS: [f64; PER_STEP + 1] = [f64::INFINITY; PER_STEP + 1];

impl Tld {
    /// The value of `r` read as `ty` if it is a load: a stored value, or an output a master
    /// reads after every step of a running simulation. None for anything else, which
    /// [`Tld::value_in_full`] answers out of line.
    #[inline(always)]
    pub(super) fn loaded(&self, sim: Option<&Damper>, r: u32, ty: VarType) -> Option<f64> {
        match source_of(r, ty) {
            Source::Stored(index) => Some(self.values.at(index)),
            Source::Output(which) => sim?.per_step_output(which),
            _ => None,
        }
    }

    /// [`fmi2_slave::Slave::get_quietly`] for Reals: one table look-up per value
    /// ([`QUICK_REALS`]), the simulation found once, no branch but the loop's and the kind's.
    /// A value reference with no quick read, and an output before initialisation, read
    /// infinity, which the one finiteness test at the end turns away with any other non-finite
    /// value.
    #[inline(always)]
    pub(super) fn quick_reals<T>(&self, vrs: &[u32], out: &mut [T], to: fn(f64) -> T) -> bool {
        let outputs = match &self.sim {
            Some(sim) => sim.per_step(),
            None => &NO_OUTPUTS,
        };
        // Finite values sum to a finite value, but for an overflow (then the full path).
        let mut sum = 0.0;
        for (slot, &r) in out.iter_mut().zip(vrs) {
            let code = usize::from(QUICK_REALS.get(r as usize).copied().unwrap_or(QUICK_NONE));
            let v = match code.checked_sub(QUICK_OUTPUT.into()) {
                // (PER_STEP + 1 is a power of two: a mask, no bounds check.)
                Some(k) => outputs[k % outputs.len()],
                None => self.values.at(code),
            };
            sum += v;
            *slot = to(v);
        }
        finite(sum)
    }

    /// The value of `r` read as `ty` where it is no load, or why there is none.
    #[inline(never)]
    pub(super) fn value_in_full(&self, r: u32, ty: VarType, ask: &Ask) -> Result<f64, Refusal> {
        let Ask { context, function } = *ask;
        match source_of(r, ty) {
            Source::Stored(index) => Ok(self.values.at(index)),
            Source::Output(which) => match &self.sim {
                Some(sim) => Ok(sim.output(which, &self.values.inputs(self.a_derivatives))),
                None => self.output_before_init(context, which),
            },
            Source::Derived => self.derived(context, r, function),
            Source::NoValue(_) => self
                .derivative_value(context, r)
                .unwrap_or_else(|| Err(TABLE.no_value(r, function))),
            Source::WrongType(index) => Err(fmi2_slave::description::wrong_type(
                r,
                &VARIABLES[index],
                function,
            )),
            Source::Unknown => Err(fmi2_slave::description::unknown(r, function)),
        }
    }

    /// An output before the simulation exists: from the simulation the values would start.
    #[cold]
    #[inline(never)]
    fn output_before_init(&self, context: &Context, which: Output) -> Result<f64, Refusal> {
        let inputs = self.values.inputs(self.a_derivatives);
        let mut provisional = None;
        Ok(self
            .simulation(context, &mut provisional)?
            .output(which, &inputs))
    }

    /// A calculated parameter.
    #[cold]
    #[inline(never)]
    fn derived(&self, context: &Context, r: u32, function: &str) -> Result<f64, Refusal> {
        let mut provisional = None;
        let derived = self.simulation(context, &mut provisional)?.derived();
        derived_value(r, &derived).ok_or_else(|| TABLE.no_value(r, function))
    }

    /// The position of `r` if it is a Real input without bounds (the per-step input) and
    /// `value` finite: what the full check would accept, by one table look-up.
    #[inline(always)]
    pub(super) fn free_input(r: u32, value: f64, ty: VarType) -> Option<usize> {
        match (ty, free_real_input(r)) {
            (VarType::Real, Some(index)) if finite(value) => Some(index),
            _ => None,
        }
    }

    #[inline(always)]
    pub(super) fn put(&mut self, r: u32, index: usize, value: f64) {
        self.values.set_at(index, value);
        if r == vr::SOLVER_TOLERANCE {
            self.user_tolerance = true;
        }
    }

    /// The position in the values of the variable `r`, if `value` may be set there now. A Real
    /// input without bounds (the per-step input) takes any finite value: one table look-up.
    #[inline(always)]
    pub(super) fn check_set(
        context: &Context,
        r: u32,
        value: f64,
        ty: VarType,
        function: &str,
    ) -> Result<usize, Refusal> {
        match Self::free_input(r, value, ty) {
            Some(index) => Ok(index),
            None => TABLE.settable(context.phase, r, value, ty, function),
        }
    }

    /// fmi2SetRealInputDerivatives: derivatives of Real inputs for the next step. base.a's are
    /// used (orders 1 and 2); those of base.v and base.x are accepted and not needed.
    pub(super) fn input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> Reply {
        for ((&r, &order), &value) in vrs.iter().zip(orders).zip(values) {
            TABLE.check_input_derivative(r, order, value, 2)?;
        }
        for ((&r, &order), &value) in vrs.iter().zip(orders).zip(values) {
            if r == vr::BASE_A {
                self.a_derivatives[order as usize - 1] = value;
            }
        }
        Ok(Status::Ok)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi::vars::{Causality, Variability, index_of};
    use fmi2_slave::calls::{Phase, allow};
    use fmi2_slave::frame::Experiment;

    /// The quick case of `check_set` must agree with the full check: every variable in its table
    /// takes any finite value, at its own position, in every phase that allows sets, and refuses a
    /// non-finite one; and every continuous Real input the full check would take that way is in
    /// it. A discrete one is not (the full check refuses it in continuous-time mode).
    #[test]
    fn free_real_inputs_are_what_the_full_check_accepts() {
        let mut listed = 0;
        for phase in [
            Phase::Instantiated,
            Phase::InitializationMode,
            Phase::StepComplete,
        ] {
            assert_ne!(phase.bit() & allow::SET, 0);
            let context = Context {
                phase,
                experiment: Experiment::default(),
                time: 0.0,
            };
            for var in VARIABLES {
                let r = var.vr;
                let full = |v: f64| TABLE.settable(phase, r, v, VarType::Real, "t").ok();
                let any_finite = [f64::MAX, -f64::MAX, 0.0, 5e-324, -1.5e7]
                    .iter()
                    .all(|&v| full(v) == index_of(r));
                match free_real_input(r) {
                    Some(index) => {
                        listed += 1;
                        assert_eq!(Some(index), index_of(r), "{}", var.name);
                        assert!(any_finite, "{} in {phase:?}", var.name);
                        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                            assert_eq!(full(v), None, "{} = {v}", var.name);
                            let quick = Tld::check_set(&context, r, v, VarType::Real, "t").ok();
                            assert_eq!(quick, None, "{} = {v}", var.name);
                        }
                    }
                    None if var.variability == Variability::Discrete => {}
                    None => assert!(
                        !(any_finite && var.causality == Causality::Input),
                        "{} is a Real input the full check takes as any finite value: list it",
                        var.name
                    ),
                }
            }
        }
        assert!(listed >= 3, "base.a, base.v and base.x at least");
        // The discrete Real inputs: never the quick path, refused in continuous-time mode.
        let discrete: Vec<_> = VARIABLES
            .iter()
            .filter(|v| v.causality == Causality::Input && v.variability == Variability::Discrete)
            .collect();
        assert!(discrete.iter().any(|v| v.name == "base.v.jump"));
        for var in discrete {
            assert_eq!(free_real_input(var.vr), None, "{}", var.name);
            let refused =
                TABLE.settable(Phase::ContinuousTimeMode, var.vr, 0.0, VarType::Real, "t");
            assert!(refused.is_err(), "{}", var.name);
            let taken = TABLE.settable(Phase::EventMode, var.vr, 0.0, VarType::Real, "t");
            assert!(taken.is_ok(), "{}", var.name);
        }
    }
}
