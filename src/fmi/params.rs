//! From the variable values the host set to the physics configuration. The only place that
//! maps FMI variable names onto the simulation's inputs and outputs.

use super::vars::{Causality, VARIABLES, VR_INDEX, VarType, index_of, vr};
use crate::physics::geometry::Tank;
use crate::physics::laws::{DampingLaw, LambdaRange};
use crate::simulation::{
    AdaptiveKind, AmplitudeSource, Config, Derived, FixedFormula, Inputs, Method, ModelKind,
    Output, SlammingParams,
};

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
const BASE_X: usize = slot(vr::BASE_X);

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
        if saved.len() != VARIABLES.len() {
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

    pub fn as_slice(&self) -> &[f64] {
        &self.0
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
    pub fn inputs(&self, a_derivatives: [f64; 2]) -> Inputs {
        Inputs {
            a: self.0[BASE_A],
            v: self.0[BASE_V],
            x: self.0[BASE_X],
            a_derivatives,
        }
    }

    /// An enumeration's value, or its Integer alias when that is set (hosts that cannot set
    /// Enumeration variables, such as libcosim, use the alias).
    fn option(&self, enumeration: u32, alias: u32) -> f64 {
        let a = self.get(alias);
        if a > 0.0 { a } else { self.get(enumeration) }
    }

    /// The configuration these values describe. `tolerance` is the experiment's tolerance, used
    /// unless the user set solver.tolerance explicitly.
    pub fn config(&self, tolerance: Option<f64>, user_tolerance: bool) -> Config {
        let g = |r| self.get(r);
        let damping = if self.option(vr::DAMPING, vr::DAMPING_ID) == 1.0 {
            DampingLaw::Constant(g(vr::ZETA))
        } else {
            DampingLaw::Nsd {
                c: g(vr::NSD_C),
                p: g(vr::NSD_P),
            }
        };
        let amplitude = if self.option(vr::AMPLITUDE, vr::AMPLITUDE_ID) == 2.0 {
            AmplitudeSource::Tracked {
                tau: g(vr::AMPLITUDE_TAU),
                prior: g(vr::A_E),
            }
        } else {
            AmplitudeSource::Fixed(g(vr::A_E))
        };
        let rtol = match tolerance {
            Some(tol) if !user_tolerance => tol,
            _ => g(vr::SOLVER_TOLERANCE),
        };
        // The items of the SolverMethod enumeration (modelDescription.xml).
        let adaptive = |kind| Method::Adaptive {
            kind,
            rtol,
            max_step: g(vr::SOLVER_MAX_STEP),
        };
        let fixed = |formula| Method::Fixed {
            formula,
            step: g(vr::SOLVER_FIXED_STEP),
        };
        let method = match self.option(vr::SOLVER, vr::SOLVER_ID) as i64 {
            2 => fixed(FixedFormula::Rk4),
            3 => adaptive(AdaptiveKind::Sdirk4),
            4 => adaptive(AdaptiveKind::Auto),
            5 => adaptive(AdaptiveKind::DormandPrince853),
            6 => fixed(FixedFormula::Rk5),
            7 => fixed(FixedFormula::Rk8),
            8 => fixed(FixedFormula::ExpRk4),
            _ => adaptive(AdaptiveKind::DormandPrince),
        };
        let model = match self.option(vr::MODEL, vr::MODEL_ID) as i64 {
            1 => ModelKind::Linear {
                modes: g(vr::MODES) as u32,
            },
            3 => ModelKind::SloshingSlamming(SlammingParams {
                omega: g(vr::SLAMMING_OMEGA),
                restitution: g(vr::SLAMMING_RESTITUTION),
                clearance: g(vr::SLAMMING_CLEARANCE),
                mass_ratio: g(vr::SLAMMING_MASS_RATIO),
            }),
            4 => ModelKind::NonlinearAuto {
                threshold: g(vr::AUTO_THRESHOLD),
            },
            _ => ModelKind::Nonlinear,
        };
        Config {
            model,
            tank: Tank {
                length: g(vr::TANK_LENGTH),
                breadth: g(vr::TANK_BREADTH),
                depth: g(vr::TANK_DEPTH),
                density: g(vr::LIQUID_DENSITY),
                g: g(vr::G),
            },
            tanks: g(vr::TANKS) as u32,
            eta: g(vr::ETA),
            phi: g(vr::PHI),
            damping,
            lambda: LambdaRange {
                min: g(vr::LAMBDA_MIN),
                max: g(vr::LAMBDA_MAX),
            },
            amplitude,
            x0: g(vr::SLOSH_X0),
            v0: g(vr::SLOSH_V0),
            method,
            max_substeps: g(vr::SOLVER_MAX_SUBSTEPS) as u64,
        }
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
        Causality::Parameter | Causality::Input | Causality::Local => Source::Stored(index),
        Causality::CalculatedParameter => Source::Derived,
        Causality::Output => match output_of(vr) {
            Some(which) => Source::Output(which),
            None => Source::NoValue(index),
        },
    }
}

/// [`source`] for every value reference, read as Real.
pub const REAL_SOURCES: [Source; VR_INDEX.len()] = {
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

/// Where fmi2SetReal stores `vr` with no check but that the value is finite: a Real input
/// without bounds (what `Instance::check_set` then checks, in every phase that allows sets).
/// None for any other variable, which goes through the full check. A table the compiler
/// builds, read on every step.
const FREE_REAL_INPUTS: [Option<u8>; VR_INDEX.len()] = {
    let mut table = [None; VR_INDEX.len()];
    let mut vr = 0;
    while vr < table.len() {
        if let Some(index) = index_of(vr as u32) {
            let var = &VARIABLES[index];
            if matches!(var.causality, Causality::Input)
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
        _ => return None,
    })
}
