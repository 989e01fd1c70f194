//! Frequency response of the nonlinear TLD by harmonic balance, instantly: the peak and the
//! jump frequencies of slow up and down sweeps, the backbone, and every branch (stable or not)
//! over a frequency grid; or (--coupled) the linear response of the seed's Table 2.1 structure
//! with one tank. `tld-freqresp --help` lists the options.

use clap::Parser;
use tld_fmu::analysis::coupled::Coupled;
use tld_fmu::analysis::harmonic::HarmonicBalance;
use tld_fmu::physics::geometry::Tank;
use tld_fmu::physics::power::PowerLaw;

/// Frequency response of the nonlinear TLD (Eq 2.11 with the power law Phi of Eq 2.13) by
/// harmonic balance, in milliseconds.
///
/// Prints the peak (where a slow sweep up jumps down), the fold (where a slow sweep down jumps
/// up) and, at each of --points frequencies from --from to --to, the backbone amplitude and
/// every steady amplitude (* = unstable). Frequencies are given as w / w_f, where w_f is the
/// linear natural frequency of the tank's fundamental sloshing mode (from --length, --depth and
/// --g by Eqs 2.1/2.2; printed on the first line). Amplitudes X are of the sloshing coordinate
/// [m]; the tank is driven by a harmonic base motion of amplitude --A.
#[derive(Parser, Debug)]
#[command(name = "tld-freqresp", version, after_help = AFTER_HELP)]
struct Args {
    /// tank length a along the motion [m]
    #[arg(long, default_value_t = 0.25)]
    length: f64,
    /// still-water depth h [m]
    #[arg(long, default_value_t = 0.021)]
    depth: f64,
    /// gravity [m/s^2]
    #[arg(long, default_value_t = 9.81)]
    g: f64,
    /// hardening exponent eta of Phi (Eq 2.13), >= 1
    #[arg(long, default_value_t = 2.0)]
    eta: f64,
    /// hardening coefficient phi of Phi (Eq 2.13), >= 0
    #[arg(long, default_value_t = 1.0)]
    phi: f64,
    /// sloshing damping ratio zeta (> 0); with --coupled the damping of the sloshing mode
    #[arg(long, default_value_t = 0.02)]
    zeta: f64,
    /// base (excitation) displacement amplitude A [m]
    #[arg(long = "A", default_value_t = 0.003)]
    a: f64,
    /// first frequency of the grid and the plot, as w / w_f (w / w_s with --coupled)
    #[arg(long, default_value_t = 0.8)]
    from: f64,
    /// last frequency of the grid and the plot
    #[arg(long, default_value_t = 1.4)]
    to: f64,
    /// number of grid frequencies (>= 2)
    #[arg(long, default_value_t = 121)]
    points: usize,
    /// write the response curve (between --from and --to) as CSV to FILE; its first line is a
    /// `# key=value,...` comment with the parameters, w_f and the peak
    #[arg(long, value_name = "FILE")]
    csv: Option<String>,
    /// print JSON (omega_f, peak, fold, the branches on the grid) instead of the table
    #[arg(long)]
    json: bool,
    /// the linear response |X|/A_g of a structure with one tank (the options below), and
    /// without it, on the grid; JSON (and --csv: w_ratio,with,without)
    #[arg(long)]
    coupled: bool,
    /// --coupled: tank breadth [m]
    #[arg(long, default_value_t = 0.32)]
    breadth: f64,
    /// --coupled: modal mass of the structure [kg]
    #[arg(long = "M", default_value_t = 168.0)]
    m: f64,
    /// --coupled: damping ratio of the structure
    #[arg(long = "zeta_s", default_value_t = 0.0032)]
    zeta_s: f64,
    /// --coupled: natural frequency of the structure w_s [rad/s]
    #[arg(long = "w_s", default_value_t = 5.636)]
    w_s: f64,
    /// --coupled: S^2 mass exchange Omega in (0, 1]: the mode carries Omega m_1 at
    /// w_1 / sqrt(Omega)
    #[arg(long = "Omega", default_value_t = 1.0)]
    omega: f64,
    /// --coupled: impact mass m_2 / m_1 (left free: it does not act without impacts)
    #[arg(long = "mass_ratio", default_value_t = 0.01)]
    mass_ratio: f64,
}

const AFTER_HELP: &str = "\
Examples:
  tld-freqresp --eta 2 --phi 1 --zeta 0.02 --A 0.003 --from 0.9 --to 1.3
  tld-freqresp --coupled --Omega 0.9 --zeta 0.01 --from 0.85 --to 1.15 --points 301
scripts/freqresp runs this and plots out/freqresp.png (out/freqresp-coupled.png with --coupled).";

fn main() {
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("tld-freqresp: {e}");
        std::process::exit(2);
    }
}

fn grid(o: &Args) -> Vec<f64> {
    let n = o.points.max(2);
    (0..n)
        .map(|k| o.from + (o.to - o.from) * k as f64 / (n - 1) as f64)
        .collect()
}

fn write(path: &str, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write {path}: {e}"))
}

/// The linear structure + sloshing-mode response, as JSON (and CSV).
fn coupled_response(tank: &Tank, o: &Args) -> Result<(), String> {
    let omega = o.omega;
    if !(omega > 0.0 && omega <= 1.0) {
        return Err("--Omega must lie in (0, 1]".into());
    }
    let mode = tank.fundamental();
    let (m, ws) = (o.m, o.w_s);
    let impact = (o.mass_ratio + 1.0 - omega) * mode.mass;
    let structure = |mode_mass: f64, rigid: f64| Coupled {
        structure_mass: m,
        structure_damping: 2.0 * o.zeta_s * m * ws,
        structure_stiffness: m * ws * ws,
        rigid_mass: rigid,
        mode_mass,
        mode_omega: mode.omega / omega.sqrt(),
        mode_zeta: o.zeta,
    };
    // The liquid at rest moves with the structure; the free impact mass does not act.
    let with = structure(
        omega * mode.mass,
        tank.liquid_mass() - mode.mass - o.mass_ratio * mode.mass,
    );
    let bare = structure(0.0, 0.0);
    let rows: Vec<(f64, f64, f64)> = grid(o)
        .into_iter()
        .map(|r| (r, with.structure_gain(r * ws), bare.structure_gain(r * ws)))
        .collect();
    let json: Vec<String> = rows
        .iter()
        .map(|(r, a, b)| format!("[{r}, {a}, {b}]"))
        .collect();
    println!(
        "{{\"w_s\": {ws}, \"omega_mode\": {}, \"impact_mass\": {impact}, \"rows\": [{}]}}",
        mode.omega / omega.sqrt(),
        json.join(", ")
    );
    if let Some(path) = &o.csv {
        let mut text = format!(
            "# coupled=1,M={m},zeta_s={},w_s={ws},Omega={omega},zeta={},length={},depth={},breadth={},omega_mode={}\nw_ratio,with,without\n",
            o.zeta_s,
            o.zeta,
            o.length,
            o.depth,
            o.breadth,
            mode.omega / omega.sqrt()
        );
        for (r, a, b) in &rows {
            text.push_str(&format!("{r},{a},{b}\n"));
        }
        write(path, &text)?;
    }
    Ok(())
}

fn run(o: &Args) -> Result<(), String> {
    if !(o.eta >= 1.0 && o.phi >= 0.0 && o.zeta > 0.0 && o.a > 0.0 && o.length > o.depth) {
        return Err("need eta >= 1, phi >= 0, zeta > 0, A > 0 and length > depth".into());
    }
    if !(o.from > 0.0 && o.to >= o.from) {
        return Err("need 0 < --from <= --to".into());
    }
    let tank = Tank {
        length: o.length,
        breadth: o.breadth,
        depth: o.depth,
        density: 1000.0,
        g: o.g,
    };
    if o.coupled {
        return coupled_response(&tank, o);
    }
    let wf = tank.fundamental().omega;
    let hb = HarmonicBalance {
        law: PowerLaw::new(wf, o.phi, o.eta, o.length),
        damping: 2.0 * o.zeta * wf,
        base_amplitude: o.a,
    };
    // Amplitudes up to three tank lengths: beyond the walls, for detached branches.
    let x_max = 3.0 * o.length;
    let peak = hb.peak(x_max);
    let fold = hb.fold(x_max);
    let branches: Vec<(f64, Vec<_>)> = grid(o)
        .into_iter()
        .map(|r| (r, hb.amplitudes(r * wf, x_max)))
        .collect();
    if o.json {
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
        "harmonic balance of Eq 2.11: w_f = {wf:.5} rad/s (linear fundamental sloshing frequency of the tank), eta = {}, phi = {}, zeta = {}, A = {} m",
        o.eta, o.phi, o.zeta, o.a
    );
    match peak {
        Some(p) => println!(
            "peak: X = {:.5} m (2X/a = {:.3}) at w/w_f = {:.4}: a slow sweep up jumps down here",
            p.x,
            2.0 * p.x / o.length,
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
    if let Some(path) = &o.csv {
        let inside = |w: f64| (o.from..=o.to).contains(&(w / wf));
        let opt = |p: Option<tld_fmu::analysis::harmonic::Point>, name: &str| {
            p.map_or(String::new(), |p| {
                format!(",{name}_w={},{name}_x={}", p.w / wf, p.x)
            })
        };
        // stable: 1 stable, 0 unstable, 2 the backbone; only between --from and --to.
        let mut text = format!(
            "# omega_f={wf},eta={},phi={},zeta={},A={},length={},depth={},g={},from={},to={}{}{}\nw_ratio,x,stable\n",
            o.eta,
            o.phi,
            o.zeta,
            o.a,
            o.length,
            o.depth,
            o.g,
            o.from,
            o.to,
            opt(peak, "peak"),
            opt(fold, "fold"),
        );
        for p in hb.curve(x_max, 2000).into_iter().filter(|p| inside(p.w)) {
            text.push_str(&format!("{},{},{}\n", p.w / wf, p.x, u8::from(p.stable)));
        }
        for k in 1..=400 {
            let x = x_max / 3.0 * k as f64 / 400.0;
            let w = hb.backbone(x);
            if inside(w) {
                text.push_str(&format!("{},{x},2\n", w / wf));
            }
        }
        write(path, &text)?;
        println!("\nwrote the response curve to {path}");
    }
    Ok(())
}
