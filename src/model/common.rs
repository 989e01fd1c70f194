//! The parameters every model shares: the tanks, the amplitude laws, the initial condition.

use super::{Parameters, choice};
use crate::description::{
    AmplitudeModeItem, DampingLawItem, ModelKindItem, ScreensResponseItem, vr,
};
use crate::physics::geometry::Tank;
use crate::physics::laws::{DampingLaw, LambdaRange, boundary_layer_zeta};
use crate::physics::screens::Arrangement;

/// Where the excitation amplitude of the amplitude laws comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AmplitudeSource {
    /// A design amplitude [m].
    Fixed(f64),
    /// Estimated online; `tau` [s] is the filter time constant (0: two sloshing periods),
    /// `prior` [m] the value used before the base has moved.
    Tracked { tau: f64, prior: f64 },
}

/// The shared parameters, as read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Common {
    pub tank: Tank,
    /// Number of identical tanks acting together.
    pub tanks: u32,
    pub damping: DampingLaw,
    pub lambda: LambdaRange,
    pub amplitude: AmplitudeSource,
    /// The damping screens of each tank.
    pub screens: Arrangement,
    /// Initial relative displacement [m] and velocity [m/s] of the (fundamental) sloshing mass.
    pub x0: f64,
    pub v0: f64,
}

/// Quantities computed from the configuration (totals over all tanks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Derived {
    pub omega_f: f64,
    pub mass_liquid: f64,
    pub mass_slosh: f64,
    pub mass_inactive: f64,
}

impl Common {
    /// The shared parameters and the warnings they deserve; Err if they cannot be simulated.
    pub fn read(p: &dyn Parameters) -> Result<(Self, Vec<String>), String> {
        let tank = Tank {
            length: p.value(vr::TANK_LENGTH),
            breadth: p.value(vr::TANK_BREADTH),
            depth: p.value(vr::TANK_DEPTH),
            density: p.value(vr::LIQUID_DENSITY),
            g: p.value(vr::G),
        };
        let screens = Arrangement {
            count: p.count(vr::SCREENS_COUNT),
            solidity: p.value(vr::SCREENS_SOLIDITY),
            spacing: p.value(vr::SCREENS_SPACING),
            loss: p.value(vr::SCREENS_LOSS),
        };
        screens.check(tank.length)?;
        let boundary = || {
            boundary_layer_zeta(
                tank.fundamental().omega,
                tank.depth,
                tank.breadth,
                p.value(vr::LIQUID_VISCOSITY),
                p.value(vr::DAMPING_CONTAMINATION),
            )
        };
        let damping = match choice(p, vr::DAMPING)? {
            DampingLawItem::Constant => DampingLaw::Constant(p.value(vr::ZETA)),
            DampingLawItem::NSD => DampingLaw::Nsd {
                c: p.value(vr::NSD_C),
                p: p.value(vr::NSD_P),
            },
            DampingLawItem::BoundaryLayer => DampingLaw::BoundaryLayer(boundary()),
            DampingLawItem::Screens => DampingLaw::Screens {
                boundary: boundary(),
                per_response: screens
                    .zeta_per_response(tank.length, tank.fundamental().mass / tank.liquid_mass()),
                random: choice::<ScreensResponseItem>(p, vr::SCREENS_RESPONSE)?
                    == ScreensResponseItem::Random,
            },
        };
        let amplitude = match choice(p, vr::AMPLITUDE)? {
            AmplitudeModeItem::Fixed => AmplitudeSource::Fixed(p.value(vr::A_E)),
            AmplitudeModeItem::Tracked => AmplitudeSource::Tracked {
                tau: p.value(vr::AMPLITUDE_TAU),
                prior: p.value(vr::A_E),
            },
        };
        if let DampingLaw::Screens { random: true, .. } = damping
            && matches!(amplitude, AmplitudeSource::Tracked { .. })
            && choice::<ModelKindItem>(p, vr::MODEL)? != ModelKindItem::ShallowWater
        {
            return Err(
                "screens.response = Random takes A_e as the design rms response sigma_X \
                 of slosh.x: set amplitude = Fixed (Tracked estimates a harmonic base amplitude)"
                    .into(),
            );
        }
        let common = Common {
            tank,
            tanks: p.count(vr::TANKS),
            damping,
            lambda: LambdaRange {
                min: p.value(vr::LAMBDA_MIN),
                max: p.value(vr::LAMBDA_MAX),
            },
            amplitude,
            screens,
            x0: p.value(vr::SLOSH_X0),
            v0: p.value(vr::SLOSH_V0),
        };
        let warnings = common.check()?;
        Ok((common, warnings))
    }

    /// Checks that involve several parameters. Ok(warnings): simulable, outside the model's
    /// stated validity where a warning says so.
    fn check(&self) -> Result<Vec<String>, String> {
        let mut warnings = Vec::new();
        if self.lambda.min > self.lambda.max {
            return Err(format!(
                "lambda.min ({}) must not exceed lambda.max ({})",
                self.lambda.min, self.lambda.max
            ));
        }
        if self.tank.depth >= self.tank.length {
            return Err(format!(
                "tank.depth ({} m) must be smaller than tank.length ({} m) for a sloshing tank",
                self.tank.depth, self.tank.length
            ));
        }
        let r = self.tank.depth_ratio();
        if r > 0.15 {
            warnings.push(format!(
                "depth ratio h/a = {r:.3} exceeds 0.15: the shallow-water model is outside its validity"
            ));
        }
        // Tuned to buildings, a damper sloshes with a period of about 0.2 to 20 s; a period far
        // outside that most likely means lengths in other units than metres.
        let period = 2.0 * std::f64::consts::PI / self.tank.fundamental().omega;
        if !(0.05..=60.0).contains(&period) {
            warnings.push(format!(
                "tank.length = {} m and tank.depth = {} m give a sloshing period of {period:.3} s, \
                 far from any structure's: are the lengths in metres (not cm or mm)?",
                self.tank.length, self.tank.depth
            ));
        }
        if self.x0.abs() > self.tank.length {
            return Err(format!(
                "|slosh.x0| = {} m exceeds the tank length {} m",
                self.x0.abs(),
                self.tank.length
            ));
        }
        Ok(warnings)
    }

    /// The damping ratio of the sloshing modes for the excitation amplitude `amplitude`.
    pub fn zeta(&self, amplitude: f64) -> f64 {
        self.damping.zeta(amplitude, self.tank.length, self.lambda)
    }

    /// d zeta / d amplitude of [`Common::zeta`].
    pub fn zeta_slope(&self, amplitude: f64) -> f64 {
        self.damping
            .zeta_slope(amplitude, self.tank.length, self.lambda)
    }

    /// Total liquid mass, all tanks [kg].
    pub fn liquid_mass(&self) -> f64 {
        self.tank.liquid_mass() * f64::from(self.tanks)
    }
}
