//! How a model reads its parameters: by value reference, from whoever holds the values (the FMI
//! layer's variable values, or start values with overrides in tests and tools).

use crate::description::{VARIABLES, index_of};

/// The name of the variable `vr`, for messages.
fn name_of(vr: u32) -> &'static str {
    index_of(vr).map_or("?", |i| VARIABLES[i].name)
}

/// Parameter values by value reference. Integer and enumeration values come as f64.
pub trait Parameters {
    /// The value of the parameter `vr` (NaN if there is none).
    fn value(&self, vr: u32) -> f64;

    /// An Integer parameter (a count), which the model description bounds.
    fn count(&self, vr: u32) -> u32 {
        self.value(vr) as u32
    }

    /// The value of an enumeration's item.
    fn item(&self, vr: u32) -> i64 {
        self.value(vr) as i64
    }
}

/// The item of the enumeration `vr` that `p` holds, or the reason there is none.
pub fn choice<T: TryFrom<i64>>(p: &dyn Parameters, vr: u32) -> Result<T, String> {
    let value = p.item(vr);
    T::try_from(value).map_err(|_| format!("{value} is no item of '{}'", name_of(vr)))
}

/// The model description's start values, with some values overridden.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StartValues {
    overrides: Vec<(u32, f64)>,
}

impl StartValues {
    /// These values with `vr` set to `value`.
    pub fn with(mut self, vr: u32, value: f64) -> Self {
        self.overrides.retain(|(r, _)| *r != vr);
        self.overrides.push((vr, value));
        self
    }
}

impl Parameters for StartValues {
    fn value(&self, vr: u32) -> f64 {
        if let Some((_, v)) = self.overrides.iter().find(|(r, _)| *r == vr) {
            return *v;
        }
        index_of(vr)
            .and_then(|i| VARIABLES[i].start)
            .unwrap_or(f64::NAN)
    }
}
