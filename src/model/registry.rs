//! The one place where the models are listed: each under the value of its item in the `model`
//! enumeration of modelDescription.xml. A new model is its module and one line here.

use super::{Common, Interval, Model, Observable, Output, Parameters, Start, StepError, Stepped};
use crate::description::ModelKindItem;
use crate::physics::base::BaseAcceleration;

macro_rules! registry {
    ($( $item:ident => $variant:ident($model:ty) ),* $(,)?) => {
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
            /// The model of the `model` item `item`, configured. Every item must be here: an
            /// item added to the XML and not registered does not compile.
            pub fn configure(
                item: ModelKindItem,
                p: &dyn Parameters,
                common: &Common,
                start: Start,
            ) -> Result<Self, String> {
                match item {
                    $( ModelKindItem::$item => {
                        <$model>::configure(p, common, start).map(AnyModel::$variant)
                    } )*
                }
            }

            /// The registered `model` items.
            pub const ITEMS: &[ModelKindItem] = &[$( ModelKindItem::$item ),*];

            #[inline(always)]
            pub fn sloshing_mass(&self) -> f64 {
                match self { $( AnyModel::$variant(m) => m.sloshing_mass(), )* }
            }

            /// [`Model::step`] over the interval of these parts. Each model's arm makes its own
            /// [`Interval`]: one made before the match would be stored to memory for the models
            /// that take it by reference, and read back by those whose step is inlined (the
            /// nonlinear ones take it in registers).
            #[inline(always)]
            #[allow(clippy::too_many_arguments)]
            pub fn step(
                &mut self,
                t: f64,
                h: f64,
                zeta: f64,
                a: [f64; 3],
                limit: f64,
            ) -> Result<Stepped, StepError> {
                match self {
                    $( AnyModel::$variant(m) => m.step(&Interval {
                        t,
                        h,
                        zeta,
                        base: BaseAcceleration { t0: 0.0, a },
                        limit,
                    }), )*
                }
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

            pub fn surface(&self) -> Option<[f64; 2]> {
                match self { $( AnyModel::$variant(m) => m.surface(), )* }
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

            pub fn extra(&self) -> f64 {
                match self { $( AnyModel::$variant(m) => m.extra(), )* }
            }

            pub fn load_extra(&mut self, x: f64) -> Result<(), String> {
                match self { $( AnyModel::$variant(m) => m.load_extra(x), )* }
            }
        }
    };
}

registry! {
    Linear => Linear(super::linear::Linear),
    Nonlinear => Nonlinear(super::nonlinear::Nonlinear),
    SloshingSlamming => SloshingSlamming(super::slamming::SloshingSlamming),
    Auto => Auto(super::auto::NonlinearAuto),
    ShallowWater => ShallowWater(super::shallow_water::ShallowWater),
}
