//! The benchmark's careful C FMU (`bench/c/tld_c.c`) in Rust, statement by statement: the same
//! struct, the same checks, the same functions, every expression in the C's order of operations
//! (so the same bits: tests/python/test_c_port.py), the C library's `tanh` and `pow` behind
//! Rust's f64 methods as in the C. It answers one question of issue #29: what rustc's back end
//! (LLVM) makes of the C FMU's own program, beside gcc's and clang's builds of it, in the same
//! host and rounds (bench/python/workprec/cfmu.py). It is a benchmark anchor, not a product: the
//! model, the units and the refusals are the C file's; read its header for them.
//!
//! Feature `energies` is the C's `-DTLD_C_ENERGIES`.
//!
//! Where the C writes `!(x > 0)` to refuse NaN with the out-of-range values, so does this port
//! (hence the allowed lint), and `fmin(fmax(..))` as `max(..).min(..)`, not `clamp`, whose NaN
//! handling differs from fmin's and fmax's; pointers from the host are checked for null as the C
//! checks them.
#![allow(
    non_snake_case,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::manual_clamp
)]

use std::f64::consts::PI;
use std::ffi::{c_char, c_int, c_uint, c_void};

mod solvers;

type Status = c_int;
const OK: Status = 0;
const DISCARD: Status = 2;
const ERROR: Status = 3;

type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char, ...);

/// fmi2CallbackFunctions, of which the logger and its environment are read.
#[repr(C)]
pub struct Callbacks {
    logger: Option<Logger>,
    allocate: *mut c_void,
    free_memory: *mut c_void,
    step_finished: *mut c_void,
    component_environment: *mut c_void,
}

// TLD.fmu's value references (modelDescription/modelDescription.xml), as in the C
const VR_LENGTH: c_uint = 0;
const VR_BREADTH: c_uint = 1;
const VR_DEPTH: c_uint = 2;
const VR_DENSITY: c_uint = 3;
const VR_G: c_uint = 4;
const VR_TANKS: c_uint = 5;
const VR_MODEL: c_uint = 6;
const VR_ETA: c_uint = 8;
const VR_PHI: c_uint = 9;
const VR_DAMPING: c_uint = 10;
const VR_ZETA: c_uint = 11;
const VR_X0: c_uint = 19;
const VR_V0: c_uint = 20;
const VR_SOLVER: c_uint = 21;
const VR_TOLERANCE: c_uint = 22;
const VR_FIXED_STEP: c_uint = 23;
const VR_MAX_SUBSTEPS: c_uint = 25;
const VR_OMEGA_F: c_uint = 40;
const VR_MASS_SLOSH: c_uint = 42;
const VR_MASS_INACTIVE: c_uint = 43;
const VR_BASE_A: c_uint = 50;
const VR_FORCE: c_uint = 60;
const VR_X: c_uint = 63;
const VR_V: c_uint = 64;
#[cfg(feature = "energies")]
const VR_ENERGY_INPUT: c_uint = 65;
#[cfg(feature = "energies")]
const VR_ENERGY_DISSIPATED: c_uint = 66;
const MODEL_NONLINEAR: c_int = 2;
const DAMPING_CONSTANT: c_int = 1;
const SOLVER_DP45: c_int = 1;
const SOLVER_RK4: c_int = 2;

/// The C's `Tld`, field for field.
pub struct Tld {
    // parameters
    length: f64,
    breadth: f64,
    depth: f64,
    density: f64,
    g: f64,
    eta: f64,
    phi: f64,
    zeta: f64,
    x0: f64,
    v0: f64,
    tol: f64,
    fixed_step: f64,
    tanks: c_int,
    model: c_int,
    damping: c_int,
    solver: c_int,
    max_substeps: c_int,
    // derived at fmi2ExitInitializationMode
    w2: f64,
    c: f64,
    q: f64,
    p: f64,
    m: f64,
    m0: f64,
    omega: f64,
    scale_x: f64,
    scale_v: f64,
    p_int: c_int,
    // state
    x: f64,
    v: f64,
    a_b: f64,
    h_carried: f64,
    // feature energies: the work in and the dissipation per unit sloshing mass, and the stored
    // energy at the start [J]
    w_in: f64,
    w_diss: f64,
    #[cfg_attr(not(feature = "energies"), allow(dead_code))]
    e0: f64,
    initialised: bool,
    cb: *const Callbacks,
    name: [c_char; 64],
}

fn say(s: &Tld, status: Status, msg: &std::ffi::CStr) {
    if s.cb.is_null() {
        return;
    }
    // SAFETY: the host's callbacks, which it keeps valid for the instance's life (FMI 2.0).
    let cb = unsafe { &*s.cb };
    if let Some(logger) = cb.logger {
        // SAFETY: the FMI 2.0 logger's signature; "%s" with one C string.
        unsafe {
            logger(
                cb.component_environment,
                s.name.as_ptr(),
                status,
                c"logStatusError".as_ptr(),
                c"%s".as_ptr(),
                msg.as_ptr(),
            )
        };
    }
}

#[inline]
fn ipow(mut x: f64, mut n: c_int) -> f64 {
    let mut r = 1.0;
    while n != 0 {
        if n & 1 != 0 {
            r *= x;
        }
        x *= x;
        n >>= 1;
    }
    r
}

#[inline]
fn phi_of(s: &Tld, x: f64) -> f64 {
    let ax = x.abs();
    let h = if s.p_int >= 0 {
        if s.p_int == 2 {
            ax * ax
        } else {
            ipow(ax, s.p_int)
        }
    } else {
        ax.powf(s.p)
    };
    s.w2 * x * (1.0 + s.q * h)
}

#[inline]
fn accel(s: &Tld, x: f64, v: f64, ab: f64) -> f64 {
    -ab - s.c * v - phi_of(s, x)
}

/// The energy integrands at velocity v: the base's work -a_b v and the dissipation c v^2.
#[cfg(feature = "energies")]
#[inline]
fn energy_rates(s: &Tld, ab: f64, v: f64) -> (f64, f64) {
    (-ab * v, s.c * v * v)
}

/// The stored energy [J]: kinetic plus the potential of Phi.
#[cfg(feature = "energies")]
fn stored(s: &Tld, x: f64, v: f64) -> f64 {
    let ax = x.abs();
    let h = if s.p_int >= 0 {
        ipow(ax, s.p_int)
    } else {
        ax.powf(s.p)
    };
    s.m * (0.5 * v * v + 0.5 * s.w2 * x * x * (1.0 + s.q * h / s.eta))
}

/// # Safety
/// `name`, when not null, is a C string; `cb` is null or valid for the instance's life.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    name: *const c_char,
    _type: c_int,
    _guid: *const c_char,
    _res: *const c_char,
    cb: *const Callbacks,
    _visible: c_int,
    _logging: c_int,
) -> *mut c_void {
    let mut s = Box::new(Tld {
        // TLD.fmu's defaults for what this FMU models
        length: 0.25,
        breadth: 0.32,
        depth: 0.021,
        density: 1000.0,
        g: 9.81,
        eta: 2.0,
        phi: 1.0,
        zeta: 0.01,
        x0: 0.0,
        v0: 0.0,
        tol: 1e-10,
        fixed_step: 1e-3,
        tanks: 1,
        model: MODEL_NONLINEAR,
        damping: 2,
        solver: SOLVER_DP45,
        max_substeps: 100000,
        w2: 0.0,
        c: 0.0,
        q: 0.0,
        p: 0.0,
        m: 0.0,
        m0: 0.0,
        omega: 0.0,
        scale_x: 0.0,
        scale_v: 0.0,
        p_int: 0,
        x: 0.0,
        v: 0.0,
        a_b: 0.0,
        h_carried: 0.0,
        w_in: 0.0,
        w_diss: 0.0,
        e0: 0.0,
        initialised: false,
        cb,
        name: [0; 64],
    });
    let given = if name.is_null() {
        c"tld_c".as_ptr()
    } else {
        name
    };
    for (i, slot) in s.name.iter_mut().take(63).enumerate() {
        // SAFETY: a C string, read up to its terminator (strncpy's bound of 63).
        let ch = unsafe { *given.add(i) };
        if ch == 0 {
            break;
        }
        *slot = ch;
    }
    Box::into_raw(s).cast()
}

/// # Safety
/// `c` is null or an instance of fmi2Instantiate, not used after.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        // SAFETY: made by Box::into_raw in fmi2Instantiate.
        drop(unsafe { Box::from_raw(c.cast::<Tld>()) });
    }
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2SetupExperiment(
    _c: *mut c_void,
    _td: c_int,
    _tol: f64,
    _t0: f64,
    _sd: c_int,
    _t1: f64,
) -> Status {
    OK
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2EnterInitializationMode(_c: *mut c_void) -> Status {
    OK
}

/// # Safety
/// `c` is an instance of fmi2Instantiate (as for every call below).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Status {
    // SAFETY: the host's instance.
    let s = unsafe { &mut *c.cast::<Tld>() };
    if s.model != MODEL_NONLINEAR
        || s.damping != DAMPING_CONSTANT
        || (s.solver != SOLVER_DP45 && s.solver != SOLVER_RK4)
    {
        say(
            s,
            ERROR,
            c"only model = Nonlinear, damping = Constant, solver = DormandPrince45 or RK4",
        );
        return ERROR;
    }
    if !(s.depth < s.length) {
        say(s, ERROR, c"tank.depth must be smaller than tank.length");
        return ERROR;
    }
    let r = s.depth / s.length;
    let k = PI * r;
    s.omega = (s.g * PI * k.tanh() / s.length).sqrt();
    let liquid = s.density * s.length * s.breadth * s.depth * f64::from(s.tanks);
    s.m = liquid * 8.0 * k.tanh() / (PI * PI * PI * r);
    s.m0 = liquid - s.m;
    s.w2 = s.omega * s.omega;
    s.c = 2.0 * s.zeta * s.omega;
    s.p = 2.0 * s.eta - 2.0;
    s.p_int = if s.p == s.p.floor() && s.p <= 64.0 {
        s.p as c_int
    } else {
        -1
    };
    s.q = s.phi * (2.0 / s.length).powf(s.p);
    s.scale_x = 0.5 * s.length;
    s.scale_v = 0.5 * s.length * s.omega;
    s.x = s.x0;
    s.v = s.v0;
    s.h_carried = 0.0;
    #[cfg(feature = "energies")]
    {
        s.w_in = 0.0;
        s.w_diss = 0.0;
        s.e0 = stored(s, s.x, s.v);
    }
    s.initialised = true;
    OK
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2Terminate(_c: *mut c_void) -> Status {
    OK
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2Reset(_c: *mut c_void) -> Status {
    ERROR
}

fn set_real(s: &mut Tld, vr: c_uint, x: f64) -> bool {
    if !x.is_finite() {
        return false;
    }
    if vr == VR_BASE_A {
        s.a_b = x;
        return true;
    }
    if s.initialised {
        return false; // parameters are fixed
    }
    let (slot, ok) = match vr {
        VR_LENGTH => (&mut s.length, x > 0.0),
        VR_BREADTH => (&mut s.breadth, x > 0.0),
        VR_DEPTH => (&mut s.depth, x > 0.0),
        VR_DENSITY => (&mut s.density, x > 0.0),
        VR_G => (&mut s.g, x > 0.0),
        VR_ETA => (&mut s.eta, (1.0..=10.0).contains(&x)),
        VR_PHI => (&mut s.phi, x >= 0.0),
        VR_ZETA => (&mut s.zeta, (0.0..=1.0).contains(&x)),
        VR_X0 => (&mut s.x0, true),
        VR_V0 => (&mut s.v0, true),
        VR_TOLERANCE => (&mut s.tol, (1e-14..=0.1).contains(&x)),
        VR_FIXED_STEP => (&mut s.fixed_step, x >= 1e-9),
        _ => return vr < VR_BASE_A, // parameters it does not model
    };
    if ok {
        *slot = x;
    }
    ok
}

/// # Safety
/// `vr` and `value` hold `n` elements each (or are null: refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    value: *const f64,
) -> Status {
    // SAFETY: the host's instance.
    let s = unsafe { &mut *c.cast::<Tld>() };
    if n != 0 && (vr.is_null() || value.is_null()) {
        return ERROR;
    }
    for i in 0..n {
        // SAFETY: i < n elements of each array, as the caller promises.
        let (r, x) = unsafe { (*vr.add(i), *value.add(i)) };
        if !set_real(s, r, x) {
            say(
                s,
                ERROR,
                c"fmi2SetReal: a value out of range, not finite or not settable",
            );
            return ERROR;
        }
    }
    OK
}

/// # Safety
/// As fmi2SetReal.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    value: *const c_int,
) -> Status {
    // SAFETY: the host's instance.
    let s = unsafe { &mut *c.cast::<Tld>() };
    if s.initialised || (n != 0 && (vr.is_null() || value.is_null())) {
        return ERROR;
    }
    for i in 0..n {
        // SAFETY: i < n elements of each array.
        let (r, x) = unsafe { (*vr.add(i), *value.add(i)) };
        match r {
            VR_TANKS if x < 1 => return ERROR,
            VR_TANKS => s.tanks = x,
            VR_MODEL => s.model = x,
            VR_DAMPING => s.damping = x,
            VR_SOLVER => s.solver = x,
            VR_MAX_SUBSTEPS if x < 1 => return ERROR,
            VR_MAX_SUBSTEPS => s.max_substeps = x,
            _ if r >= VR_BASE_A => return ERROR,
            _ => {} // others: not modelled
        }
    }
    OK
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2SetBoolean(
    _c: *mut c_void,
    _vr: *const c_uint,
    n: usize,
    _value: *const c_int,
) -> Status {
    if n != 0 { ERROR } else { OK }
}

/// # Safety
/// `vr` holds `n` elements and `value` room for `n` (or either is null: refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    value: *mut f64,
) -> Status {
    // SAFETY: the host's instance.
    let s = unsafe { &*c.cast::<Tld>() };
    if n != 0 && (vr.is_null() || value.is_null()) {
        return ERROR;
    }
    for i in 0..n {
        // SAFETY: i < n elements.
        let out = match unsafe { *vr.add(i) } {
            VR_X => s.x,
            VR_V => s.v,
            VR_FORCE => s.m * (s.c * s.v + phi_of(s, s.x)),
            VR_MASS_INACTIVE => s.m0,
            VR_MASS_SLOSH => s.m,
            VR_OMEGA_F => s.omega,
            VR_BASE_A => s.a_b,
            #[cfg(feature = "energies")]
            VR_ENERGY_INPUT => s.e0 + s.m * s.w_in,
            #[cfg(feature = "energies")]
            VR_ENERGY_DISSIPATED => s.m * s.w_diss,
            _ => {
                say(s, ERROR, c"fmi2GetReal: unknown value reference");
                return ERROR;
            }
        };
        // SAFETY: i < n elements of room.
        unsafe { *value.add(i) = out };
    }
    OK
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2SetRealInputDerivatives(
    _c: *mut c_void,
    _vr: *const c_uint,
    n: usize,
    _order: *const c_int,
    _value: *const f64,
) -> Status {
    if n != 0 { ERROR } else { OK }
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetRealOutputDerivatives(
    _c: *mut c_void,
    _vr: *const c_uint,
    n: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> Status {
    if n != 0 { ERROR } else { OK }
}

/// # Safety
/// `c` is an instance of fmi2Instantiate.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    t: f64,
    dt: f64,
    _no_set_prior: c_int,
) -> Status {
    // SAFETY: the host's instance.
    let s = unsafe { &mut *c.cast::<Tld>() };
    if !s.initialised || !(dt > 0.0) || !t.is_finite() || !dt.is_finite() {
        say(
            s,
            ERROR,
            c"fmi2DoStep: not initialised, or a bad time or step",
        );
        return ERROR;
    }
    let (mut x, mut v, carried) = (s.x, s.v, s.h_carried);
    let mut e = [s.w_in, s.w_diss];
    let fail = if s.solver == SOLVER_RK4 {
        solvers::rk4(s, dt, &mut x, &mut v, &mut e)
    } else {
        solvers::dp45(s, dt, &mut x, &mut v, &mut e)
    };
    if fail || !x.is_finite() || !v.is_finite() || x.abs() > 100.0 * s.length {
        s.h_carried = carried; // all or nothing
        say(
            s,
            DISCARD,
            c"fmi2DoStep: the step failed (too many substeps or a runaway); the state is left at the start of the step",
        );
        return DISCARD;
    }
    s.x = x;
    s.v = v;
    #[cfg(feature = "energies")]
    {
        s.w_in = e[0];
        s.w_diss = e[1];
    }
    OK
}
