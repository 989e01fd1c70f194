//! The one place where the models are listed: each under the value of its item in the `model`
//! enumeration of modelDescription.xml. A new model is its module and one line here.

use super::{Common, Interval, Model, Observable, Output, Parameters, Start, StepError, Stepped};

macro_rules! registry {
    ($( $item:literal => $variant:ident($model:ty) ),* $(,)?) => {
        /// The model an instance runs, chosen by the `model` parameter. An enum rather than a
        /// trait object: every call dispatches by one match, which the compiler can inline.
        // One per instance: the size difference costs nothing, boxing would add an indirection
        // to every step.
        #[allow(clippy::large_enum_variant)]
        #[derive(Clone, Debug, PartialEq)]
        pub enum AnyModel {
            $( $variant($model), )*
        }

        impl AnyModel {
            /// The model of the `model` item `item`, configured.
            pub fn configure(
                item: i64,
                p: &dyn Parameters,
                common: &Common,
                start: Start,
            ) -> Result<Self, String> {
                match item {
                    $( $item => <$model>::configure(p, common, start).map(AnyModel::$variant), )*
                    other => Err(format!("model = {other} is no model of this FMU")),
                }
            }

            /// The `model` items there are.
            pub const ITEMS: &[i64] = &[$( $item ),*];

            #[inline(always)]
            pub fn sloshing_mass(&self) -> f64 {
                match self { $( AnyModel::$variant(m) => m.sloshing_mass(), )* }
            }

            #[inline(always)]
            pub fn step(&mut self, step: &Interval) -> Result<Stepped, StepError> {
                match self { $( AnyModel::$variant(m) => m.step(step), )* }
            }

            #[inline(always)]
            pub fn sloshing(&self) -> (f64, f64) {
                match self { $( AnyModel::$variant(m) => m.sloshing(), )* }
            }

            pub fn force(&self) -> f64 {
                match self { $( AnyModel::$variant(m) => m.force(), )* }
            }

            pub fn rigid_mass(&self) -> f64 {
                match self { $( AnyModel::$variant(m) => m.rigid_mass(), )* }
            }

            pub fn observe(&self, which: Observable) -> f64 {
                match self { $( AnyModel::$variant(m) => m.observe(which), )* }
            }

            pub fn rate(&self, which: Output, a: f64, a_rate: f64) -> f64 {
                match self { $( AnyModel::$variant(m) => m.rate(which, a, a_rate), )* }
            }

            pub fn set_damping(&mut self, zeta: f64) {
                match self { $( AnyModel::$variant(m) => m.set_damping(zeta), )* }
            }

            pub fn state_len(&self) -> usize {
                match self { $( AnyModel::$variant(m) => m.state_len(), )* }
            }

            pub fn save(&self, out: &mut Vec<f64>) {
                match self { $( AnyModel::$variant(m) => m.save(out), )* }
            }

            pub fn load(&mut self, state: &[f64]) -> Result<(), String> {
                match self { $( AnyModel::$variant(m) => m.load(state), )* }
            }
        }
    };
}

registry! {
    1 => Linear(super::linear::Linear),
    2 => Nonlinear(super::nonlinear::Nonlinear),
    3 => SloshingSlamming(super::slamming::SloshingSlamming),
    4 => Auto(super::auto::NonlinearAuto),
}
