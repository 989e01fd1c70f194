//! Variable access of TLD.fmu: the one path of its typed getters and setters, and the input and
//! output derivatives. Integer and Boolean values travel as f64 inside. The checks every FMU
//! makes of a set (type, causality, variability, range) are the shared layer's
//! (`Table::settable`); what is TLD's own is where a value comes from (`params::source_of`).

use fmi2_slave::calls::Phase;
use fmi2_slave::{Context, Refusal, Reply, Status, refuse};

use super::params::{Source, derived_value, free_real_input, output_of, source_of};
use super::slave::{TABLE, Tld};
use super::vars::{VARIABLES, VarType, finite, index_of, vr};
use crate::model::{Damper, Output};

/// Who asks for a value that is no load: the instance's context and the calling function, one
/// pointer (the out-of-line path then takes all its arguments in registers).
#[derive(Clone, Copy)]
struct Ask<'a> {
    context: &'a Context,
    function: &'a str,
}

impl Tld {
    /// The value of `r` read as `ty` if it is a load: a stored value, or an output a master
    /// reads after every step of a running simulation. None for anything else, which
    /// [`Tld::value_in_full`] answers out of line.
    #[inline(always)]
    fn loaded(&self, sim: Option<&Damper>, r: u32, ty: VarType) -> Option<f64> {
        match source_of(r, ty) {
            Source::Stored(index) => Some(self.values.at(index)),
            Source::Output(which) => sim?.per_step_output(which),
            _ => None,
        }
    }

    /// Values of the variables `vrs` of type `ty` into `out`, converted by `to`. The instance's
    /// phase has been checked.
    #[inline(always)]
    pub(super) fn get_values<T>(
        &self,
        context: &Context,
        vrs: &[u32],
        out: &mut [T],
        ty: VarType,
        function: &str,
        to: fn(f64) -> T,
    ) -> Reply {
        // Whether the simulation exists is asked once, not per value.
        let sim = self.sim.as_ref();
        for (slot, &r) in out.iter_mut().zip(vrs) {
            let value = match self.loaded(sim, r, ty) {
                Some(v) => v,
                None => self.value_in_full(r, ty, &Ask { context, function })?,
            };
            *slot = to(value);
        }
        Ok(Status::Ok)
    }

    /// The value of `r` read as `ty` where it is no load, or why there is none.
    #[inline(never)]
    fn value_in_full(&self, r: u32, ty: VarType, ask: &Ask) -> Result<f64, Refusal> {
        let Ask { context, function } = *ask;
        match source_of(r, ty) {
            Source::Stored(index) => Ok(self.values.at(index)),
            Source::Output(which) => match &self.sim {
                Some(sim) => Ok(sim.output(which, &self.values.inputs(self.a_derivatives))),
                None => self.output_before_init(context, which),
            },
            Source::Derived => self.derived(context, r, function),
            Source::NoValue(_) => Err(TABLE.no_value(r, function)),
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

    /// Set the variables `vrs` of type `ty` to `values`, converted by `from`: all are checked
    /// before any is changed. The instance's phase has been checked.
    #[inline(always)]
    pub(super) fn set_values<T: Copy>(
        &mut self,
        context: &Context,
        vrs: &[u32],
        values: &[T],
        ty: VarType,
        function: &str,
        from: fn(T) -> f64,
    ) -> Reply {
        // One variable (an input per step, the usual call): checked and set in one pass.
        if let ([r], [v]) = (vrs, values) {
            let v = from(*v);
            let index = Self::check_set(context, *r, v, ty, function)?;
            self.put(*r, index, v);
            return Ok(Status::Ok);
        }
        for (&r, &v) in vrs.iter().zip(values) {
            Self::check_set(context, r, from(v), ty, function)?;
        }
        for (&r, &v) in vrs.iter().zip(values) {
            if let Some(index) = index_of(r) {
                self.put(r, index, from(v));
            }
        }
        Ok(Status::Ok)
    }

    /// The position of `r` if it is a Real input without bounds (the per-step input) and
    /// `value` finite: what the full check would accept, by one table look-up.
    #[inline(always)]
    fn free_input(r: u32, value: f64, ty: VarType) -> Option<usize> {
        match (ty, free_real_input(r)) {
            (VarType::Real, Some(index)) if finite(value) => Some(index),
            _ => None,
        }
    }

    #[inline(always)]
    fn put(&mut self, r: u32, index: usize, value: f64) {
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
            None => Self::check_in_full(context.phase, r, value, ty, function),
        }
    }

    #[inline(never)]
    fn check_in_full(
        phase: Phase,
        r: u32,
        value: f64,
        ty: VarType,
        function: &str,
    ) -> Result<usize, Refusal> {
        TABLE.settable(phase, r, value, ty, function)
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

    /// fmi2GetRealOutputDerivatives: exact first derivatives of outputs, handed to `put`.
    pub(super) fn rates(
        &self,
        _: &Context,
        vrs: &[u32],
        orders: &[i32],
        mut put: impl FnMut(usize, f64),
    ) -> Reply {
        const F: &str = "fmi2GetRealOutputDerivatives";
        let sim = self
            .sim
            .as_ref()
            .ok_or_else(|| refuse(format!("{F}: not initialised")))?;
        let inputs = self.values.inputs(self.a_derivatives);
        for (k, (&r, &order)) in vrs.iter().zip(orders).enumerate() {
            let (_, var) = TABLE.variable(r, F)?;
            let Some(which) = output_of(r) else {
                return Err(refuse(format!("{F}: '{}' is not an output", var.name)));
            };
            if order != 1 {
                return Err(refuse(format!(
                    "{F}: order {order} of '{}' is not offered (maxOutputDerivativeOrder = 1)",
                    var.name
                )));
            }
            put(k, sim.output_derivative(which, &inputs));
        }
        Ok(Status::Ok)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi::vars::Causality;
    use fmi2_slave::calls::allow;
    use fmi2_slave::frame::Experiment;

    /// The quick case of `check_set` must agree with the full check: every variable in its table
    /// takes any finite value, at its own position, in every phase that allows sets, and refuses a
    /// non-finite one; and every Real input the full check would take that way is in it.
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
                    None => assert!(
                        !(any_finite && var.causality == Causality::Input),
                        "{} is a Real input the full check takes as any finite value: list it",
                        var.name
                    ),
                }
            }
        }
        assert!(listed >= 3, "base.a, base.v and base.x at least");
    }
}
