//! Fit phi and eta of Eq 2.13 and the damping law zeta = c Lambda^p so that the model's
//! harmonic-balance jump frequency and damping follow a kappa(Lambda), zeta(Lambda) data set;
//! print the fit and its residuals.
//!
//! tld-calibrate [--data FILE.csv (lambda,kappa,zeta per line)] [--length 0.25] [--depth 0.021]
//!               [--from 0.005] [--to 0.1] [--points 12] [--csv OUT]
//! Without --data: the NSD laws of MODEL.md (kappa = 1.075 L^0.007 below 0.03, 2.52 L^0.25 above;
//! zeta = 0.5 L^0.35) at `points` values of Lambda spaced logarithmically over [from, to].

use tld_fmu::analysis::calibration::{Sample, calibrate, kappa_model};
use tld_fmu::physics::geometry::Tank;
use tld_fmu::physics::laws::nsd_kappa;

fn main() {
    if let Err(e) = run() {
        eprintln!("tld-calibrate: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt = |key: &str| {
        args.iter()
            .position(|a| a == key)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let num = |key: &str, default: f64| -> Result<f64, String> {
        opt(key).map_or(Ok(default), |v| {
            v.parse()
                .map_err(|_| format!("{key}: '{v}' is not a number"))
        })
    };
    let tank = Tank {
        length: num("--length", 0.25)?,
        breadth: 1.0,
        depth: num("--depth", 0.021)?,
        density: 1000.0,
        g: 9.81,
    };
    let samples: Vec<Sample> = match opt("--data") {
        Some(path) => {
            let text =
                std::fs::read_to_string(&path).map_err(|e| format!("cannot read {path}: {e}"))?;
            text.lines()
                .filter(|l| !l.trim().is_empty() && !l.starts_with('#') && !l.starts_with("lambda"))
                .map(|l| {
                    let v: Vec<f64> = l
                        .split(',')
                        .map(|x| x.trim().parse::<f64>())
                        .collect::<Result<_, _>>()
                        .map_err(|_| format!("bad line '{l}'"))?;
                    match v.as_slice() {
                        [lambda, kappa, zeta] => Ok(Sample {
                            lambda: *lambda,
                            kappa: *kappa,
                            zeta: *zeta,
                        }),
                        _ => Err(format!("line '{l}' needs lambda,kappa,zeta")),
                    }
                })
                .collect::<Result<_, _>>()?
        }
        None => {
            let (from, to, n) = (
                num("--from", 0.005)?,
                num("--to", 0.1)?,
                num("--points", 12.0)? as usize,
            );
            (0..n.max(2))
                .map(|k| {
                    let lambda = from * (to / from).powf(k as f64 / (n.max(2) - 1) as f64);
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
        return Err("need at least two samples with positive lambda, kappa and zeta".into());
    }
    let wf = tank.fundamental().omega;
    let fit = calibrate(wf, tank.length, &samples);
    println!(
        "fit: phi = {:.5}, eta = {:.5}, nsd.c = {:.5}, nsd.p = {:.5}  (omega_f = {wf:.5} rad/s)",
        fit.phi, fit.eta, fit.nsd_c, fit.nsd_p
    );
    println!("\n  Lambda     kappa data  kappa model  residual    zeta data  residual");
    let mut csv = String::from("lambda,kappa_data,kappa_model,zeta_data,zeta_model\n");
    for (k, s) in samples.iter().enumerate() {
        let zeta = fit.nsd_c * s.lambda.powf(fit.nsd_p);
        let model =
            kappa_model(wf, tank.length, fit.phi, fit.eta, s.lambda, zeta).unwrap_or(f64::NAN);
        println!(
            "  {:8.5}   {:10.5}   {:10.5}   {:+8.2e}   {:9.5}   {:+8.2e}",
            s.lambda, s.kappa, model, fit.kappa_residuals[k], s.zeta, fit.zeta_residuals[k]
        );
        csv.push_str(&format!(
            "{},{},{},{},{}\n",
            s.lambda, s.kappa, model, s.zeta, zeta
        ));
    }
    let worst = fit
        .kappa_residuals
        .iter()
        .fold(0.0f64, |m, r| m.max(r.abs()));
    println!("\nlargest kappa residual {worst:.2e}");
    if let Some(path) = opt("--csv") {
        std::fs::write(&path, csv).map_err(|e| format!("cannot write {path}: {e}"))?;
    }
    Ok(())
}
