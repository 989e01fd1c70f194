//! From the variable values the host set to the physics configuration. The only place that
//! maps FMI variable names onto the simulation's inputs and outputs.

use super::vars::{Causality, VARIABLES, VR_INDEX, VarType, Variability, index_of, vr};
use crate::model::{Derived, InputAt, Inputs, Output, PER_STEP, Parameters};

/// The variables of the first build with saved-state format version 1 (modelDescription.xml
/// up to solver_id); variables added since are appended after them.
pub const VERSION_1_VARIABLES: usize = 54;

/// Values of all variables, in the order of `VARIABLES` (integers and enumerations as f64).
#[derive(Clone, Debug, PartialEq)]
pub struct Values([f64; VARIABLES.len()]);

/// Position in `VARIABLES` of a variable known at compile time (the build fails if `vr` names
/// none): the inputs, read on every step, then cost one load.
const fn slot(vr: u32) -> usize {
    let i = VR_INDEX[vr as usize];
    assert!(i >= 0 && (i as usize) < VARIABLES.len());
    i as usize
}
const BASE_A: usize = slot(vr::BASE_A);
const BASE_V: usize = slot(vr::BASE_V);

impl Values {
    /// Start values from the model description (NaN where a variable has none).
    pub fn start() -> Self {
        Values(std::array::from_fn(|i| {
            VARIABLES[i].start.unwrap_or(f64::NAN)
        }))
    }

    /// Values checked one by one against the model description (finite, in range, an
    /// enumeration item); calculated variables carry no value and are ignored.
    pub fn from_saved(saved: &[f64]) -> Result<Self, String> {
        // Variables added after the first version-1 build are listed only up to the last one
        // away from its start ([`Values::to_saved`]); the others keep their start values.
        if !(VERSION_1_VARIABLES..=VARIABLES.len()).contains(&saved.len()) {
            return Err(format!(
                "{} values for {} variables",
                saved.len(),
                VARIABLES.len()
            ));
        }
        let mut values = Values::start();
        for ((slot, var), &value) in values.0.iter_mut().zip(VARIABLES).zip(saved) {
            if var.start.is_some() {
                if let Some(reason) = var.reject(value) {
                    return Err(reason);
                }
                *slot = value;
            }
        }
        Ok(values)
    }

    /// The values a saved state lists: the variables of the first version-1 build always, the
    /// ones added since (appended to the model description, never inserted) up to the last one
    /// not at its start value. A state of a run that leaves the new variables alone is then
    /// byte for byte the state the earlier builds wrote, and their states restore here.
    pub fn to_saved(&self) -> &[f64] {
        let start = Values::start();
        let mut n = self.0.len();
        while n > VERSION_1_VARIABLES && self.0[n - 1].to_bits() == start.0[n - 1].to_bits() {
            n -= 1;
        }
        &self.0[..n]
    }

    pub fn get(&self, vr: u32) -> f64 {
        index_of(vr)
            .and_then(|i| self.0.get(i))
            .copied()
            .unwrap_or(f64::NAN)
    }

    pub fn at(&self, index: usize) -> f64 {
        self.0.get(index).copied().unwrap_or(f64::NAN)
    }

    pub fn set_at(&mut self, index: usize, value: f64) {
        if let Some(slot) = self.0.get_mut(index) {
            *slot = value;
        }
    }

    /// The inputs, with the derivatives of base.a the host set for the coming step.
    #[inline(always)]
    pub fn inputs(&self, a_derivatives: [f64; 2]) -> Inputs {
        Inputs {
            a: self.0[BASE_A],
            // Read on its own (black_box: a value the compiler cannot merge with base.a's), so
            // that base.a is one 8-byte load. Merged, the two are one 16-byte load over base.a's
            // 8-byte store in the fmi2SetReal just before, which the processor cannot forward:
            // the load then waits for the store to reach the cache, on the path from base.a
            // to the first evaluation (measured on Co-Simulation's step, RK4 one substep:
            // 57.9 -> 54.3 ns per step; that step now reads base.a through `input_at`, and
            // this serves Model Exchange's right-hand side and the output reads, which follow
            // fmi2SetReal the same way).
            v: std::hint::black_box(self.0[BASE_V]),
            a_derivatives,
        }
    }

    /// Where base.a and base.v are, for [`crate::model::Damper::step_at`]: base.a is read
    /// alone before the step (one 8-byte load, which the processor forwards from
    /// fmi2SetReal's store just before), base.v only by an amplitude tracker.
    #[inline(always)]
    pub fn input_at(&self) -> InputAt<'_> {
        InputAt {
            a: &self.0[BASE_A],
            v: &self.0[BASE_V],
        }
    }
}

/// The Integer aliases that override enumerations (hosts that cannot set Enumeration variables,
/// such as libcosim, use the alias); 0, their start value, leaves the enumeration in force.
const ALIASES: [(u32, u32); 5] = [
    (vr::MODEL, vr::MODEL_ID),
    (vr::DAMPING, vr::DAMPING_ID),
    (vr::AMPLITUDE, vr::AMPLITUDE_ID),
    (vr::SOLVER, vr::SOLVER_ID),
    (vr::SCREENS_RESPONSE, vr::SCREENS_RESPONSE_ID),
];

/// The parameters as the models read them: the values the host set, each enumeration
/// overridden by its Integer alias when that is set, and the experiment's tolerance in place of
/// solver.tolerance unless the user set that explicitly.
pub struct Configuration<'a> {
    pub values: &'a Values,
    pub tolerance: Option<f64>,
    pub user_tolerance: bool,
}

impl Parameters for Configuration<'_> {
    fn value(&self, r: u32) -> f64 {
        if r == vr::SOLVER_TOLERANCE
            && let Some(tol) = self.tolerance
            && !self.user_tolerance
        {
            return tol;
        }
        if let Some(&(_, alias)) = ALIASES.iter().find(|(e, _)| *e == r) {
            let a = self.values.get(alias);
            if a > 0.0 {
                return a;
            }
        }
        self.values.get(r)
    }
}

/// The value of a calculated parameter, by value reference.
pub fn derived_value(vr: u32, derived: &Derived) -> Option<f64> {
    Some(match vr {
        vr::OMEGA_F => derived.omega_f,
        vr::MASS_LIQUID => derived.mass_liquid,
        vr::MASS_SLOSH => derived.mass_slosh,
        vr::MASS_INACTIVE => derived.mass_inactive,
        _ => return None,
    })
}

/// Where a get of the variable `vr` as type `ty` finds its value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Source {
    /// No variable has this value reference.
    Unknown,
    /// The variable at this position in `VARIABLES` is of another type.
    WrongType(usize),
    /// The variable at this position has no value (a calculated variable nothing computes).
    NoValue(usize),
    /// A value the host set or a start value, at this position in `VARIABLES`.
    Stored(usize),
    /// A calculated parameter, from the configuration ([`derived_value`]).
    Derived,
    /// A simulation output.
    Output(Output),
}

/// Where `vr`, read as type `ty`, comes from; Integer reads Enumeration variables too. A const
/// fn: the table for Real, read on every step, is built by the compiler.
pub const fn source(vr: u32, ty: VarType) -> Source {
    let index = match index_of(vr) {
        Some(i) => i,
        None => return Source::Unknown,
    };
    let var = &VARIABLES[index];
    if !var.accessed_as(ty) {
        return Source::WrongType(index);
    }
    match var.causality {
        Causality::Parameter | Causality::Input => Source::Stored(index),
        // The locals are Model Exchange's state derivatives, computed (fmi/me.rs).
        Causality::Local => Source::NoValue(index),
        Causality::CalculatedParameter => Source::Derived,
        Causality::Output => match output_of(vr) {
            Some(which) => Source::Output(which),
            None => Source::NoValue(index),
        },
    }
}

/// [`source`] for every value reference, read as Real.
pub static REAL_SOURCES: [Source; VR_INDEX.len()] = {
    let mut table = [Source::Unknown; VR_INDEX.len()];
    let mut vr = 0;
    while vr < table.len() {
        table[vr] = source(vr as u32, VarType::Real);
        vr += 1;
    }
    table
};

/// [`source`], from the table for Real.
#[inline(always)]
pub fn source_of(vr: u32, ty: VarType) -> Source {
    match ty {
        VarType::Real => REAL_SOURCES
            .get(vr as usize)
            .copied()
            .unwrap_or(Source::Unknown),
        _ => source(vr, ty),
    }
}

/// fmi2GetReal's quick read of `vr` (`Tld::quick_reals`), one code per value reference: i,
/// the stored value at position i; [`QUICK_OUTPUT`] + k, the damper's per-step output k
/// ([`crate::model::Damper::per_step`]), k = [`PER_STEP`] (its infinity) for none: the full
/// path.
/// The compiler builds it from [`REAL_SOURCES`].
pub static QUICK_REALS: [u16; VR_INDEX.len()] = {
    let mut table = [QUICK_NONE; VR_INDEX.len()];
    let mut vr = 0;
    while vr < table.len() {
        table[vr] = match REAL_SOURCES[vr] {
            Source::Stored(index) => {
                assert!(index < QUICK_OUTPUT as usize);
                index as u16
            }
            Source::Output(which) if (which as usize) < PER_STEP => QUICK_OUTPUT + which as u16,
            _ => QUICK_NONE,
        };
        vr += 1;
    }
    table
};

/// The first code of a per-step output in [`QUICK_REALS`], and the code of none.
pub const QUICK_OUTPUT: u16 = 0x8000;
pub const QUICK_NONE: u16 = QUICK_OUTPUT + PER_STEP as u16;

/// Where fmi2SetReal stores `vr` with no check but that the value is finite: a continuous Real
/// input without bounds (a discrete one is set in event mode only: the full check; what `Instance::check_set` then checks, in every phase that allows sets).
/// None for any other variable, which goes through the full check. A table the compiler
/// builds, read on every step.
const FREE_REAL_INPUTS: [Option<u8>; VR_INDEX.len()] = {
    let mut table = [None; VR_INDEX.len()];
    let mut vr = 0;
    while vr < table.len() {
        if let Some(index) = index_of(vr as u32) {
            let var = &VARIABLES[index];
            if matches!(var.causality, Causality::Input)
                && matches!(var.variability, Variability::Continuous)
                && matches!(var.ty, VarType::Real)
                && var.min.is_none()
                && var.max.is_none()
                && index <= u8::MAX as usize
            {
                table[vr] = Some(index as u8);
            }
        }
        vr += 1;
    }
    table
};

// The quick setter stores a free input and nothing else (`Tld::set_quietly`): never the one
// variable whose set raises a flag too (`Tld::put`).
const _: () = assert!(FREE_REAL_INPUTS[vr::SOLVER_TOLERANCE as usize].is_none());

/// [`FREE_REAL_INPUTS`] of `vr`.
#[inline(always)]
pub fn free_real_input(vr: u32) -> Option<usize> {
    FREE_REAL_INPUTS
        .get(vr as usize)
        .copied()
        .flatten()
        .map(usize::from)
}

/// The simulation output an output variable shows, by value reference.
pub const fn output_of(vr: u32) -> Option<Output> {
    Some(match vr {
        vr::FORCE => Output::Force,
        vr::FORCE_MEAN => Output::ForceMean,
        vr::BASE_SHEAR => Output::BaseShear,
        vr::SLOSH_X => Output::X,
        vr::SLOSH_V => Output::V,
        vr::ENERGY_INPUT => Output::EnergyInput,
        vr::ENERGY_DISSIPATED => Output::EnergyDissipated,
        vr::ENERGY_STORED => Output::EnergyStored,
        vr::A_E_ESTIMATE => Output::Amplitude,
        vr::ZETA_EFFECTIVE => Output::Zeta,
        vr::IMPACT_Z => Output::ImpactZ,
        vr::IMPACTS => Output::Impacts,
        vr::IMPACT_IMPULSE => Output::ImpactImpulse,
        vr::SURFACE_LEFT => Output::SurfaceLeft,
        vr::SURFACE_RIGHT => Output::SurfaceRight,
        _ => return None,
    })
}

#[cfg(test)]
#[path = "params_tests.rs"]
mod saved_tests;

#[cfg(test)]
mod tests {
    use super::*;

    fn slot_of(r: u32) -> usize {
        index_of(r).expect("a declared variable")
    }

    /// The models see each enumeration through its Integer alias once that is set, and the
    /// experiment's tolerance unless solver.tolerance was set explicitly.
    #[test]
    fn the_models_see_aliases_and_the_experiments_tolerance() {
        let mut values = Values::start();
        let seen = |values: &Values, user_tolerance| {
            let c = Configuration {
                values,
                tolerance: Some(1e-6),
                user_tolerance,
            };
            (
                ALIASES.map(|(e, _)| c.value(e)),
                c.value(vr::SOLVER_TOLERANCE),
            )
        };
        let starts = ALIASES.map(|(e, _)| values.get(e));
        assert_eq!(seen(&values, false), (starts, 1e-6));
        assert_eq!(seen(&values, true).1, values.get(vr::SOLVER_TOLERANCE));
        for (k, (enumeration, alias)) in ALIASES.into_iter().enumerate() {
            // An item other than the enumeration's own value.
            let other = if values.get(enumeration) == 1.0 {
                2.0
            } else {
                1.0
            };
            values.set_at(slot_of(alias), other);
            assert_eq!(seen(&values, false).0[k], other, "alias of {enumeration}");
        }
    }
}
