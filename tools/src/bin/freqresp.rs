//! Frequency response of the nonlinear TLD by harmonic balance, instantly: the peak and the
//! jump frequencies of slow up and down sweeps, the backbone, and every branch (stable or not)
//! over a frequency grid. Uses the geometry of Eqs 2.1/2.2 for omega_f.
//!
//! tld-freqresp [--length 0.25] [--depth 0.021] [--g 9.81] [--eta 2] [--phi 1] [--zeta 0.02]
//!              [--A 0.003] [--from 0.8] [--to 1.4] [--points 121] [--csv FILE] [--json]
//!
//! With --coupled: the linear response |X|/A_g of a structure (--M 168 --zeta_s 0.0032
//! --w_s 5.636, seed Table 2.1) with one tank (--breadth 0.32) whose fundamental mode carries
//! --Omega of m_1 at omega_1/sqrt(Omega) (S^2 without its impacts; the impact mass
//! --mass_ratio m_1 + (1 - Omega) m_1 left free), and without the tank; frequencies as
//! fractions of w_s. JSON.

use tld_fmu::analysis::coupled::Coupled;
use tld_fmu::analysis::harmonic::HarmonicBalance;
use tld_fmu::physics::geometry::Tank;
use tld_fmu::physics::power::PowerLaw;

fn main() {
    if let Err(e) = run() {
        eprintln!("tld-freqresp: {e}");
        std::process::exit(2);
    }
}

/// The linear structure + sloshing-mode response, as JSON.
fn coupled_response(tank: &Tank, o: &dyn Fn(&str) -> f64) -> Result<(), String> {
    let omega = o("Omega");
    if !(omega > 0.0 && omega <= 1.0) {
        return Err("--Omega must lie in (0, 1]".into());
    }
    let mode = tank.fundamental();
    let (m, ws) = (o("M"), o("w_s"));
    let impact = (o("mass_ratio") + 1.0 - omega) * mode.mass;
    let structure = |mode_mass: f64, rigid: f64| Coupled {
        structure_mass: m,
        structure_damping: 2.0 * o("zeta_s") * m * ws,
        structure_stiffness: m * ws * ws,
        rigid_mass: rigid,
        mode_mass,
        mode_omega: mode.omega / omega.sqrt(),
        mode_zeta: o("zeta"),
    };
    // The liquid at rest moves with the structure; the free impact mass does not act.
    let with = structure(
        omega * mode.mass,
        tank.liquid_mass() - mode.mass - o("mass_ratio") * mode.mass,
    );
    let bare = structure(0.0, 0.0);
    let n = o("points").max(2.0) as usize;
    let rows: Vec<String> = (0..n)
        .map(|k| {
            let r = o("from") + (o("to") - o("from")) * k as f64 / (n - 1) as f64;
            format!(
                "[{r}, {}, {}]",
                with.structure_gain(r * ws),
                bare.structure_gain(r * ws)
            )
        })
        .collect();
    println!(
        "{{\"w_s\": {ws}, \"omega_mode\": {}, \"impact_mass\": {impact}, \"rows\": [{}]}}",
        mode.omega / omega.sqrt(),
        rows.join(", ")
    );
    Ok(())
}

fn run() -> Result<(), String> {
    let mut opt = std::collections::BTreeMap::from([
        ("length", 0.25),
        ("depth", 0.021),
        ("g", 9.81),
        ("eta", 2.0),
        ("phi", 1.0),
        ("zeta", 0.02),
        ("A", 0.003),
        ("from", 0.8),
        ("to", 1.4),
        ("points", 121.0),
        ("breadth", 0.32),
        ("M", 168.0),
        ("zeta_s", 0.0032),
        ("w_s", 5.636),
        ("Omega", 1.0),
        ("mass_ratio", 0.01),
    ]);
    let (mut csv, mut json, mut coupled) = (None, false, false);
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        let key = args[i].trim_start_matches("--");
        match key {
            "json" => json = true,
            "coupled" => coupled = true,
            "csv" => {
                csv = Some(args.get(i + 1).ok_or("--csv needs a file")?.clone());
                i += 1;
            }
            _ => {
                let slot = opt
                    .get_mut(key)
                    .ok_or_else(|| format!("unknown option --{key}"))?;
                let value = args
                    .get(i + 1)
                    .ok_or_else(|| format!("--{key} needs a value"))?;
                *slot = value
                    .parse()
                    .map_err(|_| format!("--{key}: '{value}' is not a number"))?;
                i += 1;
            }
        }
        i += 1;
    }
    let o = |k: &str| opt[k];
    let o: &dyn Fn(&str) -> f64 = &o;
    if !(o("eta") >= 1.0
        && o("phi") >= 0.0
        && o("zeta") > 0.0
        && o("A") > 0.0
        && o("length") > o("depth"))
    {
        return Err("need eta >= 1, phi >= 0, zeta > 0, A > 0 and length > depth".into());
    }
    let tank = Tank {
        length: o("length"),
        breadth: o("breadth"),
        depth: o("depth"),
        density: 1000.0,
        g: o("g"),
    };
    if coupled {
        return coupled_response(&tank, o);
    }
    let wf = tank.fundamental().omega;
    let hb = HarmonicBalance {
        law: PowerLaw::new(wf, o("phi"), o("eta"), o("length")),
        damping: 2.0 * o("zeta") * wf,
        base_amplitude: o("A"),
    };
    // Amplitudes up to three tank lengths: beyond the walls, for detached branches.
    let x_max = 3.0 * o("length");
    let peak = hb.peak(x_max);
    let fold = hb.fold(x_max);
    let n = o("points").max(2.0) as usize;
    let grid: Vec<f64> = (0..n)
        .map(|k| o("from") + (o("to") - o("from")) * k as f64 / (n - 1) as f64)
        .collect();
    let branches: Vec<(f64, Vec<_>)> = grid
        .iter()
        .map(|&r| (r, hb.amplitudes(r * wf, x_max)))
        .collect();
    if json {
        let pt = |p: Option<tld_fmu::analysis::harmonic::Point>| {
            p.map_or("null".to_string(), |p| {
                format!("{{\"w_ratio\": {}, \"x\": {}}}", p.w / wf, p.x)
            })
        };
        let rows: Vec<String> = branches
            .iter()
            .map(|(r, xs)| {
                let xs: Vec<String> = xs
                    .iter()
                    .map(|p| format!("[{}, {}]", p.x, p.stable))
                    .collect();
                format!("[{r}, [{}]]", xs.join(", "))
            })
            .collect();
        println!(
            "{{\"omega_f\": {wf}, \"peak\": {}, \"fold\": {}, \"branches\": [{}]}}",
            pt(peak),
            pt(fold),
            rows.join(", ")
        );
        return Ok(());
    }
    println!(
        "harmonic balance of Eq 2.11: omega_f = {wf:.5} rad/s, eta = {}, phi = {}, zeta = {}, A = {} m",
        o("eta"),
        o("phi"),
        o("zeta"),
        o("A")
    );
    match peak {
        Some(p) => println!(
            "peak: X = {:.5} m (2X/a = {:.3}) at w/w_f = {:.4}: a slow sweep up jumps down here",
            p.x,
            2.0 * p.x / o("length"),
            p.w / wf
        ),
        None => println!("peak: none below {x_max} m"),
    }
    match fold {
        Some(f) => println!(
            "fold: X = {:.5} m at w/w_f = {:.4}: a slow sweep down jumps up here",
            f.x,
            f.w / wf
        ),
        None => println!("fold: none (single-valued response, no jumps)"),
    }
    println!("\n  w/w_f   backbone X at this w   amplitudes X [m] (* = unstable)");
    for (r, xs) in &branches {
        let list: Vec<String> = xs
            .iter()
            .map(|p| format!("{:.5}{}", p.x, if p.stable { "" } else { "*" }))
            .collect();
        // The amplitude whose free frequency is w, on the backbone (if within reach).
        let bb = (0..=2000)
            .map(|k| x_max * k as f64 / 2000.0)
            .find(|&x| hb.backbone(x) >= r * wf)
            .map_or("-".to_string(), |x| format!("{x:.5}"));
        println!("  {r:6.3}  {bb:>20}   {}", list.join("  "));
    }
    if let Some(path) = csv {
        // stable: 1 stable, 0 unstable, 2 the backbone.
        let mut text = String::from("w_ratio,x,stable\n");
        for p in hb.curve(x_max, 2000) {
            text.push_str(&format!("{},{},{}\n", p.w / wf, p.x, u8::from(p.stable)));
        }
        for k in 1..=400 {
            let x = x_max / 3.0 * k as f64 / 400.0;
            text.push_str(&format!("{},{x},2\n", hb.backbone(x) / wf));
        }
        std::fs::write(&path, text).map_err(|e| format!("cannot write {path}: {e}"))?;
        println!("\nwrote the response curve to {path}");
    }
    Ok(())
}
