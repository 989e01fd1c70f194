//! The model description as Rust, shared by the FMI layer and the models: what the build
//! script (build/) generates from modelDescription/modelDescription.xml, and the types it uses:
//! - `VARIABLES` (the variable table) and `vr::*` (value references, `.` becomes `_`);
//! - one enum per enumeration type, named after it with `Item` appended (`ModelKindItem`,
//!   `DampingLawItem`, `AmplitudeModeItem`, `SolverMethodItem`): the XML's items as variants with
//!   their values as discriminants, `ALL`, `from_value`/`from_f64`/`TryFrom<i64>`, `value()`,
//!   `name()`, `description()`;
//! - `LOG_CATEGORIES` and `log_category::*` (one constant per category);
//! - `limits::*`: the declared bounds (`limits::MODES_MAX` is the max of `modes`).

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

include!(concat!(env!("OUT_DIR"), "/model_description.rs"));

/// `x.is_finite()` by one float comparison (false for NaN), where LLVM makes is_finite an
/// integer test several instructions long: for the checks of every step's calls.
#[inline(always)]
pub fn finite(x: f64) -> bool {
    x.abs() <= f64::MAX
}

/// Position in [`VARIABLES`] of a value reference, if it names a variable.
pub const fn index_of(vr: u32) -> Option<usize> {
    if vr as usize >= VR_INDEX.len() {
        return None;
    }
    let i = VR_INDEX[vr as usize];
    if i < 0 { None } else { Some(i as usize) }
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
