//! Preliminary design of tuned liquid dampers with damping screens for a structural mode, and
//! its check by co-simulation with the shallow-water model. `tld-design --help` documents it.

use std::fmt::Write as _;
use std::time::Instant;

use clap::Parser;
use tld_fmu::analysis::design::{Design, Limits, Structure, damper, design, response};

/// Design tuned liquid dampers (tanks and damping screens) for a structural mode under a
/// harmonic design force at resonance, and verify the design by co-simulation.
///
/// The design (after Tait 2008, with Warburton's optimum for a harmonic force): the effective
/// mass ratio mu = m_1/M from the water mass ratio and the depth ratio; the tank tuned to
/// 1/(1 + mu) of the structure's frequency at the design amplitude (the NSD hardening
/// kappa(Lambda) taken off the linear frequency), with the footprint limits; the screens
/// (--screens per tank, a pair at 0.4 a and 0.6 a) whose solidity gives Warburton's
/// zeta_opt = sqrt(3 mu/(8 (1 + mu))) at the design amplitude, over the boundary layers'.
/// docs/DESIGN.md explains each step.
///
/// The check: the structure (Newmark) carrying the designed tanks as model = ShallowWater with
/// the screens resolved, under the design force swept slowly over 0.75-1.25 of the structure's
/// frequency; against the bare structure (closed form); and the design's robustness: the
/// structure's frequency 10 % lower and higher, the force half and twice the design's. Writes
/// a one-page report (Markdown), the curves (CSV) and a plot (SVG) to --out.
#[derive(Parser, Debug)]
#[command(name = "tld-design", version)]
struct Args {
    /// modal mass of the structure's mode [kg]
    #[arg(long, default_value_t = 1.0e6)]
    mass: f64,
    /// its natural frequency [Hz]
    #[arg(long, default_value_t = 0.25)]
    frequency: f64,
    /// its damping ratio without dampers
    #[arg(long, default_value_t = 0.01)]
    damping: f64,
    /// amplitude of the harmonic design force at resonance [N] (wind: the modal force of the
    /// vortex shedding or the buffeting's resonant part)
    #[arg(long, default_value_t = 1.0e4)]
    force: f64,
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
    /// frequencies of each sweep
    #[arg(long, default_value_t = 21)]
    points: usize,
    /// periods run at each frequency (the last quarter measured)
    #[arg(long, default_value_t = 60)]
    periods: u32,
    /// where the report, the CSV and the SVG go
    #[arg(long, default_value = "out/design")]
    out: String,
}

/// A verification case: its name, the structure, and whether it carries the tanks.
struct Case {
    name: &'static str,
    structure: Structure,
}

fn main() {
    let o = Args::parse();
    if let Err(e) = run(&o) {
        eprintln!("tld-design: {e}");
        std::process::exit(1);
    }
}

fn run(o: &Args) -> Result<(), String> {
    let start = Instant::now();
    let s = Structure {
        mass: o.mass,
        frequency: o.frequency,
        damping: o.damping,
        force: o.force,
    };
    let l = Limits {
        mass_ratio: o.mass_ratio,
        length: o.max_length,
        breadth: o.max_breadth,
        depth_ratio: o.depth_ratio,
        screens: o.screens,
    };
    if o.points < 2 || o.periods < 8 || o.cells < 8 {
        return Err("at least 2 points, 8 periods and 8 cells".into());
    }
    let d = design(&s, &l)?;
    let designed = Instant::now() - start;
    let ratios: Vec<f64> = (0..o.points)
        .map(|k| 0.75 + 0.5 * k as f64 / (o.points - 1) as f64)
        .collect();
    // The design, the structure's frequency scaled by 0.9 and 1.1, the force by 0.5 and 2.
    let scaled = |frequency: f64, force: f64| Structure {
        frequency: frequency * s.frequency,
        force: force * s.force,
        ..s
    };
    let cases = [
        ("design", scaled(1.0, 1.0)),
        ("structure -10 %", scaled(0.9, 1.0)),
        ("structure +10 %", scaled(1.1, 1.0)),
        ("half the force", scaled(1.0, 0.5)),
        ("twice the force", scaled(1.0, 2.0)),
    ]
    .map(|(name, structure)| Case { name, structure });
    // Each case on its own thread (the machine's cores share them).
    let results: Vec<Result<Vec<f64>, String>> = std::thread::scope(|scope| {
        let handles: Vec<_> = cases
            .iter()
            .map(|c| {
                let ratios = &ratios;
                let d = &d;
                scope.spawn(move || {
                    // The case's frequencies are the nominal structure's ratios.
                    let own: Vec<f64> = ratios
                        .iter()
                        .map(|r| r * s.frequency / c.structure.frequency)
                        .collect();
                    response(&c.structure, Some(damper(d, o.cells)?), &own, o.periods, 64)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| Err("a case panicked".into())))
            .collect()
    });
    let mut curves = Vec::new();
    for (c, r) in cases.iter().zip(results) {
        curves.push((c, r.map_err(|e| format!("{}: {e}", c.name))?));
    }
    let elapsed = start.elapsed();
    std::fs::create_dir_all(&o.out).map_err(|e| format!("{}: {e}", o.out))?;
    let write = |name: &str, text: String| {
        let path = format!("{}/{name}", o.out);
        std::fs::write(&path, text).map_err(|e| format!("{path}: {e}"))
    };
    write("response.csv", csv(&s, &ratios, &curves))?;
    write("response.svg", svg(&s, &ratios, &curves))?;
    let report = report(o, &s, &d, &ratios, &curves, designed, elapsed);
    write("report.md", report.clone())?;
    print!("{report}");
    Ok(())
}

/// |X| of the bare structure under the force at `ratio` of its frequency (closed form).
fn bare(s: &Structure, ratio: f64) -> f64 {
    s.force
        / s.stiffness()
        / ((1.0 - ratio * ratio).powi(2) + (2.0 * s.damping * ratio).powi(2)).sqrt()
}

fn csv(s: &Structure, ratios: &[f64], curves: &[(&Case, Vec<f64>)]) -> String {
    let mut out = String::from("ratio,bare");
    for (c, _) in curves {
        let _ = write!(out, ",{}", c.name);
    }
    out.push('\n');
    for (k, r) in ratios.iter().enumerate() {
        let _ = write!(out, "{r},{}", bare(s, *r));
        for (_, x) in curves {
            let _ = write!(out, ",{}", x[k]);
        }
        out.push('\n');
    }
    out
}

/// The curves as an SVG plot: amplitude over the design force's static deflection, against the
/// nominal frequency ratio.
fn svg(s: &Structure, ratios: &[f64], curves: &[(&Case, Vec<f64>)]) -> String {
    let (w, h, pad) = (640.0, 400.0, 50.0);
    let static_x = s.force / s.stiffness();
    let bare: Vec<f64> = ratios.iter().map(|r| bare(s, *r)).collect();
    // The dampers' curves fill the plot; the bare structure's resonance runs off its top.
    let top = 1.3
        * curves
            .iter()
            .flat_map(|(c, x)| {
                x.iter()
                    .map(move |v| v / (static_x * c.structure.force / s.force))
            })
            .fold(0.0f64, f64::max);
    let (r0, r1) = (ratios[0], ratios[ratios.len() - 1]);
    let px = |r: f64| pad + (r - r0) / (r1 - r0) * (w - 2.0 * pad);
    let py = |y: f64| h - pad - (y / top).min(1.0) * (h - 2.0 * pad);
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n\
         <text x=\"{pad}\" y=\"20\">structure amplitude / (force / stiffness) against frequency / structure frequency</text>\n\
         <line x1=\"{pad}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/>\n\
         <line x1=\"{pad}\" y1=\"{pad}\" x2=\"{pad}\" y2=\"{}\" stroke=\"black\"/>\n",
        h - pad,
        w - pad,
        h - pad,
        h - pad
    );
    for k in 0..=4 {
        let r = r0 + (r1 - r0) * f64::from(k) / 4.0;
        let y = top * f64::from(k) / 4.0;
        let _ = writeln!(
            out,
            "<text x=\"{:.1}\" y=\"{:.1}\">{r:.2}</text><text x=\"5\" y=\"{:.1}\">{y:.1}</text>",
            px(r) - 10.0,
            h - pad + 18.0,
            py(y) + 4.0
        );
    }
    let colours = [
        "black", "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#d62728",
    ];
    let mut series: Vec<(&str, Vec<f64>)> =
        vec![("bare", bare.iter().map(|x| x / static_x).collect())];
    for (c, x) in curves {
        let scale = static_x * c.structure.force / s.force;
        series.push((c.name, x.iter().map(|v| v / scale).collect()));
    }
    for (i, (name, y)) in series.iter().enumerate() {
        let points: Vec<String> = ratios
            .iter()
            .zip(y)
            .map(|(r, v)| format!("{:.1},{:.1}", px(*r), py(*v)))
            .collect();
        let colour = colours[i % colours.len()];
        let _ = writeln!(
            out,
            "<polyline fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.5\" points=\"{}\"/>\n\
             <text x=\"{:.1}\" y=\"{:.1}\" fill=\"{colour}\">{name}</text>",
            points.join(" "),
            w - pad - 120.0,
            pad + 14.0 * i as f64
        );
    }
    out.push_str("</svg>\n");
    out
}

fn report(
    o: &Args,
    s: &Structure,
    d: &Design,
    ratios: &[f64],
    curves: &[(&Case, Vec<f64>)],
    designed: std::time::Duration,
    elapsed: std::time::Duration,
) -> String {
    let t = &d.tank;
    let static_x = s.force / s.stiffness();
    let bare_peak = ratios.iter().map(|r| bare(s, *r)).fold(0.0, f64::max);
    let mut out = String::new();
    let _ = writeln!(out, "# TLD design report\n");
    let _ = writeln!(
        out,
        "Structure: modal mass {:.4e} kg, {} Hz, damping {}; harmonic design force {:.4e} N at \
         resonance (static deflection {:.4e} m, bare resonant amplitude {:.4e} m). Limits: water \
         mass ratio {}, tanks at most {} m long and {} m wide, depth ratio {} preferred, {} \
         screens per tank.\n",
        s.mass,
        s.frequency,
        s.damping,
        s.force,
        static_x,
        s.force / (2.0 * s.damping * s.stiffness()),
        o.mass_ratio,
        o.max_length,
        o.max_breadth,
        o.depth_ratio,
        o.screens
    );
    let _ = writeln!(out, "## Design\n");
    let _ = writeln!(out, "| quantity | value |\n|---|---|");
    let rows = [
        ("tanks", format!("{}", d.tanks)),
        ("tank.length a", format!("{:.3} m", t.length)),
        ("tank.breadth b", format!("{:.3} m", t.breadth)),
        (
            "tank.depth h",
            format!("{:.3} m (h/a = {:.3})", t.depth, t.depth_ratio()),
        ),
        (
            "water, all tanks",
            format!("{:.4e} kg", t.liquid_mass() * f64::from(d.tanks)),
        ),
        ("effective mass ratio mu = m_1/M", format!("{:.4}", d.mu)),
        (
            "tank frequency (linear, Eq 2.2)",
            format!(
                "{:.4} Hz",
                t.fundamental().omega / (2.0 * std::f64::consts::PI)
            ),
        ),
        (
            "tuning ratio 1/(1 + mu), hardening kappa",
            format!("{:.4}, {:.4}", d.gamma, d.kappa),
        ),
        (
            "design amplitude A_e (Lambda)",
            format!("{:.4e} m ({:.4})", d.amplitude, d.amplitude / t.length),
        ),
        (
            "zeta_opt, boundary layers' zeta",
            format!("{:.4}, {:.4}", d.zeta_opt, d.zeta_bl),
        ),
        (
            "screens.count, screens.spacing",
            format!("{}, {:.3} m", d.screens.count, d.screens.spacing),
        ),
        (
            "screens.solidity (C_l)",
            format!("{:.3} ({:.2})", d.screens.solidity, d.loss),
        ),
    ];
    for (q, v) in rows {
        let _ = writeln!(out, "| {q} | {v} |");
    }
    let predicted = static_x * (1.0 + 2.0 / d.mu).sqrt();
    let _ = writeln!(
        out,
        "\nTLD.fmu parameters: model = ShallowWater (or a mechanical model with damping = \
         Screens), tank.length = {:.4}, tank.breadth = {:.4}, tank.depth = {:.4}, tanks = {}, \
         screens.count = {}, screens.solidity = {:.4}, screens.spacing = {:.4}.\n",
        t.length,
        t.breadth,
        t.depth,
        d.tanks,
        d.screens.count,
        d.screens.solidity,
        d.screens.spacing
    );
    let _ = writeln!(out, "## Verification by co-simulation\n");
    let _ = writeln!(
        out,
        "The structure carrying the tanks as model = ShallowWater ({} cells, screens resolved), \
         slow sweep over {} frequencies, {} periods each; peaks of the steady amplitude. \
         Predicted by the design (Den Hartog): {:.4e} m at the design force.\n",
        o.cells, o.points, o.periods, predicted
    );
    let _ = writeln!(
        out,
        "| case | peak amplitude [m] | per unit force, over the bare structure's | at frequency ratio |\n|---|---|---|---|"
    );
    for (c, x) in curves {
        let (k, peak) = x
            .iter()
            .enumerate()
            .fold((0, 0.0f64), |b, (k, v)| if *v > b.1 { (k, *v) } else { b });
        let per_force = peak / (c.structure.force / s.force);
        let _ = writeln!(
            out,
            "| {} | {peak:.4e} | {:.3} | {:.3} |",
            c.name,
            per_force / bare_peak,
            ratios[k]
        );
    }
    let _ = writeln!(
        out,
        "\n![response](response.svg)\n\nThe design took {:.3} s, the whole run {:.1} s of wall \
         time ({} threads on this machine's cores).",
        designed.as_secs_f64(),
        elapsed.as_secs_f64(),
        curves.len()
    );
    out
}
