//! The arguments a call of the call-sequence target takes, as they decode from bytes (through
//! `arbitrary`): value references, Reals, Integers, steps and array lengths a host may hand over.

use arbitrary::Arbitrary;

/// A value reference: one of the model description's (the `n`-th, modulo their number) or any.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Vr {
    Known(u8),
    Any(u32),
}

/// A real number: mostly small (`Milli(n)` is n / 1000), some special, some any bit pattern.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Real {
    Milli(i16),
    Special(u8),
    Bits(f64),
}

const SPECIAL: [f64; 16] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    1e-12,
    1e-300,
    -1e-300,
    1e300,
    -1e300,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::MIN_POSITIVE,
    f64::MAX,
    1e6,
    100.0,
];

impl Real {
    pub fn value(self) -> f64 {
        match self {
            Real::Milli(n) => f64::from(n) / 1000.0,
            Real::Special(i) => SPECIAL[usize::from(i) % SPECIAL.len()],
            Real::Bits(x) => x,
        }
    }
}

/// An integer: mostly small (enumeration items, counts), some any.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Int {
    Small(i8),
    Any(i32),
}

impl Int {
    pub(crate) fn value(self) -> i32 {
        match self {
            Int::Small(n) => i32::from(n),
            Int::Any(n) => n,
        }
    }
}

/// A communication step: mostly a usual one, sometimes any real.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Step {
    Usual(u8),
    Other(Real),
}

impl Step {
    pub(crate) fn value(self) -> f64 {
        match self {
            Step::Usual(i) => [1e-3, 0.01, 0.05, 0.3][usize::from(i) % 4],
            Step::Other(r) => r.value(),
        }
    }
}

/// How many values an array argument has: the model's number of states or event indicators,
/// or another.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Len {
    Right,
    Other(u8),
}

impl Len {
    pub(crate) fn value(self, right: usize) -> usize {
        match self {
            Len::Right => right,
            Len::Other(n) => usize::from(n % 64),
        }
    }
}
