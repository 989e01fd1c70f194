//! Fit phi and eta of Eq 2.13 and the damping law zeta = c Lambda^p so that the model's
//! harmonic-balance jump frequency and damping follow a kappa(Lambda), zeta(Lambda) data set;
//! print the fit and its residuals. `tld-calibrate --help` documents the options and the CSV.

use clap::{Parser, ValueEnum};
use tld_fmu::analysis::calibration::{Sample, calibrate, kappa_model};
use tld_fmu::analysis::sweep::{Characteristic, Plan, Settling, characterise};
use tld_fmu::description::{AmplitudeModeItem, DampingLawItem, ModelKindItem, vr};
use tld_fmu::model::StartValues;
use tld_fmu::physics::geometry::Tank;
use tld_fmu::physics::laws::nsd_kappa;

/// Calibrate the nonlinear TLD model to measured jump frequencies and damping.
///
/// Fits phi and eta of the power law Phi (Eq 2.13) so that the harmonic-balance jump frequency
/// of a slow upward sweep, as a fraction kappa of w_f (the tank's linear fundamental sloshing
/// frequency), follows the data, and the NSD damping law zeta = c Lambda^p to the damping data
/// (c, p are the FMU's nsd.c, nsd.p). Prints the fit and the residuals per sample.
///
/// The data (--source): the NSD laws of docs/MODEL.md (kappa = 1.075 Lambda^0.007 below
/// Lambda = 0.03, 2.52 Lambda^0.25 above; zeta = 0.5 Lambda^0.35); a CSV file (--data); or the
/// shallow-water model of the tank (model = ShallowWater, damping = BoundaryLayer), swept slowly
/// up and down in frequency at each Lambda (stepped sine, each frequency settled): kappa is the
/// frequency over w_f where the up-sweep's response is in quadrature with the excitation (the
/// equivalent linear resonance), zeta the energy-equivalent damping there. The
/// NSD and shallow-water sources take --points values of Lambda spaced logarithmically over
/// [--from, --to].
#[derive(Parser, Debug)]
#[command(name = "tld-calibrate", version, after_help = DATA_FORMAT)]
struct Args {
    /// where the kappa(Lambda), zeta(Lambda) data come from (default: data with --data, else nsd)
    #[arg(long, value_enum)]
    source: Option<Source>,
    /// the data set: a CSV file of Lambda,kappa,zeta samples (format below)
    #[arg(long, value_name = "FILE.csv")]
    data: Option<String>,
    /// tank length a along the motion [m]
    #[arg(long, default_value_t = 0.25)]
    length: f64,
    /// still-water depth h [m]
    #[arg(long, default_value_t = 0.021)]
    depth: f64,
    /// tank breadth b across the motion [m] (shallow-water source: the boundary-layer damping)
    #[arg(long, default_value_t = 0.32)]
    breadth: f64,
    /// smallest Lambda (default 0.005; shallow-water 0.001)
    #[arg(long)]
    from: Option<f64>,
    /// largest Lambda (default 0.1; shallow-water 0.3)
    #[arg(long)]
    to: Option<f64>,
    /// number of samples, >= 2 (default 12; shallow-water 8)
    #[arg(long)]
    points: Option<usize>,
    /// shallow-water source: finite volumes across the tank (default: the FMU's swe.cells)
    #[arg(long)]
    cells: Option<u32>,
    /// shallow-water source: the sweeps' frequency step, as a fraction of w_f
    #[arg(long, default_value_t = 0.01)]
    step: f64,
    /// shallow-water source: the sweeps' lowest frequency over w_f (the up-sweep starts there)
    #[arg(long, default_value_t = 0.8)]
    lowest: f64,
    /// shallow-water source: the up-sweep's highest frequency over w_f
    #[arg(long, default_value_t = 2.5)]
    highest: f64,
    /// shallow-water source: write every swept point as CSV to this file (columns
    /// lambda,direction,ratio,x,phase,x_peak,zeta_eq,cycles,settled,jump; jump is 1 on the last
    /// point before the sweep jumps)
    #[arg(long, value_name = "OUT")]
    sweeps: Option<String>,
    /// write the samples with the fitted model as CSV to OUT (columns
    /// lambda,kappa_data,kappa_model,zeta_data,zeta_model,kappa_nsd,zeta_nsd, the last two the NSD
    /// laws at that Lambda; first line a `# phi=...,eta=...,
    /// nsd_c=...,nsd_p=...,omega_f=...,worst_kappa_residual=...` comment with the fit)
    #[arg(long, value_name = "OUT")]
    csv: Option<String>,
    /// write the fitted model and the NSD laws on 81 values of Lambda spaced logarithmically
    /// over the samples' range as CSV to OUT (columns lambda,kappa_model,zeta_model,kappa_nsd,
    /// zeta_nsd): the plot's curves
    #[arg(long, value_name = "OUT")]
    curve: Option<String>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Source {
    /// the NSD laws (a published fit of experiments)
    Nsd,
    /// a CSV file (--data)
    Data,
    /// slow frequency sweeps of the shallow-water model of the tank
    ShallowWater,
}

const DATA_FORMAT: &str = "\
Data format (--data FILE.csv): plain text, one sample per line, three comma-separated numbers
  Lambda  the excitation amplitude over the tank length, A_e / a        (> 0)
  kappa   the jump frequency of a slow upward sweep over w_f            (> 0)
  zeta    the equivalent damping ratio of the sloshing at that Lambda   (> 0)
An optional header line names the columns (any case, any order), e.g. `Lambda,kappa,zeta`;
without one the order is Lambda,kappa,zeta. Blank lines and lines starting with # are skipped.
Example (three samples of the NSD laws, which the default data follow):
  Lambda,kappa,zeta
  0.005,1.0359,0.0783
  0.02,1.0460,0.1272
  0.08,1.3402,0.2066";

fn main() {
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("tld-calibrate: {e}");
        std::process::exit(2);
    }
}

/// The samples of a data file (format: DATA_FORMAT).
fn read_samples(text: &str) -> Result<Vec<Sample>, String> {
    let mut order = [0usize, 1, 2];
    let mut samples = Vec::new();
    let mut first = true;
    for (n, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = l.split(',').map(str::trim).collect();
        let header = first && fields.iter().any(|f| f.parse::<f64>().is_err());
        first = false;
        if header {
            // which column holds Lambda, kappa and zeta
            let names: Vec<String> = fields.iter().map(|f| f.to_lowercase()).collect();
            for (slot, want) in ["lambda", "kappa", "zeta"].iter().enumerate() {
                order[slot] = names.iter().position(|f| f == want).ok_or_else(|| {
                    format!(
                        "line {}: header '{l}' has no column '{want}' (need Lambda,kappa,zeta)",
                        n + 1
                    )
                })?;
            }
            if names.len() != 3 {
                return Err(format!(
                    "line {}: header '{l}' needs exactly the columns Lambda,kappa,zeta",
                    n + 1
                ));
            }
            continue;
        }
        let v: Vec<f64> = fields
            .iter()
            .map(|x| x.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("line {}: '{l}' is not three numbers", n + 1))?;
        if v.len() != 3 {
            return Err(format!("line {}: '{l}' needs Lambda,kappa,zeta", n + 1));
        }
        samples.push(Sample {
            lambda: v[order[0]],
            kappa: v[order[1]],
            zeta: v[order[2]],
        });
    }
    Ok(samples)
}

fn run(o: &Args) -> Result<(), String> {
    let tank = Tank {
        length: o.length,
        breadth: o.breadth,
        depth: o.depth,
        density: 1000.0,
        g: 9.81,
    };
    let source = o.source.unwrap_or(if o.data.is_some() {
        Source::Data
    } else {
        Source::Nsd
    });
    let swept = source == Source::ShallowWater;
    let from = o.from.unwrap_or(if swept { 0.001 } else { 0.005 });
    let to = o.to.unwrap_or(if swept { 0.3 } else { 0.1 });
    let n = o.points.unwrap_or(if swept { 8 } else { 12 }).max(2);
    if !(from > 0.0 && to > from) {
        return Err(format!("need 0 < --from < --to, not {from}, {to}"));
    }
    let lambdas: Vec<f64> = (0..n)
        .map(|k| from * (to / from).powf(k as f64 / (n - 1) as f64))
        .collect();
    let samples: Vec<Sample> = match source {
        Source::Data => {
            let path = o
                .data
                .as_deref()
                .ok_or("--source data needs --data FILE.csv")?;
            read_samples(
                &std::fs::read_to_string(path).map_err(|e| format!("cannot read {path}: {e}"))?,
            )
            .map_err(|e| format!("{path}: {e}"))?
        }
        Source::Nsd => lambdas
            .iter()
            .map(|&lambda| Sample {
                lambda,
                kappa: nsd_kappa(lambda),
                zeta: 0.5 * lambda.powf(0.35),
            })
            .collect(),
        Source::ShallowWater => {
            let found = shallow_water(o, &tank, &lambdas)?;
            if let Some(path) = &o.sweeps {
                write_sweeps(path, &found)?;
            }
            for c in found.iter().filter(|c| c.quadrature.is_none()) {
                eprintln!(
                    "tld-calibrate: Lambda = {}: the up-sweep never reached quadrature below {} w_f; left out of the fit",
                    c.lambda, o.highest
                );
            }
            found
                .iter()
                .filter_map(|c| {
                    c.quadrature.map(|(kappa, zeta)| Sample {
                        lambda: c.lambda,
                        kappa,
                        zeta,
                    })
                })
                .collect()
        }
    };
    if samples.len() < 2
        || samples
            .iter()
            .any(|s| !(s.lambda > 0.0 && s.kappa > 0.0 && s.zeta > 0.0))
    {
        return Err("need at least two samples with positive Lambda, kappa and zeta".into());
    }
    let wf = tank.fundamental().omega;
    let fit = calibrate(wf, tank.length, &samples);
    println!(
        "fit: phi = {:.5}, eta = {:.5}, nsd.c = {:.5}, nsd.p = {:.5}  (w_f = {wf:.5} rad/s)",
        fit.phi, fit.eta, fit.nsd_c, fit.nsd_p
    );
    println!("\n  Lambda     kappa data  kappa model  residual    zeta data  residual");
    let mut rows = String::new();
    for (k, s) in samples.iter().enumerate() {
        let zeta = fit.nsd_c * s.lambda.powf(fit.nsd_p);
        let model =
            kappa_model(wf, tank.length, fit.phi, fit.eta, s.lambda, zeta).unwrap_or(f64::NAN);
        println!(
            "  {:8.5}   {:10.5}   {:10.5}   {:+8.2e}   {:9.5}   {:+8.2e}",
            s.lambda, s.kappa, model, fit.kappa_residuals[k], s.zeta, fit.zeta_residuals[k]
        );
        rows.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            s.lambda,
            s.kappa,
            model,
            s.zeta,
            zeta,
            nsd_kappa(s.lambda),
            0.5 * s.lambda.powf(0.35)
        ));
    }
    let worst = fit
        .kappa_residuals
        .iter()
        .fold(0.0f64, |m, r| m.max(r.abs()));
    println!("\nlargest kappa residual {worst:.2e}");
    if let Some(path) = &o.csv {
        let text = format!(
            "# phi={},eta={},nsd_c={},nsd_p={},omega_f={wf},worst_kappa_residual={worst}\nlambda,kappa_data,kappa_model,zeta_data,zeta_model,kappa_nsd,zeta_nsd\n{rows}",
            fit.phi, fit.eta, fit.nsd_c, fit.nsd_p
        );
        std::fs::write(path, text).map_err(|e| format!("cannot write {path}: {e}"))?;
    }
    if let Some(path) = &o.curve {
        let (lo, hi) = samples.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), s| {
            (lo.min(s.lambda), hi.max(s.lambda))
        });
        let mut text = String::from("lambda,kappa_model,zeta_model,kappa_nsd,zeta_nsd\n");
        for k in 0..=80 {
            let lambda = lo * (hi / lo).powf(f64::from(k) / 80.0);
            let zeta = fit.nsd_c * lambda.powf(fit.nsd_p);
            let model =
                kappa_model(wf, tank.length, fit.phi, fit.eta, lambda, zeta).unwrap_or(f64::NAN);
            text.push_str(&format!(
                "{lambda},{model},{zeta},{},{}\n",
                nsd_kappa(lambda),
                0.5 * lambda.powf(0.35)
            ));
        }
        std::fs::write(path, text).map_err(|e| format!("cannot write {path}: {e}"))?;
    }
    Ok(())
}

/// The shallow-water model of `tank`, characterised at each Lambda (on all cores).
fn shallow_water(o: &Args, tank: &Tank, lambdas: &[f64]) -> Result<Vec<Characteristic>, String> {
    let item = |i: i64| i as f64;
    let mut p = StartValues::default()
        .with(vr::MODEL, item(ModelKindItem::ShallowWater as i64))
        .with(vr::DAMPING, item(DampingLawItem::BoundaryLayer as i64))
        .with(vr::AMPLITUDE, item(AmplitudeModeItem::Fixed as i64))
        .with(vr::TANKS, 1.0)
        .with(vr::TANK_LENGTH, tank.length)
        .with(vr::TANK_BREADTH, tank.breadth)
        .with(vr::TANK_DEPTH, tank.depth)
        .with(vr::SLOSH_X0, 0.0)
        .with(vr::SLOSH_V0, 0.0);
    if let Some(cells) = o.cells {
        p = p.with(vr::SWE_CELLS, f64::from(cells));
    }
    let plan = Plan {
        from: o.lowest,
        to: o.highest,
        step: o.step,
        settling: Settling::default(),
    };
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(vec![None; lambdas.len()]);
    std::thread::scope(|scope| {
        for _ in 0..workers.min(lambdas.len()) {
            scope.spawn(|| {
                loop {
                    let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(&lambda) = lambdas.get(k) else { break };
                    let started = std::time::Instant::now();
                    let found = characterise(&p, lambda, &plan);
                    if let Ok(c) = &found {
                        let (kappa, zeta) = c.quadrature.unwrap_or((f64::NAN, f64::NAN));
                        eprintln!(
                            "  Lambda {lambda:.4}: kappa {kappa:.3}, zeta {zeta:.4}, largest response at {:.2} w_f ({} + {} frequencies, {:.0} s)",
                            c.peak.ratio,
                            c.up.len(),
                            c.down.len(),
                            started.elapsed().as_secs_f64()
                        );
                    }
                    if let Ok(mut all) = results.lock() {
                        all[k] = Some(found);
                    }
                }
            });
        }
    });
    let all = results.into_inner().map_err(|_| "a sweep thread failed")?;
    all.into_iter()
        .zip(lambdas)
        .map(|(found, lambda)| {
            found
                .unwrap_or_else(|| Err("not run".into()))
                .map_err(|e| format!("Lambda = {lambda}: {e}"))
        })
        .collect()
}

/// Every swept point as CSV.
fn write_sweeps(path: &str, found: &[Characteristic]) -> Result<(), String> {
    let mut text =
        String::from("lambda,direction,ratio,x,phase,x_peak,zeta_eq,cycles,settled,jump\n");
    for c in found {
        for (direction, points, jump) in [("up", &c.up, c.jump_down), ("down", &c.down, c.jump_up)]
        {
            // 1 on the last point before the sweep's jump (analysis::sweep::jump's)
            let before = jump.map(|(b, _)| b.ratio);
            for r in points.iter() {
                text.push_str(&format!(
                    "{},{direction},{:.6},{},{},{},{},{},{},{}\n",
                    c.lambda,
                    r.ratio,
                    r.x,
                    r.phase,
                    r.x_peak,
                    r.zeta_eq,
                    r.cycles,
                    u8::from(r.settled),
                    u8::from(before == Some(r.ratio))
                ));
            }
        }
    }
    std::fs::write(path, text).map_err(|e| format!("cannot write {path}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::{Args, Parser, read_samples, run, shallow_water};
    use tld_fmu::physics::geometry::Tank;

    /// The shallow-water source end to end on a coarse tank (12 cells, steps of 0.05 w_f): both
    /// amplitudes reach quadrature, the larger one later (hardening), with more damping; the
    /// sweeps' CSV has every point.
    #[test]
    fn the_shallow_water_source_measures_hardening() {
        let csv = std::env::temp_dir().join(format!("tld-calibrate-{}.csv", std::process::id()));
        let o = Args::try_parse_from([
            "tld-calibrate",
            "--source",
            "shallow-water",
            "--cells",
            "12",
            "--step",
            "0.05",
            "--lowest",
            "0.9",
            "--highest",
            "1.6",
        ])
        .expect("arguments");
        let tank = Tank {
            length: 0.25,
            breadth: 0.32,
            depth: 0.021,
            density: 1000.0,
            g: 9.81,
        };
        let found = shallow_water(&o, &tank, &[0.003, 0.03]).expect("sweeps");
        let (k0, z0) = found[0].quadrature.expect("quadrature");
        let (k1, z1) = found[1].quadrature.expect("quadrature");
        assert!(k1 > k0 && z1 > z0, "{k0} {z0} {k1} {z1}");
        super::write_sweeps(csv.to_str().expect("path"), &found).expect("written");
        let text = std::fs::read_to_string(&csv).expect("read");
        let points: usize = found.iter().map(|c| c.up.len() + c.down.len()).sum();
        assert_eq!(text.lines().count(), 1 + points);
        // A point is marked before a jump exactly when the sweep found one.
        let jumps = found
            .iter()
            .map(|c| usize::from(c.jump_down.is_some()) + usize::from(c.jump_up.is_some()))
            .sum::<usize>();
        assert_eq!(
            text.lines().skip(1).filter(|l| l.ends_with(",1")).count(),
            jumps
        );
        let _ = std::fs::remove_file(&csv);
    }

    #[test]
    fn the_data_source_needs_a_file() {
        let o = Args::try_parse_from(["tld-calibrate", "--source", "data"]).expect("arguments");
        assert!(run(&o).unwrap_err().contains("--data"));
        let o = Args::try_parse_from(["tld-calibrate", "--from", "0.1", "--to", "0.01"])
            .expect("arguments");
        assert!(run(&o).unwrap_err().contains("--from"));
    }

    #[test]
    fn a_header_names_the_columns_in_any_order_and_case() {
        let s = read_samples("# measured\nzeta, LAMBDA ,Kappa\n0.1,0.02,1.05\n\n0.2,0.08,1.3\n")
            .unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].lambda, s[0].kappa, s[0].zeta), (0.02, 1.05, 0.1));
        let s = read_samples("Lambda,kappa,zeta\n0.02,1.05,0.1\n").unwrap();
        assert_eq!((s[0].lambda, s[0].kappa, s[0].zeta), (0.02, 1.05, 0.1));
        let s = read_samples("0.02,1.05,0.1\n0.08,1.3,0.2\n").unwrap();
        assert_eq!((s[1].lambda, s[1].kappa, s[1].zeta), (0.08, 1.3, 0.2));
    }

    #[test]
    fn bad_lines_and_headers_say_where() {
        let e = read_samples("Lambda,kappa,damping\n0.02,1.05,0.1\n").unwrap_err();
        assert!(e.contains("line 1") && e.contains("zeta"), "{e}");
        let e = read_samples("Lambda,kappa,zeta\n0.02,1.05\n").unwrap_err();
        assert!(e.contains("line 2"), "{e}");
        let e = read_samples("0.02,1.05,0.1\nLambda,kappa,zeta\n").unwrap_err();
        assert!(e.contains("line 2"), "{e}");
    }
}
