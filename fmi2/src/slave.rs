//! The contract between the shared FMI layer and one FMU: what a slave is asked to do once the
//! call has passed its phase mask and the host's pointers have been checked. A slave knows its
//! variables and its model; it never sees a host pointer, a phase mask or the logger.

use crate::calls::Phase;
use crate::continuous::Continuous;
use crate::description::{Table, VarType};
use crate::frame::{Experiment, Reader};
use crate::status::{Refusal, Reply};

/// What the shared instance holds for the slave: the phase, the experiment, the time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Context {
    pub phase: Phase,
    pub experiment: Experiment,
    pub time: f64,
}

/// One FMU's model behind the FMI 2.0 Co-Simulation interface, and through [`Continuous`] (whose
/// defaults refuse it) behind Model Exchange. Every method leaves the slave as it was when it
/// refuses.
pub trait Slave: Continuous {
    /// The model description (variables, value references, GUID, log categories).
    const TABLE: &'static Table;
    /// Marks this FMU's instances and states in memory (a pointer of another kind is refused).
    const MARK: u64;
    /// The first bytes of a saved state, and its format version.
    const STATE_TAG: [u8; 4];
    const STATE_VERSION: u16;

    /// A new instance's slave: start values, no simulation.
    fn new() -> Self;

    /// The tolerance of fmi2SetupExperiment as the slave will use it.
    fn tolerance(t: f64) -> f64 {
        t
    }

    /// fmi2ExitInitializationMode: build the simulation from the parameters; warnings to log.
    fn initialise(&mut self, context: &Context) -> Result<Vec<String>, Refusal>;

    /// Undo [`Slave::initialise`] (the parameters stay): a Model Exchange instance whose
    /// parameters choose a model not offered there stays in initialisation mode.
    fn uninitialise(&mut self);

    /// fmi2DoStep from `t` by `h` (both finite, `h` > 0, `t` the instance's time): all or
    /// nothing. `Ok(true)`: carried out, with a notice for the host ([`Slave::notice`]). (A
    /// flag, not the message: the result stays two words, returned in registers.)
    fn step(&mut self, context: &Context, t: f64, h: f64) -> Result<bool, Refusal>;

    /// The notice of the step just carried out (`context.time` is its end), logged as a
    /// warning.
    fn notice(&mut self, context: &Context) -> Option<String> {
        let _ = context;
        None
    }

    /// fmi2Get{Real,Integer,Boolean}: values of `vrs` read as `ty`, converted by `to`.
    fn get<T>(
        &self,
        context: &Context,
        vrs: &[u32],
        out: &mut [T],
        ty: VarType,
        function: &str,
        to: fn(f64) -> T,
    ) -> Reply;

    /// fmi2Set{Real,Integer,Boolean}: all checked before any is set.
    fn set<T: Copy>(
        &mut self,
        context: &Context,
        vrs: &[u32],
        values: &[T],
        ty: VarType,
        function: &str,
        from: fn(T) -> f64,
    ) -> Reply;

    /// The quick path of fmi2Set{Real,Integer,Boolean} for one value (the per-step input): set
    /// `r` to `value` read as `ty` and answer true if [`Slave::set`] would take it as it is, in
    /// every phase that allows a set, with nothing to say; false leaves the slave as it was and
    /// the call to [`Slave::set`] (which decides again and says why). The default takes none.
    #[inline(always)]
    fn set_quietly(&mut self, r: u32, value: f64, ty: VarType) -> bool {
        let _ = (r, value, ty);
        false
    }

    /// The quick path of fmi2Get{Real,Integer,Boolean}: the values of `vrs` read as `ty` into
    /// `out` (as long), converted by `to`, and true if each is what [`Slave::get`] answers, in
    /// every phase that allows a get, with nothing to say (a stored value, an output kept with
    /// the state), and finite; false: ask [`Slave::get`] (which writes `out` again, or refuses).
    /// One call for all the values: what every value needs (the simulation, the tables) is
    /// found once. The default answers false.
    #[inline(always)]
    fn get_quietly<T>(&self, vrs: &[u32], out: &mut [T], ty: VarType, to: fn(f64) -> T) -> bool {
        let _ = (vrs, out, ty, to);
        false
    }

    /// fmi2SetRealInputDerivatives, for the next step only.
    fn set_input_derivatives(&mut self, vrs: &[u32], orders: &[i32], values: &[f64]) -> Reply;

    /// fmi2GetRealOutputDerivatives, each value handed to `put` with its position.
    fn output_derivatives(
        &self,
        context: &Context,
        vrs: &[u32],
        orders: &[i32],
        put: impl FnMut(usize, f64),
    ) -> Reply;

    /// Its own flag bit of the saved state (see [`crate::frame`]).
    fn flag(&self) -> bool {
        false
    }

    /// Its part of the saved state.
    fn save(&self, out: &mut Vec<u8>);

    /// A slave from its part of a saved state (`context` and `flag` already read and checked).
    fn load(context: &Context, flag: bool, part: &mut Reader) -> Result<Self, String>;
}

#[cfg(test)]
#[path = "slave_tests.rs"]
mod tests;
