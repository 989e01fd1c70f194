//! Variable access of an instance: the one path of every typed getter and setter, and the
//! input and output derivatives. Integer and Boolean values travel as f64 inside.

use super::instance::Instance;
use super::params::{Source, derived_value, free_real_input, output_of, source_of};
use super::status::{Refusal, Reply, Status, refuse};
use super::vars::{Causality, VARIABLES, VarType, Variability, Variable, finite, index_of, vr};
use crate::model::Output;

use super::calls::Phase;

/// The variable behind `vr`.
fn variable(vr: u32, function: &str) -> Result<(usize, &'static Variable), Refusal> {
    match index_of(vr).and_then(|i| VARIABLES.get(i).map(|v| (i, v))) {
        Some(found) => Ok(found),
        None => Err(unknown(vr, function)),
    }
}

#[cold]
fn unknown(vr: u32, function: &str) -> Refusal {
    refuse(format!("{function}: unknown value reference {vr}"))
}

#[cold]
fn wrong_type(vr: u32, var: &Variable, function: &str) -> Refusal {
    refuse(format!(
        "{function}: '{}' (value reference {vr}) is of type {:?}",
        var.name, var.ty
    ))
}

#[cold]
fn no_value(vr: u32, function: &str) -> Refusal {
    let name = index_of(vr).map_or("?", |i| VARIABLES[i].name);
    refuse(format!("{function}: '{name}' has no value"))
}

/// The variable behind `vr`, if it is of the type `ty` the calling function handles
/// (fmi2Get/SetInteger also serve Enumeration variables).
fn typed_variable(
    vr: u32,
    ty: VarType,
    function: &str,
) -> Result<(usize, &'static Variable), Refusal> {
    let (index, var) = variable(vr, function)?;
    if var.accessed_as(ty) {
        Ok((index, var))
    } else {
        Err(wrong_type(vr, var, function))
    }
}

impl Instance {
    /// The value of `r` read as `ty` if it is a load: a stored value, or an output a master
    /// reads after every step of a running simulation. None for anything else, which
    /// [`Instance::value_in_full`] answers out of line.
    #[inline(always)]
    fn loaded(&self, r: u32, ty: VarType) -> Option<f64> {
        match source_of(r, ty) {
            Source::Stored(index) => Some(self.values.at(index)),
            Source::Output(which) => self.sim.as_ref()?.per_step_output(which),
            _ => None,
        }
    }

    /// Values of the variables `vrs` of type `ty` into `out`, converted by `to`. The instance's
    /// phase has been checked.
    pub fn get<T>(
        &self,
        vrs: &[u32],
        out: &mut [T],
        ty: VarType,
        function: &str,
        to: fn(f64) -> T,
    ) -> Reply {
        for (slot, &r) in out.iter_mut().zip(vrs) {
            let value = match self.loaded(r, ty) {
                Some(v) => v,
                None => self.value_in_full(r, ty, function)?,
            };
            *slot = to(value);
        }
        Ok(Status::Ok)
    }

    /// The value of `r` read as `ty` where it is no load, or why there is none.
    #[inline(never)]
    fn value_in_full(&self, r: u32, ty: VarType, function: &str) -> Result<f64, Refusal> {
        match source_of(r, ty) {
            Source::Stored(index) => Ok(self.values.at(index)),
            Source::Output(which) => match &self.sim {
                Some(sim) => Ok(sim.output(which, &self.values.inputs(self.a_derivatives))),
                None => self.output_before_init(which),
            },
            Source::Derived => self.derived(r, function),
            Source::NoValue(_) => Err(no_value(r, function)),
            Source::WrongType(index) => Err(wrong_type(r, &VARIABLES[index], function)),
            Source::Unknown => Err(unknown(r, function)),
        }
    }

    /// An output before the simulation exists: from the simulation the values would start.
    #[cold]
    #[inline(never)]
    fn output_before_init(&self, which: Output) -> Result<f64, Refusal> {
        let inputs = self.values.inputs(self.a_derivatives);
        let mut provisional = None;
        Ok(self.simulation(&mut provisional)?.output(which, &inputs))
    }

    /// A calculated parameter.
    #[cold]
    #[inline(never)]
    fn derived(&self, r: u32, function: &str) -> Result<f64, Refusal> {
        let mut provisional = None;
        let derived = self.simulation(&mut provisional)?.derived();
        derived_value(r, &derived).ok_or_else(|| no_value(r, function))
    }

    /// Set the variables `vrs` of type `ty` to `values`, converted by `from`: all are checked
    /// before any is changed. The instance's phase has been checked.
    pub fn set<T: Copy>(
        &mut self,
        vrs: &[u32],
        values: &[T],
        ty: VarType,
        function: &str,
        from: fn(T) -> f64,
    ) -> Reply {
        // One variable (an input per step, the usual call): checked and set in one pass.
        if let ([r], [v]) = (vrs, values) {
            let v = from(*v);
            let index = self.check_set(*r, v, ty, function)?;
            self.put(*r, index, v);
            return Ok(Status::Ok);
        }
        for (&r, &v) in vrs.iter().zip(values) {
            self.check_set(r, from(v), ty, function)?;
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
        &self,
        r: u32,
        value: f64,
        ty: VarType,
        function: &str,
    ) -> Result<usize, Refusal> {
        match Self::free_input(r, value, ty) {
            Some(index) => Ok(index),
            None => self.check_set_in_full(r, value, ty, function),
        }
    }

    #[inline(never)]
    fn check_set_in_full(
        &self,
        r: u32,
        value: f64,
        ty: VarType,
        function: &str,
    ) -> Result<usize, Refusal> {
        let (index, var) = typed_variable(r, ty, function)?;
        match var.causality {
            Causality::Parameter => {
                let before_init =
                    matches!(self.phase, Phase::Instantiated | Phase::InitializationMode);
                if !before_init && var.variability != Variability::Tunable {
                    return Err(refuse(format!(
                        "{function}: '{}' is a fixed parameter and can only be set before fmi2ExitInitializationMode",
                        var.name
                    )));
                }
            }
            Causality::Input => {}
            _ => {
                return Err(refuse(format!(
                    "{function}: '{}' is computed by the FMU and cannot be set",
                    var.name
                )));
            }
        }
        if let Some(reason) = var.reject(value) {
            return Err(refuse(format!("{function}: {reason}")));
        }
        Ok(index)
    }

    /// fmi2SetRealInputDerivatives: derivatives of Real inputs for the next step. base.a's are
    /// used (orders 1 and 2); those of base.v and base.x are accepted and not needed.
    pub fn set_input_derivatives(&mut self, vrs: &[u32], orders: &[i32], values: &[f64]) -> Reply {
        const F: &str = "fmi2SetRealInputDerivatives";
        for ((&r, &order), &value) in vrs.iter().zip(orders).zip(values) {
            let (_, var) = variable(r, F)?;
            if var.causality != Causality::Input || var.ty != VarType::Real {
                return Err(refuse(format!("{F}: '{}' is not a Real input", var.name)));
            }
            if !(1..=2).contains(&order) {
                return Err(refuse(format!(
                    "{F}: order {order} for '{}' is not supported (1 or 2)",
                    var.name
                )));
            }
            if !value.is_finite() {
                return Err(refuse(format!(
                    "{F}: derivative {value} of '{}' must be finite",
                    var.name
                )));
            }
        }
        for ((&r, &order), &value) in vrs.iter().zip(orders).zip(values) {
            if r == vr::BASE_A {
                self.a_derivatives[order as usize - 1] = value;
            }
        }
        Ok(Status::Ok)
    }

    /// fmi2GetRealOutputDerivatives: exact first derivatives of outputs, handed to `put`.
    pub fn output_derivatives(
        &self,
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
            let (_, var) = variable(r, F)?;
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
    use crate::fmi::calls::allow;
    use crate::fmi::logger::Logger;

    /// The quick case of `check_set` must agree with the full check: every variable in its table
    /// takes any finite value, at its own position, in every phase that allows sets, and refuses a
    /// non-finite one; and every Real input the full check would take that way is in it.
    #[test]
    fn free_real_inputs_are_what_the_full_check_accepts() {
        let mut inst = Instance::new(c"t".into(), Logger::new(None, std::ptr::null_mut()), false);
        let mut listed = 0;
        for phase in [
            Phase::Instantiated,
            Phase::InitializationMode,
            Phase::StepComplete,
        ] {
            assert_ne!(phase.bit() & allow::SET, 0);
            inst.phase = phase;
            for var in VARIABLES {
                let r = var.vr;
                let full = |v: f64| inst.check_set_in_full(r, v, VarType::Real, "t").ok();
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
                            let quick = inst.check_set(r, v, VarType::Real, "t").ok();
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
