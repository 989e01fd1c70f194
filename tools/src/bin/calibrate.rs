//! Fit phi and eta of Eq 2.13 and the damping law zeta = c Lambda^p so that the model's
//! harmonic-balance jump frequency and damping follow a kappa(Lambda), zeta(Lambda) data set;
//! print the fit and its residuals. `tld-calibrate --help` documents the options and the CSV.

use clap::Parser;
use tld_fmu::analysis::calibration::{Sample, calibrate, kappa_model};
use tld_fmu::physics::geometry::Tank;
use tld_fmu::physics::laws::nsd_kappa;

/// Calibrate the nonlinear TLD model to measured jump frequencies and damping.
///
/// Fits phi and eta of the power law Phi (Eq 2.13) so that the harmonic-balance jump frequency
/// of a slow upward sweep, as a fraction kappa of w_f (the tank's linear fundamental sloshing
/// frequency), follows the data, and the NSD damping law zeta = c Lambda^p to the damping data
/// (c, p are the FMU's nsd.c, nsd.p). Prints the fit and the residuals per sample.
///
/// Without --data: the NSD laws of docs/MODEL.md (kappa = 1.075 Lambda^0.007 below Lambda = 0.03,
/// 2.52 Lambda^0.25 above; zeta = 0.5 Lambda^0.35) at --points values of Lambda spaced
/// logarithmically over [--from, --to].
#[derive(Parser, Debug)]
#[command(name = "tld-calibrate", version, after_help = DATA_FORMAT)]
struct Args {
    /// the data set: a CSV file of Lambda,kappa,zeta samples (format below)
    #[arg(long, value_name = "FILE.csv")]
    data: Option<String>,
    /// tank length a along the motion [m]
    #[arg(long, default_value_t = 0.25)]
    length: f64,
    /// still-water depth h [m]
    #[arg(long, default_value_t = 0.021)]
    depth: f64,
    /// without --data: smallest Lambda
    #[arg(long, default_value_t = 0.005)]
    from: f64,
    /// without --data: largest Lambda
    #[arg(long, default_value_t = 0.1)]
    to: f64,
    /// without --data: number of samples (>= 2)
    #[arg(long, default_value_t = 12)]
    points: usize,
    /// write the samples with the fitted model as CSV to OUT (columns
    /// lambda,kappa_data,kappa_model,zeta_data,zeta_model; first line a `# phi=...,eta=...,
    /// nsd_c=...,nsd_p=...,omega_f=...,worst_kappa_residual=...` comment with the fit)
    #[arg(long, value_name = "OUT")]
    csv: Option<String>,
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
        breadth: 1.0,
        depth: o.depth,
        density: 1000.0,
        g: 9.81,
    };
    let samples: Vec<Sample> = match &o.data {
        Some(path) => read_samples(
            &std::fs::read_to_string(path).map_err(|e| format!("cannot read {path}: {e}"))?,
        )
        .map_err(|e| format!("{path}: {e}"))?,
        None => {
            let n = o.points.max(2);
            (0..n)
                .map(|k| {
                    let lambda = o.from * (o.to / o.from).powf(k as f64 / (n - 1) as f64);
                    Sample {
                        lambda,
                        kappa: nsd_kappa(lambda),
                        zeta: 0.5 * lambda.powf(0.35),
                    }
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
            "{},{},{},{},{}\n",
            s.lambda, s.kappa, model, s.zeta, zeta
        ));
    }
    let worst = fit
        .kappa_residuals
        .iter()
        .fold(0.0f64, |m, r| m.max(r.abs()));
    println!("\nlargest kappa residual {worst:.2e}");
    if let Some(path) = &o.csv {
        let text = format!(
            "# phi={},eta={},nsd_c={},nsd_p={},omega_f={wf},worst_kappa_residual={worst}\nlambda,kappa_data,kappa_model,zeta_data,zeta_model\n{rows}",
            fit.phi, fit.eta, fit.nsd_c, fit.nsd_p
        );
        std::fs::write(path, text).map_err(|e| format!("cannot write {path}: {e}"))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::read_samples;

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
