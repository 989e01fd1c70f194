//! Model Exchange: time, continuous states, derivatives, event indicators and the event
//! iteration. Each body checks its mask (the guard), the host's pointers and the array lengths
//! against the model description's numbers, then asks the slave ([`crate::Continuous`]).

use fmi_sys::fmi2::*;

use super::{guard, handed_out_finite, host_ref, host_slice, host_slice_mut};
use crate::calls::{self, Call, Phase};
use crate::description::finite;
use crate::slave::Slave;
use crate::status::{Refusal, Reply, Status, refuse};

/// `n` as the host gave it against the number the model description declares.
fn check_len(call: &Call, what: &str, n: usize, declared: usize) -> Result<(), Refusal> {
    if n == declared {
        Ok(())
    } else {
        Err(refuse(format!(
            "{}: {what} = {n}, but the model description declares {declared}",
            call.name
        )))
    }
}

#[inline(always)]
pub unsafe fn fmi2SetTime<S: Slave>(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    guard::<S>(c, &calls::SET_TIME, |inst| {
        if !finite(time) {
            return Err(refuse(format!("fmi2SetTime: time {time} is not finite")));
        }
        inst.context.time = time;
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2SetContinuousStates<S: Slave>(
    c: fmi2Component,
    x: *const fmi2Real,
    nx: usize,
) -> fmi2Status {
    const CALL: &Call = &calls::SET_CONTINUOUS_STATES;
    guard::<S>(c, CALL, |inst| {
        check_len(CALL, "nx", nx, S::STATES)?;
        // SAFETY: host array of nx elements.
        let x = unsafe { host_slice(x, nx, CALL, "x")? };
        if let Some(k) = x.iter().position(|v| !finite(*v)) {
            return Err(refuse(format!(
                "fmi2SetContinuousStates: state {k} is {} (the host's solver diverged?); the states are left as they were",
                x[k]
            )));
        }
        inst.slave.set_states(&inst.context, x)
    })
}

/// A host output array of the declared length, filled by `fill`.
#[inline(always)]
unsafe fn fill_array<S: Slave>(
    c: fmi2Component,
    call: &'static Call,
    out: *mut fmi2Real,
    n: usize,
    declared: fn() -> usize,
    fill: impl FnOnce(&S, &crate::slave::Context, &mut [f64]) -> Reply,
) -> fmi2Status {
    guard::<S>(c, call, |inst| {
        check_len(call, "the array length", n, declared())?;
        // SAFETY: host output array of n elements.
        let out = unsafe { host_slice_mut(out, n, call, "the output array")? };
        let status = fill(&inst.slave, &inst.context, out)?;
        handed_out_finite(call, out, |k| format!("value {k}"))?;
        Ok(status)
    })
}

#[inline(always)]
pub unsafe fn fmi2GetDerivatives<S: Slave>(
    c: fmi2Component,
    derivatives: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    // SAFETY: forwarded host array.
    unsafe {
        fill_array::<S>(
            c,
            &calls::GET_DERIVATIVES,
            derivatives,
            nx,
            || S::STATES,
            |s, ctx, out| s.derivatives(ctx, out),
        )
    }
}

#[inline(always)]
pub unsafe fn fmi2GetEventIndicators<S: Slave>(
    c: fmi2Component,
    eventIndicators: *mut fmi2Real,
    ni: usize,
) -> fmi2Status {
    // SAFETY: forwarded host array.
    unsafe {
        fill_array::<S>(
            c,
            &calls::GET_EVENT_INDICATORS,
            eventIndicators,
            ni,
            || S::EVENT_INDICATORS,
            |s, ctx, out| s.event_indicators(ctx, out),
        )
    }
}

#[inline(always)]
pub unsafe fn fmi2GetContinuousStates<S: Slave>(
    c: fmi2Component,
    x: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    // SAFETY: forwarded host array.
    unsafe {
        fill_array::<S>(
            c,
            &calls::GET_CONTINUOUS_STATES,
            x,
            nx,
            || S::STATES,
            |s, _, out| s.states(out),
        )
    }
}

#[inline(always)]
pub unsafe fn fmi2GetNominalsOfContinuousStates<S: Slave>(
    c: fmi2Component,
    x_nominal: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    // SAFETY: forwarded host array.
    unsafe {
        fill_array::<S>(
            c,
            &calls::GET_NOMINALS_OF_CONTINUOUS_STATES,
            x_nominal,
            nx,
            || S::STATES,
            |s, _, out| s.nominals(out),
        )
    }
}

#[inline(always)]
pub unsafe fn fmi2EnterEventMode<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard::<S>(c, &calls::ENTER_EVENT_MODE, |inst| {
        inst.context.phase = Phase::EventMode;
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2NewDiscreteStates<S: Slave>(
    c: fmi2Component,
    info: *mut fmi2EventInfo,
) -> fmi2Status {
    const CALL: &Call = &calls::NEW_DISCRETE_STATES;
    guard::<S>(c, CALL, |inst| {
        // SAFETY: host output struct.
        let info = unsafe { host_ref(info, CALL, "fmi2EventInfo")? };
        let update = inst.slave.event_update(&inst.context)?;
        info.newDiscreteStatesNeeded = 0;
        info.terminateSimulation = 0;
        info.nominalsOfContinuousStatesChanged = 0;
        info.valuesOfContinuousStatesChanged = fmi2Boolean::from(update.states_changed);
        info.nextEventTimeDefined = fmi2Boolean::from(update.next_event.is_some());
        info.nextEventTime = update.next_event.unwrap_or(0.0);
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2EnterContinuousTimeMode<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard::<S>(c, &calls::ENTER_CONTINUOUS_TIME_MODE, |inst| {
        inst.context.phase = Phase::ContinuousTimeMode;
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2CompletedIntegratorStep<S: Slave>(
    c: fmi2Component,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
    enterEventMode: *mut fmi2Boolean,
    terminateSimulation: *mut fmi2Boolean,
) -> fmi2Status {
    const CALL: &Call = &calls::COMPLETED_INTEGRATOR_STEP;
    guard::<S>(c, CALL, |inst| {
        // SAFETY: host output scalars.
        let (enter, terminate) = unsafe {
            (
                host_ref(enterEventMode, CALL, "enterEventMode")?,
                host_ref(terminateSimulation, CALL, "terminateSimulation")?,
            )
        };
        let event = inst.slave.completed_step(&inst.context)?;
        *enter = fmi2Boolean::from(event);
        *terminate = 0;
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2GetDirectionalDerivative<S: Slave>(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_DIRECTIONAL_DERIVATIVE;
    guard::<S>(c, CALL, |inst| {
        // SAFETY: host arrays of the lengths given.
        let (unknowns, knowns, dv_known, dv_unknown) = unsafe {
            (
                host_slice(vUnknown_ref, nUnknown, CALL, "vUnknown_ref")?,
                host_slice(vKnown_ref, nKnown, CALL, "vKnown_ref")?,
                host_slice(dvKnown, nKnown, CALL, "dvKnown")?,
                host_slice_mut(dvUnknown, nUnknown, CALL, "dvUnknown")?,
            )
        };
        if let Some(k) = dv_known.iter().position(|v| !finite(*v)) {
            return Err(refuse(format!(
                "fmi2GetDirectionalDerivative: dvKnown[{k}] = {} is not finite",
                dv_known[k]
            )));
        }
        let status = inst.slave.directional_derivative(
            &inst.context,
            unknowns,
            knowns,
            dv_known,
            dv_unknown,
        )?;
        handed_out_finite(CALL, dv_unknown, |k| {
            format!("dvUnknown[{k}] (value reference {})", unknowns[k])
        })?;
        Ok(status)
    })
}

#[cfg(test)]
#[path = "me_tests.rs"]
mod tests;
