//! Preliminary design of tuned liquid dampers with damping screens for a structural mode, and
//! its check by co-simulation with the shallow-water model. `tld-design --help` documents it.

mod building;
mod report;

use std::time::Instant;

use clap::Parser;
use tld_fmu::analysis::design::{
    Design, Excitation, Limits, Structure, damper, design_for, history, response, wind_force,
};

/// Design tuned liquid dampers (tanks and damping screens) for a structure's mode under a
/// design excitation, and verify the design by co-simulation.
///
/// The structure: a mode (--mass, --frequency, --damping) or a building configuration
/// (--building FILE, as scripts/examples/building.toml: its first mode at the first damper's
/// floor, shape 1 there, with the tanks' water that does not slosh on that floor). The
/// excitation: a harmonic force at resonance (--force, the default), a wind response level
/// (--wind-rms-accel: the bare structure's rms acceleration at the damper floor) or a
/// ground-motion record (--record FILE: two columns t, a_g).
///
/// The design (after Tait 2008, with Warburton's optima: harmonic force, white-noise force,
/// harmonic ground acceleration): the effective mass ratio mu = m_1/M from the water mass
/// ratio and the depth ratio; the tank tuned to Warburton's frequency ratio at the design
/// amplitude (the NSD hardening taken off the linear frequency), within the footprint; the
/// screens (--screens per tank, a pair at 0.4 a and 0.6 a) whose solidity gives Warburton's
/// damping at the design response (the Screens law, its random form for wind). docs/DESIGN.md
/// explains each step.
///
/// The check: the structure carrying the designed tanks as model = ShallowWater with the
/// screens resolved, against the bare structure, under the same excitation (a slow sweep of
/// the force; one wind realisation of --seed; the record), and the design's robustness: the
/// structure's frequency 10 % lower and higher, the excitation half and twice the design's.
/// Writes a one-page report (Markdown), the curves (CSV) and a plot (SVG) to --out.
#[derive(Parser, Debug)]
#[command(name = "tld-design", version)]
pub struct Args {
    /// modal mass of the structure's mode [kg]
    #[arg(long, default_value_t = 1.0e6)]
    mass: f64,
    /// its natural frequency [Hz]
    #[arg(long, default_value_t = 0.25)]
    frequency: f64,
    /// its damping ratio without dampers
    #[arg(long, default_value_t = 0.01)]
    damping: f64,
    /// a building configuration (TOML, as scripts/examples/building.toml) instead of --mass,
    /// --frequency and --damping
    #[arg(long)]
    building: Option<String>,
    /// amplitude of the harmonic design force at resonance [N] (the modal force)
    #[arg(long, default_value_t = 1.0e4)]
    force: f64,
    /// wind: the bare structure's rms acceleration at the damper floor [m/s^2] (its resonant
    /// response to a white-noise modal force)
    #[arg(long, conflicts_with = "record")]
    wind_rms_accel: Option<f64>,
    /// earthquake: a ground-motion record, two columns t [s], a_g [m/s^2] (comma or blank
    /// separated, evenly spaced; lines starting with # skipped)
    #[arg(long)]
    record: Option<String>,
    /// wind: seconds of the realisation simulated (the first eighth not measured)
    #[arg(long, default_value_t = 1800.0)]
    duration: f64,
    /// wind: seed of the realisation
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// water mass over the modal mass
    #[arg(long, default_value_t = 0.02)]
    mass_ratio: f64,
    /// longest tank along the motion [m]
    #[arg(long, default_value_t = 20.0)]
    max_length: f64,
    /// widest tank across the motion [m] (more tanks when the water needs more breadth)
    #[arg(long, default_value_t = 5.0)]
    max_breadth: f64,
    /// preferred still-water depth over the tank length (shallower if the length needs it)
    #[arg(long, default_value_t = 0.12)]
    depth_ratio: f64,
    /// damping screens per tank (2: Tait's pair at 0.4 a and 0.6 a; otherwise evenly spaced)
    #[arg(long, default_value_t = 2)]
    screens: u32,
    /// finite volumes across each tank in the co-simulation
    #[arg(long, default_value_t = 100)]
    cells: u32,
    /// harmonic: frequencies of each sweep
    #[arg(long, default_value_t = 21)]
    points: usize,
    /// harmonic: periods run at each frequency (the last quarter measured)
    #[arg(long, default_value_t = 60)]
    periods: u32,
    /// where the report, the CSV and the SVG go
    #[arg(long, default_value = "out/design")]
    out: String,
}

/// A verification case: its name, the structure, the excitation's scale.
pub struct Case {
    pub name: &'static str,
    pub structure: Structure,
    pub scale: f64,
}

/// One case's time histories, with and without the tanks: rms and peak displacement.
pub struct Row {
    pub with: (f64, f64),
    pub bare: (f64, f64),
}

/// What the check found.
pub enum Check {
    /// Harmonic: the sweep's frequency ratios and each case's steady amplitudes.
    Sweep {
        ratios: Vec<f64>,
        curves: Vec<Vec<f64>>,
    },
    /// Wind or record: each case's row, and the design case's histories on the step h.
    Histories {
        h: f64,
        rows: Vec<Row>,
        bare: Vec<f64>,
        with: Vec<f64>,
    },
}

/// The structure as designed (with the tanks' inactive water), as co-simulated (without: the
/// shallow-water tanks carry all their water), the participation factors of both, the design.
pub struct Designed {
    pub s: Structure,
    pub sim: Structure,
    pub participation: (f64, f64),
    pub excitation: Excitation,
    pub design: Design,
    pub source: String,
}

fn main() {
    let o = Args::parse();
    if let Err(e) = run(&o) {
        eprintln!("tld-design: {e}");
        std::process::exit(1);
    }
}

/// The ground-motion record: times and accelerations, evenly spaced.
fn read_record(path: &str) -> Result<(f64, Vec<f64>), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let (mut t, mut a) = (Vec::new(), Vec::new());
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let v: Vec<f64> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(|s| s.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{path}:{}: {e}", k + 1))?;
        match v[..] {
            [ti, ai, ..] if ti.is_finite() && ai.is_finite() => {
                t.push(ti);
                a.push(ai);
            }
            _ => return Err(format!("{path}:{}: two numbers t, a_g expected", k + 1)),
        }
    }
    if t.len() < 2 {
        return Err(format!("{path}: fewer than two samples"));
    }
    let step = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    if step.is_nan()
        || step <= 0.0
        || t.windows(2)
            .any(|w| ((w[1] - w[0]) / step - 1.0).abs() > 1e-6)
    {
        return Err(format!(
            "{path}: the times must be evenly spaced and increasing"
        ));
    }
    Ok((step, a))
}

fn design_structure(o: &Args, l: &Limits) -> Result<Designed, String> {
    let record = o.record.as_deref().map(read_record).transpose()?;
    let excite = |s: &Structure, participation: f64| match (&record, o.wind_rms_accel) {
        (Some((step, accel)), _) => Excitation::Record {
            step: *step,
            accel: accel.clone(),
            participation,
        },
        (None, Some(rms)) => Excitation::wind_from_rms_accel(s, rms),
        (None, None) => Excitation::Harmonic,
    };
    let Some(path) = &o.building else {
        let s = Structure {
            mass: o.mass,
            frequency: o.frequency,
            damping: o.damping,
            force: o.force,
        };
        let excitation = excite(&s, s.mass);
        let design = design_for(&s, &excitation, l)?;
        return Ok(Designed {
            s,
            sim: s,
            participation: (s.mass, s.mass),
            excitation,
            design,
            source: format!("a mode of {:.4e} kg at {} Hz", s.mass, s.frequency),
        });
    };
    let cfg = building::Config::read(path)?;
    let structure = |inactive: f64| -> Result<(Structure, f64), String> {
        let m = cfg.mode(inactive)?;
        Ok((
            Structure {
                mass: m.mass,
                frequency: m.omega / (2.0 * std::f64::consts::PI),
                damping: m.damping,
                force: o.force,
            },
            m.participation,
        ))
    };
    let (sim, l_sim) = structure(0.0)?;
    // The water that does not slosh moves with the floor: it lowers the mode the tanks are
    // tuned to (as python/tld_fmu/building.py adds mass.inactive), and depends on the design.
    let mut inactive = 0.0;
    for _ in 0..20 {
        let (s, l_s) = structure(inactive)?;
        let excitation = excite(&s, l_s);
        let design = design_for(&s, &excitation, l)?;
        let tanks = f64::from(design.tanks);
        let next = tanks * (design.tank.liquid_mass() - design.tank.fundamental().mass);
        if (next - inactive).abs() <= 1e-9 * next {
            return Ok(Designed {
                s,
                sim,
                participation: (l_s, l_sim),
                excitation,
                design,
                source: format!(
                    "{path}: first mode at floor {} of {}, with {:.4e} kg of inactive water there",
                    cfg.floor,
                    cfg.masses.len(),
                    inactive
                ),
            });
        }
        inactive = next;
    }
    Err("the tanks' inactive water and the mode did not settle in 20 rounds".into())
}

fn run(o: &Args) -> Result<(), String> {
    let start = Instant::now();
    let l = Limits {
        mass_ratio: o.mass_ratio,
        length: o.max_length,
        breadth: o.max_breadth,
        depth_ratio: o.depth_ratio,
        screens: o.screens,
    };
    if o.points < 2 || o.periods < 8 || o.cells < 8 || o.duration.is_nan() || o.duration < 60.0 {
        return Err("at least 2 points, 8 periods, 8 cells and 60 s of wind".into());
    }
    let d = design_structure(o, &l)?;
    let designed = start.elapsed();
    let sim = d.sim;
    // The design, the structure's frequency scaled by 0.9 and 1.1, the excitation by 0.5, 2.
    let scaled = |frequency: f64, scale: f64| Structure {
        frequency: frequency * sim.frequency,
        force: scale * sim.force,
        ..sim
    };
    let cases = [
        ("design", 1.0, 1.0),
        ("structure -10 %", 0.9, 1.0),
        ("structure +10 %", 1.1, 1.0),
        ("half the excitation", 1.0, 0.5),
        ("twice the excitation", 1.0, 2.0),
    ]
    .map(|(name, f, scale)| Case {
        name,
        structure: scaled(f, scale),
        scale,
    });
    let check = match &d.excitation {
        Excitation::Harmonic => sweep(o, &d.design, &sim, &cases)?,
        e => histories(o, &d, e, &cases)?,
    };
    let elapsed = start.elapsed();
    report::write(&report::Run {
        o,
        d: &d,
        cases: &cases,
        check: &check,
        designed,
        elapsed,
    })
}

/// The harmonic check: each case swept over 0.75-1.25 of the nominal structure's frequency,
/// each on its own thread.
fn sweep(o: &Args, d: &Design, sim: &Structure, cases: &[Case]) -> Result<Check, String> {
    let ratios: Vec<f64> = (0..o.points)
        .map(|k| 0.75 + 0.5 * k as f64 / (o.points - 1) as f64)
        .collect();
    let results: Vec<Result<Vec<f64>, String>> = std::thread::scope(|scope| {
        let handles: Vec<_> = cases
            .iter()
            .map(|c| {
                let ratios = &ratios;
                scope.spawn(move || {
                    // The case's frequencies are the nominal structure's ratios.
                    let own: Vec<f64> = ratios
                        .iter()
                        .map(|r| r * sim.frequency / c.structure.frequency)
                        .collect();
                    response(&c.structure, Some(damper(d, o.cells)?), &own, o.periods, 64)
                })
            })
            .collect();
        join(handles)
    });
    let mut curves = Vec::new();
    for (c, r) in cases.iter().zip(results) {
        curves.push(r.map_err(|e| format!("{}: {e}", c.name))?);
    }
    Ok(Check::Sweep { ratios, curves })
}

fn join<T>(
    handles: Vec<std::thread::ScopedJoinHandle<'_, Result<T, String>>>,
) -> Vec<Result<T, String>> {
    handles
        .into_iter()
        .map(|h| h.join().unwrap_or_else(|_| Err("a case panicked".into())))
        .collect()
}

/// The wind or record check: each case with and without the tanks under the same
/// excitation (scaled), on the structure's step (64 per nominal period, or the record's if
/// finer), each case on its own thread.
fn histories(o: &Args, d: &Designed, e: &Excitation, cases: &[Case]) -> Result<Check, String> {
    let period = 1.0 / d.sim.frequency;
    let (h, force, ground, skip) = match e {
        Excitation::Wind { s0 } => {
            let h = period / 64.0;
            let count = (o.duration / h).ceil() as usize + 1;
            let w = d.sim.omega();
            let f = wind_force(*s0, (0.3 * w, 3.0 * w), h, count, o.seed);
            (h, f, vec![0.0; count], count / 8)
        }
        Excitation::Record { step, accel, .. } => {
            let sub = (step / (period / 64.0)).ceil().max(1.0) as usize;
            let h = step / sub as f64;
            let mut a = Vec::with_capacity((accel.len() - 1) * sub + 1);
            for w in accel.windows(2) {
                for k in 0..sub {
                    a.push(w[0] + (w[1] - w[0]) * k as f64 / sub as f64);
                }
            }
            a.push(accel[accel.len() - 1]);
            (h, vec![0.0; a.len()], a, 0)
        }
        Excitation::Harmonic => return Err("the harmonic check is a sweep".into()),
    };
    let l = d.participation.1;
    let measure = |x: &[f64]| {
        let tail = &x[skip..];
        let rms = (tail.iter().map(|v| v * v).sum::<f64>() / tail.len() as f64).sqrt();
        (rms, tail.iter().fold(0.0f64, |m, v| m.max(v.abs())))
    };
    type Pair = (Vec<f64>, Vec<f64>);
    let results: Vec<Result<Pair, String>> = std::thread::scope(|scope| {
        let handles: Vec<_> = cases
            .iter()
            .map(|c| {
                let (force, ground) = (&force, &ground);
                scope.spawn(move || {
                    let f: Vec<f64> = force.iter().map(|v| v * c.scale).collect();
                    let g: Vec<f64> = ground.iter().map(|v| v * c.scale).collect();
                    let tanks = Some(damper(&d.design, o.cells)?);
                    let with = history(&c.structure, tanks, h, &f, &g, l)?;
                    let bare = history(&c.structure, None, h, &f, &g, l)?;
                    Ok((with, bare))
                })
            })
            .collect();
        join(handles)
    });
    let (mut rows, mut design) = (Vec::new(), None);
    for (c, r) in cases.iter().zip(results) {
        let (with, bare) = r.map_err(|e| format!("{}: {e}", c.name))?;
        rows.push(Row {
            with: measure(&with),
            bare: measure(&bare),
        });
        design.get_or_insert((bare, with));
    }
    let (bare, with) = design.ok_or("no cases")?;
    Ok(Check::Histories {
        h,
        rows,
        bare,
        with,
    })
}
