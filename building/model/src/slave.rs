//! Building.fmu as a slave of the shared FMI layer (`fmi2_slave`): the values the host set, the
//! input derivatives for the next step, and once initialised the building, its exact step and
//! its state. The shared layer has checked the call's phase and the host's pointers before any
//! method here runs; every refusal leaves the slave as it was.

use fmi2_slave::description::Table;
use fmi2_slave::frame::{Reader, put_f64_list};
use fmi2_slave::{Context, Refusal, Reply, Slave, Status, refuse};
use nalgebra::DMatrix;

use crate::description::{Causality, TABLE, VARIABLES, VarType, finite, index_of, per_storey, vr};
use crate::propagator::{Cache, ORDERS};
use crate::structure::{self, Design};

/// A running building: its structure, first-order system, cached steps and state
/// z = [u, u', x_g, v_g, h, v_h] (h: the built-in ground motion's displacement), with room for a step's input polynomial and next state (a step
/// allocates nothing).
#[derive(Clone, Debug)]
struct Simulation {
    building: structure::Building,
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    cache: Cache,
    z: Vec<f64>,
    p: Vec<f64>,
    next: Vec<f64>,
    /// The value of the discrete input tld.impulse the state has taken (Model Exchange): an
    /// event applies the change since.
    impulse_taken: f64,
}

impl Simulation {
    /// The change of the state z a unit impulse [N s] on the damper's floor makes: the column
    /// of B that takes the damper's force (M^-1 on the velocities, nothing on the rest).
    fn impulse_response(&self) -> Vec<f64> {
        self.b
            .column(1 + self.building.damper)
            .iter()
            .copied()
            .collect()
    }

    fn new(building: structure::Building) -> Self {
        let (a, b) = building.state_space();
        let (z, next) = (building.initial_state(), vec![0.0; building.states()]);
        let p = vec![0.0; (ORDERS + 1) * building.channels()];
        Simulation {
            building,
            a,
            b,
            cache: Cache::default(),
            z,
            p,
            next,
            impulse_taken: 0.0,
        }
    }
}

pub struct Building {
    /// Values of all variables, in the order of `VARIABLES` (integers as f64; NaN: none).
    values: Vec<f64>,
    /// Derivatives (orders 1, 2) of every variable's value for the next step (inputs only).
    derivatives: Vec<[f64; ORDERS]>,
    sim: Option<Simulation>,
}

mod me;

/// Variables of version 2's first build; those after it (tld.impulse, tld.v.jump) are saved
/// only when away from their start.
const VERSION_2_VARIABLES: usize = 187;

/// The value of `vr` in `values` (NaN if it names no variable).
fn value(values: &[f64], r: u32) -> f64 {
    index_of(r)
        .and_then(|i| values.get(i))
        .copied()
        .unwrap_or(f64::NAN)
}

/// The building the parameters in `values` describe.
fn design(values: &[f64]) -> Result<Design, String> {
    let n = value(values, vr::STOREYS) as usize;
    let floor = match value(values, vr::TLD_FLOOR) as usize {
        0 => n,
        f => f,
    };
    let zeta = value(values, vr::DAMPING_ZETA);
    let own = |r: u32, name: &str| {
        let z = value(values, r);
        if z == -1.0 {
            Ok(zeta)
        } else if z >= 0.0 {
            Ok(z)
        } else {
            Err(format!(
                "{name} = {z}: a damping ratio >= 0, or -1 for damping.zeta"
            ))
        }
    };
    Ok(Design {
        masses: (1..=n)
            .map(|i| value(values, per_storey(vr::STOREY_1__MASS, i)))
            .collect(),
        stiffnesses: (1..=n)
            .map(|i| value(values, per_storey(vr::STOREY_1__STIFFNESS, i)))
            .collect(),
        zeta: [
            own(vr::DAMPING_ZETA1, "damping.zeta1")?,
            own(vr::DAMPING_ZETA2, "damping.zeta2")?,
        ],
        damper_floor: floor,
        damper_mass: value(values, vr::TLD_MASS),
        ground: structure::Harmonic {
            amplitude: value(values, vr::GROUND_AMPLITUDE),
            omega: value(values, vr::GROUND_OMEGA),
        },
    })
}

fn configure(values: &[f64]) -> Result<Simulation, Refusal> {
    design(values)
        .and_then(|d| structure::Building::new(&d))
        .map(Simulation::new)
        .map(|s| Simulation {
            // At the start, and in a saved state (taken between events): the input's value.
            impulse_taken: value(values, vr::TLD_IMPULSE),
            ..s
        })
        .map_err(|e| refuse(format!("the parameters are inconsistent: {e}")))
}

/// Where an output comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Output {
    TldA,
    TldV,
    TldX,
    RoofX,
    BaseShear,
    FloorX(usize),
    FloorA(usize),
    TldVJump,
}

fn output_of(r: u32) -> Option<Output> {
    let block = |first: u32| (first..first + structure::MAX_STOREYS as u32).contains(&r);
    Some(match r {
        vr::TLD_A => Output::TldA,
        vr::TLD_V => Output::TldV,
        vr::TLD_X => Output::TldX,
        vr::ROOF_X => Output::RoofX,
        vr::BASE_SHEAR => Output::BaseShear,
        vr::TLD_V_JUMP => Output::TldVJump,
        _ if block(vr::FLOOR_1__X) => Output::FloorX((r - vr::FLOOR_1__X) as usize),
        _ if block(vr::FLOOR_1__A) => Output::FloorA((r - vr::FLOOR_1__A) as usize),
        _ => return None,
    })
}

impl Building {
    /// The input channels [a_g, F_1..F_n] of the step's polynomial into `out`: order 0 (the
    /// values), 1 or 2 (the derivatives the host set). F_i is floor i's force, plus the
    /// damper's on its floor.
    fn fill_channels(&self, b: &structure::Building, order: usize, out: &mut [f64]) {
        let of = |r: u32| match (order, index_of(r)) {
            (0, Some(i)) => self.values[i],
            (k, Some(i)) => self.derivatives[i][k - 1],
            _ => 0.0,
        };
        out[0] = of(vr::GROUND_A);
        for i in 0..b.n {
            let damper = if i == b.damper {
                of(vr::TLD_FORCE)
            } else {
                0.0
            };
            out[1 + i] = of(per_storey(vr::FLOOR_1__FORCE, i + 1)) + damper;
        }
    }

    fn channels(&self, s: &Simulation, order: usize) -> Vec<f64> {
        let mut p = vec![0.0; s.building.channels()];
        self.fill_channels(&s.building, order, &mut p);
        p
    }

    /// The running simulation, or before initialisation one built on the parameters set so
    /// far (at rest).
    fn simulation(&self) -> Result<std::borrow::Cow<'_, Simulation>, Refusal> {
        match &self.sim {
            Some(s) => Ok(std::borrow::Cow::Borrowed(s)),
            None => Ok(std::borrow::Cow::Owned(configure(&self.values)?)),
        }
    }

    fn output(&self, s: &Simulation, which: Output) -> f64 {
        let b = &s.building;
        let (n, z) = (b.n, &s.z);
        let (xg, vg) = (z[2 * n], z[2 * n + 1]);
        let accelerations = || b.accelerations(z, &self.channels(s, 0)[1..]);
        match which {
            Output::TldA => accelerations()[b.damper],
            Output::TldV => vg + z[n + b.damper],
            Output::TldX => xg + z[b.damper],
            Output::RoofX => z[n - 1],
            Output::BaseShear => b.base_shear(&z[..n], &z[n..2 * n]),
            Output::FloorX(i) => z.get(i).filter(|_| i < n).copied().unwrap_or(0.0),
            Output::FloorA(i) if i < n => accelerations()[i],
            Output::FloorA(_) => 0.0,
            Output::TldVJump => s.impulse_taken * s.impulse_response()[n + b.damper],
        }
    }

    /// The first time derivative of an output now, with the input rates the host set.
    fn rate(&self, s: &Simulation, which: Output) -> f64 {
        let b = &s.building;
        let (n, z) = (b.n, &s.z);
        let p = self.channels(s, 0);
        let dp = self.channels(s, 1);
        let a = b.accelerations(z, &p[1..]);
        // u'' (relative: less the whole ground acceleration), then the state's derivative
        // [u', u''] for the linear outputs.
        let ag = b.ground_acceleration(z, p[0]);
        let relative: Vec<f64> = a.iter().map(|ai| ai - ag).collect();
        let mut dz = z[n..2 * n].to_vec();
        dz.extend_from_slice(&relative);
        // a' = M^-1 (F' - C u'' - K u'): the accelerations of [u', u''] under the force rates.
        let jerk = || b.accelerations(&dz, &dp[1..]);
        match which {
            Output::TldA => jerk()[b.damper],
            Output::TldV => a[b.damper],
            Output::TldX => z[2 * n + 1] + z[n + b.damper],
            Output::RoofX => z[2 * n - 1],
            Output::BaseShear => b.base_shear(&dz[..n], &dz[n..]),
            Output::FloorX(i) if i < n => z[n + i],
            Output::FloorA(i) if i < n => jerk()[i],
            Output::FloorX(_) | Output::FloorA(_) | Output::TldVJump => 0.0,
        }
    }

    fn derived(s: &Simulation, r: u32) -> Option<f64> {
        let b = &s.building;
        Some(match r {
            vr::MODE_1__OMEGA => b.omega[0],
            vr::MODE_2__OMEGA => *b.omega.get(1).unwrap_or(&b.omega[0]),
            vr::DAMPING_ALPHA => b.alpha,
            vr::DAMPING_BETA => b.beta,
            _ => return None,
        })
    }

    fn value_of(&self, r: u32, ty: VarType, function: &str) -> Result<f64, Refusal> {
        let (index, var) = TABLE.typed_variable(r, ty, function)?;
        match var.causality {
            Causality::Parameter | Causality::Input => Ok(self.values[index]),
            Causality::Output => {
                let s = self.simulation()?;
                let which = output_of(r).ok_or_else(|| TABLE.no_value(r, function))?;
                Ok(self.output(&s, which))
            }
            Causality::CalculatedParameter => {
                Self::derived(&*self.simulation()?, r).ok_or_else(|| TABLE.no_value(r, function))
            }
            Causality::Local => self
                .local(r)
                .unwrap_or_else(|| Err(TABLE.no_value(r, function))),
        }
    }
}

impl Slave for Building {
    const TABLE: &'static Table = &TABLE;
    const MARK: u64 = 0x4255_494c_4449_4e47;
    const STATE_TAG: [u8; 4] = *b"BLDs";
    /// 2: the state holds the built-in ground motion's oscillator (h, v_h); 1 did not.
    const STATE_VERSION: u16 = 2;

    fn new() -> Self {
        Building {
            values: VARIABLES
                .iter()
                .map(|v| v.start.unwrap_or(f64::NAN))
                .collect(),
            derivatives: vec![[0.0; ORDERS]; VARIABLES.len()],
            sim: None,
        }
    }

    fn initialise(&mut self, _: &Context) -> Result<Vec<String>, Refusal> {
        self.sim = Some(configure(&self.values)?);
        Ok(Vec::new())
    }

    fn uninitialise(&mut self) {
        self.sim = None;
    }

    fn step(&mut self, _: &Context, t: f64, h: f64) -> Result<bool, Refusal> {
        let Some(mut s) = self.sim.take() else {
            return Err(refuse("fmi2DoStep: no simulation (not initialised)"));
        };
        let m = s.building.channels();
        for order in 0..=ORDERS {
            self.fill_channels(&s.building, order, &mut s.p[order * m..(order + 1) * m]);
        }
        let (a, b) = (&s.a, &s.b);
        match s.cache.get(h, a, b) {
            Ok(propagator) => propagator.advance(&s.z, &s.p, &mut s.next),
            Err(why) => {
                self.sim = Some(s);
                return Err(refuse(format!(
                    "fmi2DoStep from t = {t} by {h}: {why}. The state is left at the start of the step."
                )));
            }
        }
        if !s.next.iter().all(|x| finite(*x)) {
            self.sim = Some(s);
            return Err(refuse(format!(
                "fmi2DoStep from t = {t} by {h}: the motion is no longer finite (inputs too large?). The state is left at the start of the step."
            )));
        }
        std::mem::swap(&mut s.z, &mut s.next);
        self.sim = Some(s);
        // Input derivatives describe one communication step.
        self.derivatives.iter_mut().for_each(|d| *d = [0.0; ORDERS]);
        Ok(false)
    }

    fn get<T>(
        &self,
        _: &Context,
        vrs: &[u32],
        out: &mut [T],
        ty: VarType,
        function: &str,
        to: fn(f64) -> T,
    ) -> Reply {
        for (slot, &r) in out.iter_mut().zip(vrs) {
            *slot = to(self.value_of(r, ty, function)?);
        }
        Ok(Status::Ok)
    }

    fn set<T: Copy>(
        &mut self,
        context: &Context,
        vrs: &[u32],
        values: &[T],
        ty: VarType,
        function: &str,
        from: fn(T) -> f64,
    ) -> Reply {
        let mut checked = Vec::with_capacity(vrs.len());
        for (&r, &v) in vrs.iter().zip(values) {
            let v = from(v);
            checked.push((TABLE.settable(context.phase, r, v, ty, function)?, v));
        }
        for (index, v) in checked {
            self.values[index] = v;
        }
        Ok(Status::Ok)
    }

    fn set_input_derivatives(&mut self, vrs: &[u32], orders: &[i32], values: &[f64]) -> Reply {
        for ((&r, &order), &value) in vrs.iter().zip(orders).zip(values) {
            TABLE.check_input_derivative(r, order, value, ORDERS as i32)?;
        }
        for ((&r, &order), &value) in vrs.iter().zip(orders).zip(values) {
            if let Some(i) = index_of(r) {
                self.derivatives[i][order as usize - 1] = value;
            }
        }
        Ok(Status::Ok)
    }

    fn output_derivatives(
        &self,
        _: &Context,
        vrs: &[u32],
        orders: &[i32],
        put: impl FnMut(usize, f64),
    ) -> Reply {
        TABLE.first_output_derivatives(
            self.sim.as_ref(),
            vrs,
            orders,
            output_of,
            |s, which| self.rate(s, which),
            put,
        )
    }

    /// Values of all variables | input derivatives (orders 1, 2 of every variable) | the state
    /// z = [u, u', x_g, v_g, h, v_h] (empty before initialisation).
    fn save(&self, out: &mut Vec<u8>) {
        // Model Exchange's locals (states and derivatives) are the simulation's, not values:
        // the saved values are those of the other variables, as before they were added.
        // Variables added since version 2's first build are listed up to the last one away
        // from its start, so a run that leaves them alone saves version 2's bytes.
        let start = Building::new();
        let mut listed = VARIABLES.len();
        while listed > VERSION_2_VARIABLES
            && self.values[listed - 1].to_bits() == start.values[listed - 1].to_bits()
            && self.derivatives[listed - 1] == [0.0; ORDERS]
        {
            listed -= 1;
        }
        let kept = |k: &usize| VARIABLES[*k].causality != Causality::Local;
        let values: Vec<f64> = (0..listed).filter(kept).map(|k| self.values[k]).collect();
        put_f64_list(out, &values);
        let flat: Vec<f64> = (0..listed)
            .filter(kept)
            .flat_map(|k| self.derivatives[k])
            .collect();
        put_f64_list(out, &flat);
        put_f64_list(out, self.sim.as_ref().map_or(&[][..], |s| &s.z));
    }

    fn load(context: &Context, _: bool, part: &mut Reader) -> Result<Self, String> {
        let saved = part.f64_list()?;
        let saved_flat = part.f64_list()?;
        let z = part.f64_list()?;
        let kept: Vec<usize> = (0..VARIABLES.len())
            .filter(|k| VARIABLES[*k].causality != Causality::Local)
            .collect();
        let first = kept.iter().filter(|&&k| k < VERSION_2_VARIABLES).count();
        if !(first..=kept.len()).contains(&saved.len()) || saved_flat.len() != ORDERS * saved.len()
        {
            return Err(format!(
                "{} values and {} derivatives for {} variables",
                saved.len(),
                saved_flat.len(),
                kept.len()
            ));
        }
        let mut values: Vec<f64> = VARIABLES
            .iter()
            .map(|v| v.start.unwrap_or(f64::NAN))
            .collect();
        let mut flat = vec![0.0; ORDERS * VARIABLES.len()];
        for (j, &k) in kept.iter().take(saved.len()).enumerate() {
            values[k] = saved[j];
            flat[ORDERS * k..ORDERS * (k + 1)]
                .copy_from_slice(&saved_flat[ORDERS * j..ORDERS * (j + 1)]);
        }
        for (var, &v) in VARIABLES.iter().zip(&values) {
            if var.start.is_some()
                && let Some(reason) = var.reject(v)
            {
                return Err(reason);
            }
        }
        if !flat.iter().all(|d| d.is_finite()) {
            return Err("non-finite input derivatives".into());
        }
        let derivatives = flat.chunks(ORDERS).map(|c| [c[0], c[1]]).collect();
        let initialised = context.phase.initialised();
        let sim = if initialised {
            let mut s = configure(&values).map_err(|r| *r.message)?;
            if z.len() != s.z.len() || !z.iter().all(|x| x.is_finite()) {
                return Err(format!(
                    "{} finite state values expected, {} found",
                    s.z.len(),
                    z.len()
                ));
            }
            s.z = z;
            Some(s)
        } else if z.is_empty() {
            None
        } else {
            return Err("a state before initialisation with simulation values".into());
        };
        Ok(Building {
            values,
            derivatives,
            sim,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fmi2_slave::calls::Phase;
    use fmi2_slave::frame::{self, Common, Experiment};

    fn context(phase: Phase) -> Context {
        Context {
            phase,
            experiment: Experiment::default(),
            time: 0.0,
        }
    }

    /// A Building from a framed state whose slave part `payload` writes (the frame and its
    /// checksum sound, so only `load` judges the payload).
    fn load(phase: Phase, payload: impl FnOnce(&mut Vec<u8>)) -> Result<Building, String> {
        let common = Common {
            phase,
            experiment: Experiment::default(),
            time: 0.0,
            flag: false,
        };
        let (tag, version) = (Building::STATE_TAG, Building::STATE_VERSION);
        let bytes = frame::encode(&tag, version, TABLE.guid, &common, payload);
        let (common, mut part) = frame::decode(&bytes, &tag, version, TABLE.guid, "Building")?;
        Building::load(&context(common.phase), common.flag, &mut part)
    }

    fn payload(lists: &[Vec<f64>; 3]) -> Vec<u8> {
        let mut out = Vec::new();
        lists.iter().for_each(|l| put_f64_list(&mut out, l));
        out
    }

    /// A saved state's three lists, each one entry short or long alone, are refused; the
    /// lists as saved load.
    #[test]
    fn a_state_whose_lists_do_not_fit_is_refused() {
        let mut b = <Building as Slave>::new();
        b.initialise(&context(Phase::InitializationMode))
            .expect("the default building");
        // The lists as `save` writes them.
        let mut whole = Vec::new();
        b.save(&mut whole);
        let bytes = frame::encode(
            &Building::STATE_TAG,
            Building::STATE_VERSION,
            TABLE.guid,
            &Common {
                phase: Phase::StepComplete,
                experiment: Experiment::default(),
                time: 0.0,
                flag: false,
            },
            |out| out.extend_from_slice(&whole),
        );
        let (_, mut part) = frame::decode(
            &bytes,
            &Building::STATE_TAG,
            Building::STATE_VERSION,
            TABLE.guid,
            "Building",
        )
        .expect("frame");
        let lists = [part.f64_list(), part.f64_list(), part.f64_list()].map(|l| l.expect("list"));
        assert!(!lists[2].is_empty());
        let good = payload(&lists);
        assert!(load(Phase::StepComplete, |out| out.extend_from_slice(&good)).is_ok());
        for k in 0..3 {
            for longer in [false, true] {
                let mut changed = lists.clone();
                if longer {
                    changed[k].push(0.0);
                } else {
                    changed[k].pop();
                }
                let bad = payload(&changed);
                let refused = load(Phase::StepComplete, |out| out.extend_from_slice(&bad));
                assert!(refused.is_err(), "list {k} longer {longer}");
            }
        }
        // The state of a simulation with a value not finite.
        let mut changed = lists.clone();
        changed[2][0] = f64::NAN;
        let bad = payload(&changed);
        assert!(load(Phase::StepComplete, |out| out.extend_from_slice(&bad)).is_err());
    }
}
