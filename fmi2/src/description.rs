//! The model description as the shared layer sees it: the types of the variable table each
//! FMU's build script generates (build/), and [`Table`], that table with its value-reference
//! index, GUID and log categories: what the FMI layer needs to address, check and describe a
//! variable. The checks every setter makes (type, causality, variability, range) live here.

use crate::calls::Phase;
use crate::status::{Refusal, Reply, Status, refuse};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    Enumeration,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variable {
    pub name: &'static str,
    pub vr: u32,
    pub ty: VarType,
    pub causality: Causality,
    pub variability: Variability,
    pub start: Option<f64>,
    pub min: Option<f64>,
    pub max: Option<f64>,
    /// Enumeration items (name, value).
    pub items: &'static [(&'static str, i64)],
    /// Unit ("" for none).
    pub unit: &'static str,
    pub description: &'static str,
}

/// `x.is_finite()` by one float comparison (false for NaN), where LLVM makes is_finite an
/// integer test several instructions long: for the checks of every step's calls.
#[inline(always)]
pub fn finite(x: f64) -> bool {
    x.abs() <= f64::MAX
}

/// One FMU's model description: its variables and how value references find them.
#[derive(Debug)]
pub struct Table {
    pub model_identifier: &'static str,
    pub guid: &'static str,
    pub variables: &'static [Variable],
    /// Position in `variables` of each value reference (-1: none).
    pub vr_index: &'static [i32],
    pub log_categories: &'static [&'static str],
}

/// The log categories the shared layer writes to; every FMU declares them.
pub mod log_category {
    pub const LOG_STATUS_ERROR: &str = "logStatusError";
    pub const LOG_STATUS_WARNING: &str = "logStatusWarning";
    pub const LOG_CALLS: &str = "logCalls";
}

impl Table {
    /// Position in `variables` of a value reference, if it names a variable.
    pub const fn index_of(&self, vr: u32) -> Option<usize> {
        if vr as usize >= self.vr_index.len() {
            return None;
        }
        let i = self.vr_index[vr as usize];
        if i < 0 { None } else { Some(i as usize) }
    }

    /// The variable behind `vr`, with its position.
    pub fn variable(&self, vr: u32, function: &str) -> Result<(usize, &'static Variable), Refusal> {
        match self
            .index_of(vr)
            .and_then(|i| self.variables.get(i).map(|v| (i, v)))
        {
            Some(found) => Ok(found),
            None => Err(unknown(vr, function)),
        }
    }

    /// The variable behind `vr`, if it is of the type `ty` the calling function handles
    /// (fmi2Get/SetInteger also serve Enumeration variables).
    pub fn typed_variable(
        &self,
        vr: u32,
        ty: VarType,
        function: &str,
    ) -> Result<(usize, &'static Variable), Refusal> {
        let (index, var) = self.variable(vr, function)?;
        if var.accessed_as(ty) {
            Ok((index, var))
        } else {
            Err(wrong_type(vr, var, function))
        }
    }

    /// Why `vr` has no value to read.
    #[cold]
    pub fn no_value(&self, vr: u32, function: &str) -> Refusal {
        let name = self.index_of(vr).map_or("?", |i| self.variables[i].name);
        refuse(format!("{function}: '{name}' has no value"))
    }

    /// The position of the variable `r` if `value` may be set there in `phase`: of type `ty`, a
    /// parameter (a fixed one only before fmi2ExitInitializationMode) or an input, and an
    /// acceptable value for it.
    #[inline]
    pub fn settable(
        &self,
        phase: Phase,
        r: u32,
        value: f64,
        ty: VarType,
        function: &str,
    ) -> Result<usize, Refusal> {
        let (index, var) = self.typed_variable(r, ty, function)?;
        match var.causality {
            Causality::Parameter => {
                let before_init = matches!(phase, Phase::Instantiated | Phase::InitializationMode);
                if !before_init && var.variability != Variability::Tunable {
                    return Err(refuse(format!(
                        "{function}: '{}' is a fixed parameter and can only be set before fmi2ExitInitializationMode",
                        var.name
                    )));
                }
            }
            // FMI 2.0 (Model Exchange): a discrete input changes at events only.
            Causality::Input
                if phase == Phase::ContinuousTimeMode
                    && var.variability == Variability::Discrete =>
            {
                return Err(refuse(format!(
                    "{function}: '{}' is a discrete input: set it in event mode \
                     (fmi2EnterEventMode), then call fmi2NewDiscreteStates",
                    var.name
                )));
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

    /// fmi2GetRealOutputDerivatives of a slave whose outputs have exact first derivatives: for
    /// each of `vrs`, an output (`output` names which, `None`: not an output) asked for order 1,
    /// its `rate` in the running `model` (`None`: not initialised), handed to `put` with its
    /// position.
    pub fn first_output_derivatives<M: Copy, W>(
        &self,
        model: Option<M>,
        vrs: &[u32],
        orders: &[i32],
        output: impl Fn(u32) -> Option<W>,
        rate: impl Fn(M, W) -> f64,
        mut put: impl FnMut(usize, f64),
    ) -> Reply {
        const F: &str = "fmi2GetRealOutputDerivatives";
        let model = model.ok_or_else(|| refuse(format!("{F}: not initialised")))?;
        for (k, (&r, &order)) in vrs.iter().zip(orders).enumerate() {
            let (_, var) = self.variable(r, F)?;
            let Some(which) = output(r) else {
                return Err(refuse(format!("{F}: '{}' is not an output", var.name)));
            };
            if order != 1 {
                return Err(refuse(format!(
                    "{F}: order {order} of '{}' is not offered (maxOutputDerivativeOrder = 1)",
                    var.name
                )));
            }
            put(k, rate(model, which));
        }
        Ok(Status::Ok)
    }

    /// Checks of fmi2SetRealInputDerivatives for one entry: a Real input, order 1 or up to
    /// `max_order`, a finite value.
    pub fn check_input_derivative(
        &self,
        r: u32,
        order: i32,
        value: f64,
        max_order: i32,
    ) -> Result<&'static Variable, Refusal> {
        const F: &str = "fmi2SetRealInputDerivatives";
        let (_, var) = self.variable(r, F)?;
        if var.causality != Causality::Input || var.ty != VarType::Real {
            return Err(refuse(format!("{F}: '{}' is not a Real input", var.name)));
        }
        if !(1..=max_order).contains(&order) {
            return Err(refuse(format!(
                "{F}: order {order} for '{}' is not supported (1 or {max_order})",
                var.name
            )));
        }
        if !value.is_finite() {
            return Err(refuse(format!(
                "{F}: derivative {value} of '{}' must be finite",
                var.name
            )));
        }
        Ok(var)
    }
}

/// The body of an FMU's model description module: the code its build script writes with the
/// workspace's generator (build/generate.rs) into `$OUT_DIR/model_description.rs` (`VARIABLES`,
/// `vr::*`, `GUID`, ...), that table as the shared layer reads it (`TABLE`), and `index_of`.
/// The module brings the types the generated code names into scope first
/// (`pub use fmi2_slave::description::{Causality, Table, VarType, Variability, Variable};`).
#[macro_export]
macro_rules! model_description {
    () => {
        include!(concat!(env!("OUT_DIR"), "/model_description.rs"));

        /// The table as the shared FMI layer reads it.
        pub const TABLE: $crate::description::Table = $crate::description::Table {
            model_identifier: MODEL_IDENTIFIER,
            guid: GUID,
            variables: VARIABLES,
            vr_index: &VR_INDEX,
            log_categories: &LOG_CATEGORIES,
        };

        /// Position in [`VARIABLES`] of a value reference, if it names a variable.
        pub const fn index_of(vr: u32) -> Option<usize> {
            TABLE.index_of(vr)
        }
    };
}

#[cold]
pub fn unknown(vr: u32, function: &str) -> Refusal {
    refuse(format!("{function}: unknown value reference {vr}"))
}

#[cold]
pub fn wrong_type(vr: u32, var: &Variable, function: &str) -> Refusal {
    refuse(format!(
        "{function}: '{}' (value reference {vr}) is of type {:?}",
        var.name, var.ty
    ))
}

impl Variable {
    /// Whether the getters and setters of type `ty` address this variable: its own type, and
    /// the Integer ones Enumerations too (FMI 2.0 has no Enumeration getter).
    pub const fn accessed_as(&self, ty: VarType) -> bool {
        self.ty as u8 == ty as u8
            || (matches!(ty, VarType::Integer) && matches!(self.ty, VarType::Enumeration))
    }

    /// Why `value` is not acceptable for this variable, if it is not.
    #[inline]
    pub fn reject(&self, value: f64) -> Option<String> {
        // The common case, a finite Real within its bounds, decided inline; any other goes
        // to the full check, which also words the reason.
        let within = finite(value)
            && self.ty != VarType::Enumeration
            && self.min.is_none_or(|min| value >= min)
            && self.max.is_none_or(|max| value <= max);
        if within { None } else { self.reason(value) }
    }

    #[cold]
    fn reason(&self, value: f64) -> Option<String> {
        if !value.is_finite() {
            return Some(format!(
                "'{}' cannot be set to {value}: the value must be finite",
                self.name
            ));
        }
        if self.ty == VarType::Enumeration {
            if !self.items.iter().any(|(_, v)| *v as f64 == value) {
                let list: Vec<String> = self
                    .items
                    .iter()
                    .map(|(n, v)| format!("{v} = {n}"))
                    .collect();
                return Some(format!(
                    "'{}' cannot be set to {value}: not an item of its enumeration ({})",
                    self.name,
                    list.join(", ")
                ));
            }
            return None;
        }
        if let Some(min) = self.min
            && value < min
        {
            return Some(format!(
                "'{}' = {value} is below its minimum {min}",
                self.name
            ));
        }
        if let Some(max) = self.max
            && value > max
        {
            return Some(format!(
                "'{}' = {value} is above its maximum {max}",
                self.name
            ));
        }
        None
    }
}

#[cfg(test)]
#[path = "description_tests.rs"]
mod tests;
