//! The structural master of python/tld_fmu/building.py (`simulate`), operation for operation:
//! a shear building M X'' + C X' + K X = -M 1 a_g + F (X relative to the ground) with TLD.fmu
//! instances on its floors under harmonic ground motion, coupled at a fixed communication step,
//! the building advanced by RK4 with the dampers' forces held (Gauss-Seidel, first order), or
//! with the forces extrapolated from their exact rates and d(base.a)/dt handed to the dampers
//! (Jacobi with derivatives, second order). The arithmetic is written in the order numpy
//! evaluates the Python master's expressions, so that both masters give the same numbers.
//!
//! The structure's matrices come from the caller (tld_fmu.building.Building: masses with the
//! dampers' inactive liquid added, Rayleigh damping): they are built once, in Python.

use crate::fmu::{Instance, Library, Param};

/// One run: the structure, its dampers, the excitation and the coupling.
#[derive(Clone, Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Run {
    /// names the run in its error messages
    pub name: String,
    /// 1 / floor mass (the dampers' inactive liquid included)
    #[serde(deserialize_with = "crate::protocol::numbers")]
    pub minv: Vec<f64>,
    /// damping and stiffness matrices, row by row
    #[serde(deserialize_with = "crate::protocol::matrix")]
    pub c: Vec<Vec<f64>>,
    #[serde(deserialize_with = "crate::protocol::matrix")]
    pub k: Vec<Vec<f64>>,
    pub dampers: Vec<DamperSpec>,
    /// ground motion x_g = amplitude sin(w t)
    pub ground: Harmonic,
    /// communication step, duration and the tail over which the peaks are taken [s]
    #[serde(deserialize_with = "crate::protocol::number")]
    pub step: f64,
    #[serde(deserialize_with = "crate::protocol::number")]
    pub duration: f64,
    #[serde(deserialize_with = "crate::protocol::number")]
    pub tail: f64,
    pub derivatives: bool,
    /// measure the time inside fmi2DoStep (Outcome::do_step_seconds)
    #[serde(default)]
    pub timing: bool,
}

#[derive(Clone, Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DamperSpec {
    /// 0-based floor index
    pub floor: usize,
    /// parameters, in the order they are set (tanks first, as the Python master does)
    pub params: Vec<Param>,
    /// mass.inactive the structure's masses were built with: the FMU must report the same
    #[serde(deserialize_with = "crate::protocol::number")]
    pub inactive: f64,
}

#[derive(Clone, Copy, Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Harmonic {
    #[serde(deserialize_with = "crate::protocol::number")]
    pub w: f64,
    #[serde(deserialize_with = "crate::protocol::number")]
    pub amplitude: f64,
}

impl Harmonic {
    /// (a_g, v_g, x_g) at t, as tld_fmu.building.harmonic_ground evaluates them.
    #[inline]
    fn at(&self, t: f64) -> (f64, f64, f64) {
        let (w, a) = (self.w, self.amplitude);
        let s = (w * t).sin();
        (-w * w * a * s, w * a * (w * t).cos(), a * s)
    }

    /// a_g alone (the same number as `at(t).0`, without the cosine).
    #[inline]
    fn accel(&self, t: f64) -> f64 {
        let (w, a) = (self.w, self.amplitude);
        -w * w * a * (w * t).sin()
    }
}

/// What a run gives: max |X| of every floor over the tail (X relative to the ground).
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    pub peak: Vec<f64>,
    pub steps: usize,
    /// with Run::timing: the time all dampers spent inside fmi2DoStep [s] (else 0)
    pub do_step_seconds: f64,
}

/// FMU instances kept across runs: the k-th damper of a run reuses the k-th instance.
#[derive(Default)]
pub struct Pool {
    pub instances: Vec<Instance>,
}

impl Pool {
    fn get(&mut self, lib: &Library, k: usize) -> Result<&mut Instance, String> {
        while self.instances.len() <= k {
            let i = Instance::new(lib, &format!("tld{}", self.instances.len()))?;
            self.instances.push(i);
        }
        Ok(&mut self.instances[k])
    }
}

fn check(run: &Run) -> Result<usize, String> {
    let n = run.minv.len();
    let square = |m: &Vec<Vec<f64>>| m.len() == n && m.iter().all(|r| r.len() == n);
    if n == 0 || !square(&run.c) || !square(&run.k) {
        return Err(format!(
            "the structure needs 1/m of length n >= 1 and n x n C and K (n = {n})"
        ));
    }
    if !(run.step > 0.0 && run.step.is_finite()) {
        return Err(format!("step {} s: need a finite step > 0", run.step));
    }
    if !(run.duration >= run.step && run.duration.is_finite()) {
        return Err(format!(
            "duration {} s: need a finite duration of at least one step",
            run.duration
        ));
    }
    if !(run.tail > 0.0 && run.tail <= run.duration) {
        return Err(format!("tail {} s: need 0 < tail <= duration", run.tail));
    }
    if let Some(d) = run.dampers.iter().find(|d| d.floor >= n) {
        return Err(format!(
            "a damper on floor index {} of a {n}-floor structure",
            d.floor
        ));
    }
    Ok(n)
}

/// y = M x for a dense matrix given by rows.
#[inline]
fn mat_vec(m: &[Vec<f64>], x: &[f64], y: &mut [f64]) {
    for (yi, row) in y.iter_mut().zip(m) {
        let mut s = 0.0;
        for (a, b) in row.iter().zip(x) {
            s += a * b;
        }
        *yi = s;
    }
}

/// The structure's right-hand side with scratch space.
struct Structure<'a> {
    minv: &'a [f64],
    c: &'a [Vec<f64>],
    k: &'a [Vec<f64>],
    cv: Vec<f64>,
    kx: Vec<f64>,
}

impl Structure<'_> {
    /// out = minv * (F - C V - K X) - ag: relative accelerations (Building.accel).
    #[inline]
    fn accel(&mut self, x: &[f64], v: &[f64], f: &[f64], ag: f64, out: &mut [f64]) {
        mat_vec(self.c, v, &mut self.cv);
        mat_vec(self.k, x, &mut self.kx);
        for i in 0..out.len() {
            out[i] = self.minv[i] * (f[i] - self.cv[i] - self.kx[i]) - ag;
        }
    }
}

/// out = f + 0.0: the Python master adds the external floor forces (none here, the scalar 0.0),
/// which turns a -0.0 into +0.0.
#[inline]
fn plus_zero(f: &[f64], out: &mut [f64]) {
    for (o, fi) in out.iter_mut().zip(f) {
        *o = fi + 0.0;
    }
}

/// Co-simulate one run on the pool's instances.
pub fn simulate(lib: &Library, pool: &mut Pool, run: &Run) -> Result<Outcome, String> {
    let n = check(run)?;
    let nd = run.dampers.len();
    for (j, d) in run.dampers.iter().enumerate() {
        let inactive = pool.get(lib, j)?.configure(&d.params)?;
        if inactive.to_bits() != d.inactive.to_bits() {
            return Err(format!(
                "damper {j}: the FMU reports mass.inactive = {inactive} kg, the structure was \
                 built with {} kg",
                d.inactive
            ));
        }
    }
    let dampers = &mut pool.instances[..nd];
    for d in dampers.iter_mut() {
        d.timed = run.timing;
        d.in_do_step = std::time::Duration::ZERO;
    }
    let floors: Vec<usize> = run.dampers.iter().map(|d| d.floor).collect();
    let mut s = Structure {
        minv: &run.minv,
        c: &run.c,
        k: &run.k,
        cv: vec![0.0; n],
        kx: vec![0.0; n],
    };
    let h = run.step;
    let ground = run.ground;
    let steps = (run.duration / h).round_ties_even() as usize;
    let t_tail = run.duration - run.tail;
    let derivatives = run.derivatives;

    let mut x = vec![0.0; n];
    let mut v = vec![0.0; n];
    let mut peak = vec![0.0f64; n];
    // scratch
    let mut f = vec![0.0; n];
    let mut df = vec![0.0; n];
    let mut a0 = vec![0.0; n];
    let mut a_rate = vec![0.0; n];
    let mut fs = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    let (mut x2, mut v2) = (vec![0.0; n], vec![0.0; n]);
    let mut k1v = vec![0.0; n];
    let mut k2v = vec![0.0; n];
    let mut k3v = vec![0.0; n];
    let mut k4v = vec![0.0; n];
    let (mut k2x, mut k3x, mut k4x) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut a_rel = vec![0.0; n];
    let mut fe = vec![0.0; n];
    let mut rates = Vec::with_capacity(nd);

    // per-damper values summed onto the dampers' floors
    let on_floors = |out: &mut [f64], values: &mut dyn Iterator<Item = f64>| {
        out.fill(0.0);
        for (i, val) in floors.iter().zip(values) {
            out[*i] += val;
        }
    };

    for step in 0..steps {
        let t = step as f64 * h;
        let held = !(derivatives || step == 0);
        on_floors(
            &mut f,
            &mut dampers
                .iter()
                .map(|d| if held { d.force_mean } else { d.force }),
        );
        df.fill(0.0);
        // the ground at the step's start, mid-step and end: each time once (the Python master
        // evaluates some twice, to the same numbers)
        let (ag0, vg0, xg0) = if derivatives {
            ground.at(t)
        } else {
            (ground.accel(t), 0.0, 0.0)
        };
        let ag_half = ground.accel(t + h / 2.0);
        let end = if derivatives {
            (ground.accel(t + h), 0.0, 0.0)
        } else {
            ground.at(t + h)
        };
        if derivatives && nd > 0 {
            let (ag, vg, xg) = (ag0, vg0, xg0);
            plus_zero(&f, &mut fe);
            s.accel(&x, &v, &fe, ag, &mut a0);
            // the force rates depend on base.a: read them with this step's inputs set
            for (d, &i) in dampers.iter_mut().zip(&floors) {
                d.set_inputs(t, ag + a0[i], vg + v[i], xg + x[i])?;
            }
            rates.clear();
            for d in dampers.iter_mut() {
                rates.push(d.force_rate()?);
            }
            on_floors(&mut df, &mut rates.iter().copied());
            mat_vec(s.c, &a0, &mut s.cv);
            mat_vec(s.k, &v, &mut s.kx);
            for i in 0..n {
                // + 0.0: the external forces' slope (none here)
                a_rate[i] = s.minv[i] * (df[i] + 0.0 - s.cv[i] - s.kx[i]);
            }
            for (d, &i) in dampers.iter_mut().zip(&floors) {
                d.step_with_rate(t, h, Some(a_rate[i]))?;
            }
        }

        // the floor forces at the RK4 stage times t, t + h/2, t + h
        for (j, fj) in fs.iter_mut().enumerate() {
            if derivatives {
                let c = 0.5 * h * j as f64;
                for i in 0..n {
                    fj[i] = f[i] + df[i] * c + 0.0;
                }
            } else {
                fj.copy_from_slice(&f);
            }
        }

        // RK4 over the step (k1x = V)
        s.accel(&x, &v, &fs[0], ag0, &mut k1v);
        let half = h / 2.0;
        for i in 0..n {
            x2[i] = x[i] + half * v[i];
            v2[i] = v[i] + half * k1v[i];
        }
        k2x.copy_from_slice(&v2);
        s.accel(&x2, &v2, &fs[1], ag_half, &mut k2v);
        for i in 0..n {
            x2[i] = x[i] + half * k2x[i];
            v2[i] = v[i] + half * k2v[i];
        }
        k3x.copy_from_slice(&v2);
        s.accel(&x2, &v2, &fs[1], ag_half, &mut k3v);
        for i in 0..n {
            x2[i] = x[i] + h * k3x[i];
            v2[i] = v[i] + h * k3v[i];
        }
        k4x.copy_from_slice(&v2);
        s.accel(&x2, &v2, &fs[2], end.0, &mut k4v);
        let sixth = h / 6.0;
        for i in 0..n {
            x[i] += sixth * (v[i] + 2.0 * k2x[i] + 2.0 * k3x[i] + k4x[i]);
            v[i] += sixth * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
        }

        if !derivatives && nd > 0 {
            let (ag, vg, xg) = end;
            plus_zero(&f, &mut fe);
            s.accel(&x, &v, &fe, ag, &mut a_rel);
            for (d, &i) in dampers.iter_mut().zip(&floors) {
                d.step(t, h, ag + a_rel[i], vg + v[i], xg + x[i])?;
            }
        }
        if (step + 1) as f64 * h > t_tail {
            for (p, xi) in peak.iter_mut().zip(&x) {
                // NaN propagates, as numpy's max does
                if !p.is_nan() && (xi.is_nan() || xi.abs() > *p) {
                    *p = xi.abs();
                }
            }
        }
    }
    let do_step_seconds = dampers.iter().map(|d| d.in_do_step.as_secs_f64()).sum();
    Ok(Outcome {
        peak,
        steps,
        do_step_seconds,
    })
}
