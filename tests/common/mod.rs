//! TLD.fmu's native FMI test host: the workspace's raw test host (tests/fmi_host), loading
//! libtld_fmu, with TLD's own helpers.
#![allow(dead_code)]

#[path = "../fmi_host/mod.rs"]
mod fmi_host;

pub use fmi_host::*;
pub(crate) use tld_fmu::fmi::vars::GUID;
use tld_fmu::fmi::vars::vr;

/// The library's crate name, which the test host loads.
pub(crate) const LIBRARY: &str = "tld_fmu";

impl Instance {
    /// Model Exchange: initialisation entered and left, the first event iteration, into
    /// continuous-time mode.
    pub fn start_continuous_time(&self) {
        assert_eq!(self.enter(), OK);
        assert_eq!(self.exit(), OK, "{:?}", self.logs());
        assert_eq!(self.new_discrete_states().0, OK);
        assert_eq!(self.enter_continuous_time_mode(), OK);
    }

    /// setup, enter, exit: ready to step.
    pub fn initialise(&self) {
        assert_eq!(self.setup(), OK);
        assert_eq!(self.enter(), OK);
        assert_eq!(self.exit(), OK);
    }

    /// Harmonic base motion near resonance for `n` steps of `h`; returns slosh.x at the end.
    pub fn run_harmonic(&mut self, n: usize, h: f64) -> f64 {
        let w = 6.0;
        for _ in 0..n {
            let t = self.time;
            assert_eq!(
                self.set_real(vr::BASE_A, -w * w * 0.004 * (w * t).sin()),
                OK
            );
            assert_eq!(self.do_step(h), OK, "{:?}", self.logs());
        }
        self.get_real(vr::SLOSH_X).1
    }
}

/// `bytes` deserialised and set into `inst` (both calls must succeed); the state, to be freed.
pub fn restore(inst: &Instance, bytes: &[u8]) -> fmi_sys::fmi2::fmi2FMUstate {
    let (status, restored) = deserialize(inst, bytes);
    assert_eq!(status, OK, "{:?}", inst.logs());
    // SAFETY: our instance and a state it just made.
    let set = unsafe { inst.lib.fmi2SetFMUstate(inst.c, restored) };
    assert_eq!(set, OK, "{:?}", inst.logs());
    restored
}

/// An instance out of initialisation mode with the Tracked amplitude estimate (amplitude = 2),
/// whose state holds more than x and v.
pub fn tracked(name: &str) -> Instance {
    let inst = Instance::new(name);
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_integer(vr::AMPLITUDE, 2), OK);
    assert_eq!(inst.exit(), OK);
    inst
}

/// A Model Exchange (`me`) or Co-Simulation instance after fmi2SetupExperiment, with the
/// Integer and Real parameters given, in initialisation mode.
pub fn configured(name: &str, me: bool, integers: &[(u32, i32)], reals: &[(u32, f64)]) -> Instance {
    let inst = if me {
        Instance::model_exchange(name)
    } else {
        Instance::new(name)
    };
    assert_eq!(inst.setup(), OK);
    for &(r, v) in integers {
        assert_eq!(inst.set_integer(r, v), OK, "{r}");
    }
    for &(r, v) in reals {
        assert_eq!(inst.set_real(r, v), OK, "{r}");
    }
    assert_eq!(inst.enter(), OK);
    inst
}

/// The Real outputs' value references, from the model description: every one of them.
pub fn real_outputs() -> Vec<u32> {
    use tld_fmu::fmi::vars::{Causality, VARIABLES, VarType};
    VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Output && v.ty == VarType::Real)
        .map(|v| v.vr)
        .collect()
}

/// J's column for the known `known` (fmi2GetDirectionalDerivative with the direction 1) for
/// the `unknowns`, at the current states and inputs; the call must succeed.
pub fn jacobian_column(inst: &Instance, unknowns: &[u32], known: u32) -> Vec<f64> {
    let mut j = vec![f64::NAN; unknowns.len()];
    // SAFETY: our instance, arrays of the lengths given.
    let s = unsafe {
        inst.lib.fmi2GetDirectionalDerivative(
            inst.c,
            unknowns.as_ptr(),
            unknowns.len(),
            &known,
            1,
            &1.0,
            j.as_mut_ptr(),
        )
    };
    assert_eq!(s, OK, "{:?}", inst.logs());
    j
}

/// The value reference of the variable `name`, which must exist.
pub fn vr_of(name: &str) -> u32 {
    tld_fmu::fmi::vars::VARIABLES
        .iter()
        .find(|v| v.name == name)
        .map(|v| v.vr)
        .unwrap_or_else(|| panic!("no variable {name}"))
}

/// The first continuous states, those S^2 uses (every oscillator model the first four).
pub const S2_NAMES: [&str; 6] = [
    "slosh.x",
    "slosh.v",
    "energy.input",
    "energy.dissipated",
    "impact.z",
    "impact.v",
];

/// J's column `j` against the central differences of the unknowns' values `up` and `down` at
/// steps +-`h` of one known: every entry within 1e-6 relative (the differences' truncation)
/// plus their rounding; a failure names the entry by `entry(i)`. Returns the largest error
/// relative to its tolerance (<= 1 passes).
pub fn against_differences(
    j: &[f64],
    up: &[f64],
    down: &[f64],
    h: f64,
    entry: impl Fn(usize) -> String,
) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..j.len() {
        let fd = (up[i] - down[i]) / (2.0 * h);
        let tol = 1e-6 * j[i].abs().max(fd.abs())
            + 1e3 * f64::EPSILON * (up[i].abs() + down[i].abs()) / h;
        let err = (j[i] - fd).abs();
        assert!(
            err <= tol,
            "{}: {} by J d, {fd} by differences",
            entry(i),
            j[i]
        );
        worst = worst.max(err / tol.max(f64::MIN_POSITIVE));
    }
    worst
}

/// The unknowns' values (read by `values`) at the point `p` moved by +`h` and by -`h` in its
/// coordinate `k` (each point set by `put`): what a central difference needs.
pub fn values_either_side(
    p: &[f64],
    k: usize,
    h: f64,
    put: impl Fn(&[f64]),
    values: impl Fn() -> Vec<f64>,
) -> (Vec<f64>, Vec<f64>) {
    let mut q = p.to_vec();
    q[k] = p[k] + h;
    put(&q);
    let up = values();
    q[k] = p[k] - h;
    put(&q);
    (up, values())
}
