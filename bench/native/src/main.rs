//! tld-bench: native work-precision benchmark host for TLD.fmu.
//!
//! Usage: `tld-bench JOBFILE`. The job file (written by bench/python/workprec/native.py) is read line by
//! line; settings lines configure, `run` lines execute:
//!
//! ```text
//! lib PATH                    the FMU's binaries/linux64/TLD.so (another `lib` line: the
//!                             `fmu` runs after it drive that library, e.g. bench/c's C FMU)
//! guid GUID
//! vrs base_a=50 x=63 v=64 force=60 mass_inactive=43
//! input PATH N                N f64 (little endian): base.a held over step k (open-loop scenes)
//! coupled M=.. C=.. K=.. Ag=.. wg=.. sub=.. n=.. m0=..   structure + ground motion (coupled scene)
//! dt SECONDS
//! repeats R
//! outdir DIR
//! model omega=.. zeta=.. eta=.. phi=.. a=.. m=..       the baseline's model constants
//! run ID fmu R:vr=value I:vr=value ...                  TLD.fmu with these parameters
//! run ID rk4 sub=S [span=abs]                           plain-Rust RK4, S substeps per step
//!                                                       (span=abs: over (t+dt)-t, diagnostic)
//! run ID dp45 rtol=TOL                                  plain-Rust Dormand-Prince 5(4)
//! clock wall|cpu              what the runs below time: the wall clock (default) or the
//!                             CPU time of the host's thread (not stretched by other
//!                             processes on a loaded machine)
//! latency on|off              open-loop runs below also time every step on its own (by the
//!                             `clock`: the wall clock, std::time::Instant, whose own cost, some
//!                             20-40 ns, is in every figure; or the thread's CPU time, a system
//!                             call of some 100s of ns, which preemption does not stretch) and print
//!                             `latency ID median_ns p99_ns p9999_ns max_ns` over the steps of
//!                             all repeats
//! ```
//!
//! Each run is repeated R times on a fresh instance; only the stepping loop is timed
//! (std::time::Instant around it, or the thread's CPU time: `clock`). Per run it writes DIR/ID.x.f64 (slosh.x at the N+1
//! communication points; open-loop scenes also DIR/ID.f.f64, force; coupled scene
//! DIR/ID.X.f64, the structure's displacement) and
//! prints `result ID ok N median_ns t1,t2,..` or `result ID fail STEP message`.

mod baseline;
mod fmu;

use std::collections::HashMap;
use std::io::Write;
use std::time::Instant;

/// What a run's time is measured by.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum Clock {
    #[default]
    Wall,
    /// CPU time of this thread.
    Cpu,
}

/// A running stopwatch of `Clock`.
enum Stopwatch {
    Wall(Instant),
    Cpu(u128),
}

fn thread_cpu_ns() -> u128 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes the timespec it is given, which lives across the call.
    if unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) } != 0 {
        return 0;
    }
    t.tv_sec as u128 * 1_000_000_000 + t.tv_nsec as u128
}

impl Stopwatch {
    fn start(clock: Clock) -> Self {
        match clock {
            Clock::Wall => Stopwatch::Wall(Instant::now()),
            Clock::Cpu => Stopwatch::Cpu(thread_cpu_ns()),
        }
    }

    fn ns(&self) -> u128 {
        match self {
            Stopwatch::Wall(t0) => t0.elapsed().as_nanos(),
            Stopwatch::Cpu(t0) => thread_cpu_ns().saturating_sub(*t0),
        }
    }
}

use baseline::{Dp45, Model, Rk4};
use fmi2_host::Value;

/// Something that advances the sloshing over one communication step with base.a held and
/// returns (slosh.x, slosh.v, force) at its end.
pub trait Damper {
    fn step(&mut self, t: f64, dt: f64, ab: f64) -> Result<[f64; 3], String>;
    /// (x, v, force) now, before any step.
    fn outputs(&mut self) -> Result<[f64; 3], String>;
}

/// Baseline damper: model + integrator + state.
struct Plain<I> {
    model: Model,
    integ: I,
    y: [f64; 2],
    /// Diagnostic: integrate over (t + dt) - t, the interval length as seen from absolute
    /// times, instead of dt (reproduces an FMU that computes its span from t0 and t1).
    abs_span: bool,
}

trait Integrator {
    fn advance(&mut self, m: &Model, ab: f64, y: &mut [f64; 2], dt: f64) -> Result<(), String>;
}

impl Integrator for Rk4 {
    #[inline(always)]
    fn advance(&mut self, m: &Model, ab: f64, y: &mut [f64; 2], dt: f64) -> Result<(), String> {
        self.step(m, ab, y, dt)
    }
}

impl Integrator for Dp45 {
    #[inline(always)]
    fn advance(&mut self, m: &Model, ab: f64, y: &mut [f64; 2], dt: f64) -> Result<(), String> {
        self.step(m, ab, y, dt)
    }
}

impl<I: Integrator> Damper for Plain<I> {
    #[inline]
    fn step(&mut self, t: f64, dt: f64, ab: f64) -> Result<[f64; 3], String> {
        let span = if self.abs_span { (t + dt) - t } else { dt };
        self.integ.advance(&self.model, ab, &mut self.y, span)?;
        let [x, v] = self.y;
        Ok([x, v, self.model.force(x, v)])
    }
    fn outputs(&mut self) -> Result<[f64; 3], String> {
        let [x, v] = self.y;
        Ok([x, v, self.model.force(x, v)])
    }
}

/// Structure of the coupled scene: (M + m0) a_tank = F - C X' - K X, X relative to the ground,
/// a_tank = X'' + a_g absolute, ground motion x_g = Ag sin(wg t).
#[derive(Clone, Copy, Debug)]
struct Coupled {
    mass: f64,
    c: f64,
    k: f64,
    ag: f64,
    wg: f64,
    sub: u32,
    n: usize,
    m0: f64,
}

/// Open-loop scene with every step timed on its own by `clock`: the loop of [`run_open`]
/// with a clock read between steps, the step times (ns) in `per_step`.
fn run_open_per_step<D: Damper>(
    d: &mut D,
    a: &[f64],
    dt: f64,
    clock: Clock,
    per_step: &mut Vec<u32>,
) -> RunResult {
    let n = a.len();
    let mut xs = vec![0.0; n + 1];
    let o = d.outputs().map_err(|e| (0, e))?;
    xs[0] = o[0];
    per_step.reserve(n);
    let t0 = Stopwatch::start(clock);
    let mut last = t0.ns();
    for k in 0..n {
        let o = d.step(k as f64 * dt, dt, a[k]).map_err(|e| (k, e))?;
        xs[k + 1] = o[0];
        let now = t0.ns();
        per_step.push(u32::try_from(now.saturating_sub(last)).unwrap_or(u32::MAX));
        last = now;
    }
    Ok(Run {
        ns: t0.ns(),
        x: xs,
        big_x: vec![],
        force: vec![],
    })
}

/// (median, 99th, 99.99th percentile, max) of the step times, nearest rank.
fn tails(times: &mut [u32]) -> [u32; 4] {
    times.sort_unstable();
    let n = times.len();
    if n == 0 {
        return [0; 4];
    }
    // the ceil(n q)-th smallest, q = num / den in integers (0.9999 n is no integer in f64)
    let rank = |num: usize, den: usize| times[(n * num).div_ceil(den).clamp(1, n) - 1];
    [rank(1, 2), rank(99, 100), rank(9999, 10_000), times[n - 1]]
}

/// Open-loop scene: base.a[k] held over step k. Returns (elapsed ns, x history, force history).
fn run_open<D: Damper>(d: &mut D, a: &[f64], dt: f64, clock: Clock) -> RunResult {
    let n = a.len();
    let mut xs = vec![0.0; n + 1];
    let mut vs = vec![0.0; n + 1];
    let mut fs = vec![0.0; n + 1];
    let o = d.outputs().map_err(|e| (0, e))?;
    (xs[0], vs[0], fs[0]) = (o[0], o[1], o[2]);
    let t0 = Stopwatch::start(clock);
    for k in 0..n {
        let o = d.step(k as f64 * dt, dt, a[k]).map_err(|e| (k, e))?;
        xs[k + 1] = o[0];
        vs[k + 1] = o[1];
        fs[k + 1] = o[2];
    }
    let ns = t0.ns();
    std::hint::black_box(&vs);
    Ok(Run {
        ns,
        x: xs,
        big_x: vec![],
        force: fs,
    })
}

/// What a timed run gives: ns in the stepping loop, slosh.x at the communication points, the
/// structure's X for the coupled scene and force for the open-loop ones (empty otherwise).
struct Run {
    ns: u128,
    x: Vec<f64>,
    big_x: Vec<f64>,
    force: Vec<f64>,
}

/// A run, or the step it failed at and why.
type RunResult = Result<Run, (usize, String)>;

/// The co-simulation master of the coupled scene (explicit, force held over the step):
/// at t_k, a_tank = (F_k - C V_k - K X_k)/(M + m0) is given to the damper as base.a, the damper
/// steps, and the structure is advanced over the same step by RK4 (`sub` substeps) with F_k
/// held and the ground acceleration evaluated where RK4 needs it. The reference master
/// (`coupled_master` in python/tld_fmu/scenes.py) performs the same operations in the same order.
fn run_coupled<D: Damper>(d: &mut D, s: &Coupled, m0: f64, dt: f64, clock: Clock) -> RunResult {
    let n = s.n;
    let mut xs = vec![0.0; n + 1];
    let mut big_x = vec![0.0; n + 1];
    let mass = s.mass + m0;
    let o = d.outputs().map_err(|e| (0, e))?;
    xs[0] = o[0];
    let mut force = o[2];
    let (mut x, mut v) = (0.0f64, 0.0f64);
    let h = dt / s.sub as f64;
    let w2a = s.wg * s.wg * s.ag;
    let acc = |t: f64, x: f64, v: f64, f: f64| -> f64 {
        // X'' = (F - C V - K X)/(M + m0) - a_g(t),  a_g = -wg^2 Ag sin(wg t)
        (f - s.c * v - s.k * x) / mass + w2a * (s.wg * t).sin()
    };
    let t0 = Stopwatch::start(clock);
    for k in 0..n {
        let t = k as f64 * dt;
        let a_tank = (force - s.c * v - s.k * x) / mass;
        let o = d.step(t, dt, a_tank).map_err(|e| (k, e))?;
        for j in 0..s.sub {
            let tj = t + j as f64 * h;
            let k1x = v;
            let k1v = acc(tj, x, v, force);
            let k2x = v + 0.5 * h * k1v;
            let k2v = acc(tj + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v, force);
            let k3x = v + 0.5 * h * k2v;
            let k3v = acc(tj + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v, force);
            let k4x = v + h * k3v;
            let k4v = acc(tj + h, x + h * k3x, v + h * k3v, force);
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        }
        force = o[2];
        xs[k + 1] = o[0];
        big_x[k + 1] = x;
    }
    let ns = t0.ns();
    Ok(Run {
        ns,
        x: xs,
        big_x,
        force: vec![],
    })
}

fn kv(tokens: &[&str]) -> HashMap<String, String> {
    tokens
        .iter()
        .filter_map(|t| t.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

fn num(m: &HashMap<String, String>, k: &str) -> Result<f64, String> {
    m.get(k)
        .ok_or(format!("missing {k}"))?
        .parse::<f64>()
        .map_err(|e| format!("{k}: {e}"))
}

fn write_f64(path: &str, v: &[f64]) -> Result<(), String> {
    let mut bytes = Vec::with_capacity(v.len() * 8);
    for x in v {
        bytes.extend_from_slice(&x.to_le_bytes());
    }
    std::fs::write(path, bytes).map_err(|e| format!("{path}: {e}"))
}

fn read_f64(path: &str, n: usize) -> Result<Vec<f64>, String> {
    let b = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    if b.len() != 8 * n {
        return Err(format!("{path}: {} bytes, expected {}", b.len(), 8 * n));
    }
    Ok(b.chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect())
}

fn median(v: &mut [u128]) -> u128 {
    v.sort_unstable();
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2
    }
}

#[derive(Default)]
struct Settings {
    lib: Option<fmi2_host::Library>,
    lib_path: String,
    guid: String,
    vrs: Option<fmu::Vrs>,
    input: Vec<f64>,
    coupled: Option<Coupled>,
    dt: f64,
    repeats: usize,
    outdir: String,
    model: Option<Model>,
    clock: Clock,
    latency: bool,
}

enum Kind {
    Fmu(Vec<(u32, Value)>),
    Rk4(u32, bool),
    Dp45(f64),
}

/// One repeat of a run: fresh damper, timed loop (each step's time added to `per_step` when
/// the settings ask for it, open-loop FMU runs only).
fn once(st: &Settings, kind: &Kind, per_step: &mut Vec<u32>) -> RunResult {
    let e0 = |e: String| (0usize, e);
    match kind {
        Kind::Fmu(params) => {
            let lib = st.lib.as_ref().ok_or((0, "no lib".to_string()))?;
            let vrs = st.vrs.ok_or((0, "no vrs".to_string()))?;
            let mut inst = fmu::Instance::new(lib, vrs, params).map_err(e0)?;
            match &st.coupled {
                Some(c) => {
                    let m0 = inst.mass_inactive().map_err(e0)?;
                    run_coupled(&mut inst, c, m0, st.dt, st.clock)
                }
                None if st.latency => {
                    run_open_per_step(&mut inst, &st.input, st.dt, st.clock, per_step)
                }
                None => run_open(&mut inst, &st.input, st.dt, st.clock),
            }
        }
        Kind::Rk4(sub, abs_span) => {
            let model = st.model.ok_or((0, "no model".to_string()))?;
            let mut d = Plain {
                model,
                integ: Rk4 { sub: *sub },
                y: [0.0; 2],
                abs_span: *abs_span,
            };
            go(&mut d, st)
        }
        Kind::Dp45(rtol) => {
            let model = st.model.ok_or((0, "no model".to_string()))?;
            let mut d = Plain {
                model,
                integ: Dp45::new(*rtol),
                y: [0.0; 2],
                abs_span: false,
            };
            go(&mut d, st)
        }
    }
}

fn go<D: Damper>(d: &mut D, st: &Settings) -> RunResult {
    match &st.coupled {
        Some(c) => run_coupled(d, c, c.m0, st.dt, st.clock),
        None => run_open(d, &st.input, st.dt, st.clock),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 2 {
        eprintln!("usage: tld-bench JOBFILE");
        std::process::exit(2);
    }
    if let Err(e) = real_main(&args[1]) {
        eprintln!("tld-bench: {e}");
        std::process::exit(1);
    }
}

fn real_main(jobfile: &str) -> Result<(), String> {
    let text = std::fs::read_to_string(jobfile).map_err(|e| format!("{jobfile}: {e}"))?;
    let mut st = Settings {
        repeats: 3,
        ..Default::default()
    };
    let stdout = std::io::stdout();
    for (lineno, line) in text.lines().enumerate() {
        let tok: Vec<&str> = line.split_whitespace().collect();
        if tok.is_empty() || tok[0].starts_with('#') {
            continue;
        }
        let err = |e: String| format!("{jobfile}:{}: {e}", lineno + 1);
        match tok[0] {
            "lib" => {
                // the runs below load this library (a job may time several FMUs in turn)
                st.lib_path = tok[1].to_string();
                st.lib = None;
            }
            "guid" => st.guid = tok[1].to_string(),
            "vrs" => {
                let m = kv(&tok[1..]);
                let g = |k: &str| num(&m, k).map(|v| v as u32);
                st.vrs = Some(fmu::Vrs {
                    base_a: g("base_a").map_err(err)?,
                    x: g("x").map_err(err)?,
                    v: g("v").map_err(err)?,
                    force: g("force").map_err(err)?,
                    mass_inactive: g("mass_inactive").map_err(err)?,
                });
            }
            "input" => {
                let n: usize = tok[2].parse().map_err(|e| err(format!("{e}")))?;
                st.input = read_f64(tok[1], n).map_err(err)?;
                st.coupled = None;
            }
            "coupled" => {
                let m = kv(&tok[1..]);
                let g = |k: &str| num(&m, k);
                st.coupled = Some(Coupled {
                    mass: g("M").map_err(err)?,
                    c: g("C").map_err(err)?,
                    k: g("K").map_err(err)?,
                    ag: g("Ag").map_err(err)?,
                    wg: g("wg").map_err(err)?,
                    sub: g("sub").map_err(err)? as u32,
                    n: g("n").map_err(err)? as usize,
                    m0: g("m0").map_err(err)?,
                });
            }
            "dt" => st.dt = tok[1].parse().map_err(|e| err(format!("{e}")))?,
            "repeats" => st.repeats = tok[1].parse().map_err(|e| err(format!("{e}")))?,
            "outdir" => st.outdir = tok[1].to_string(),
            "clock" => {
                st.clock = match tok.get(1).copied() {
                    Some("wall") => Clock::Wall,
                    Some("cpu") => Clock::Cpu,
                    other => return Err(err(format!("clock {other:?}: wall or cpu"))),
                }
            }
            "latency" => {
                st.latency = match tok.get(1).copied() {
                    Some("on") => true,
                    Some("off") => false,
                    other => return Err(err(format!("latency {other:?}: on or off"))),
                }
            }
            "model" => {
                let m = kv(&tok[1..]);
                let g = |k: &str| num(&m, k);
                st.model = Some(Model::new(
                    g("omega").map_err(err)?,
                    g("zeta").map_err(err)?,
                    g("eta").map_err(err)?,
                    g("phi").map_err(err)?,
                    g("a").map_err(err)?,
                    g("m").map_err(err)?,
                ));
            }
            "run" => {
                if st.lib.is_none() && tok[2] == "fmu" {
                    st.lib = Some(fmu::load(&st.lib_path, &st.guid).map_err(err)?);
                }
                let id = tok[1];
                let m = kv(&tok[3..]);
                let kind = match tok[2] {
                    "fmu" => {
                        let mut params = Vec::new();
                        for t in &tok[3..] {
                            let (head, val) = t.split_once('=').ok_or(err(format!("bad {t}")))?;
                            let (ty, vr) = head.split_once(':').ok_or(err(format!("bad {t}")))?;
                            let vr: u32 = vr.parse().map_err(|e| err(format!("{t}: {e}")))?;
                            params.push((
                                vr,
                                match ty {
                                    "R" => Value::Real(
                                        val.parse().map_err(|e| err(format!("{t}: {e}")))?,
                                    ),
                                    "I" => Value::Integer(
                                        val.parse().map_err(|e| err(format!("{t}: {e}")))?,
                                    ),
                                    _ => return Err(err(format!("bad type in {t}"))),
                                },
                            ));
                        }
                        Kind::Fmu(params)
                    }
                    "rk4" => Kind::Rk4(
                        num(&m, "sub").map_err(err)? as u32,
                        m.get("span").map(String::as_str) == Some("abs"),
                    ),
                    "dp45" => Kind::Dp45(num(&m, "rtol").map_err(err)?),
                    other => return Err(err(format!("unknown run kind {other}"))),
                };
                let mut times = Vec::new();
                let mut first: Option<Run> = None;
                let mut failure = None;
                let mut per_step = Vec::new();
                for _ in 0..st.repeats.max(1) {
                    match once(&st, &kind, &mut per_step) {
                        Ok(run) => {
                            times.push(run.ns);
                            if first.is_none() {
                                first = Some(run);
                            }
                        }
                        Err((k, e)) => {
                            failure = Some((k, e));
                            break;
                        }
                    }
                }
                let mut out = stdout.lock();
                match failure {
                    Some((k, e)) => {
                        writeln!(out, "result {id} fail {k} {}", e.replace('\n', " ")).ok();
                    }
                    None => {
                        let Some(Run {
                            x, big_x, force, ..
                        }) = first
                        else {
                            return Err(err("no repeat ran".into()));
                        };
                        write_f64(&format!("{}/{id}.x.f64", st.outdir), &x).map_err(err)?;
                        if !big_x.is_empty() {
                            write_f64(&format!("{}/{id}.X.f64", st.outdir), &big_x).map_err(err)?;
                        }
                        if !force.is_empty() {
                            write_f64(&format!("{}/{id}.f.f64", st.outdir), &force).map_err(err)?;
                        }
                        if !per_step.is_empty() {
                            let [median, p99, p9999, max] = tails(&mut per_step);
                            writeln!(out, "latency {id} {median} {p99} {p9999} {max}").ok();
                        }
                        let all: Vec<String> = times.iter().map(|t| t.to_string()).collect();
                        let med = median(&mut times.clone());
                        writeln!(
                            out,
                            "result {id} ok {} {med} {}",
                            x.len() - 1,
                            all.join(",")
                        )
                        .ok();
                    }
                }
                out.flush().ok();
            }
            other => return Err(err(format!("unknown directive {other}"))),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    /// Nearest rank: of 1..=10,000 ns the median is 5,000, the 99th percentile 9,900, the
    /// 99.99th 9,999 (not the worst), the worst 10,000; of 3 steps the median is the 2nd (the
    /// rank rounds up); whatever the order they came in.
    #[test]
    fn tails_are_nearest_ranks() {
        let mut times: Vec<u32> = (1..=10_000).rev().collect();
        assert_eq!(super::tails(&mut times), [5_000, 9_900, 9_999, 10_000]);
        assert_eq!(super::tails(&mut [3, 1, 2]), [2, 3, 3, 3]);
        assert_eq!(super::tails(&mut [7]), [7; 4]);
        assert_eq!(super::tails(&mut []), [0; 4]);
    }
}
