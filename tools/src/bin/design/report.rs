//! tld-design's outputs: the one-page report (report.md), the curves (response.csv) and the
//! plot (response.svg).

use std::fmt::Write as _;
use std::time::Duration;

use tld_fmu::analysis::design::{Excitation, Structure};
use tld_fmu::physics::screens::RANDOM_SCREENS;

use crate::{Args, Case, Check, Designed};

/// |X| of the bare structure under the force at `ratio` of its frequency (closed form).
fn bare(s: &Structure, ratio: f64) -> f64 {
    s.force
        / s.stiffness()
        / ((1.0 - ratio * ratio).powi(2) + (2.0 * s.damping * ratio).powi(2)).sqrt()
}

/// A finished run: the options, the design, the check and the times.
pub struct Run<'a> {
    pub o: &'a Args,
    pub d: &'a Designed,
    pub cases: &'a [Case],
    pub check: &'a Check,
    pub designed: Duration,
    pub elapsed: Duration,
}

pub fn write(r: &Run) -> Result<(), String> {
    let (o, d, cases, check) = (r.o, r.d, r.cases, r.check);
    std::fs::create_dir_all(&o.out).map_err(|e| format!("{}: {e}", o.out))?;
    let write = |name: &str, text: String| {
        let path = format!("{}/{name}", o.out);
        std::fs::write(&path, text).map_err(|e| format!("{path}: {e}"))
    };
    let (csv, svg) = match check {
        Check::Sweep { ratios, curves } => sweep_outputs(&d.sim, cases, ratios, curves),
        Check::Histories { h, bare, with, .. } => history_outputs(*h, bare, with),
    };
    write("response.csv", csv)?;
    write("response.svg", svg)?;
    let text = report(r);
    write("report.md", text.clone())?;
    print!("{text}");
    Ok(())
}

fn sweep_outputs(
    s: &Structure,
    cases: &[Case],
    ratios: &[f64],
    curves: &[Vec<f64>],
) -> (String, String) {
    let mut csv = String::from("ratio,bare");
    for c in cases {
        let _ = write!(csv, ",{}", c.name);
    }
    csv.push('\n');
    for (k, r) in ratios.iter().enumerate() {
        let _ = write!(csv, "{r},{}", bare(s, *r));
        for x in curves {
            let _ = write!(csv, ",{}", x[k]);
        }
        csv.push('\n');
    }
    // Amplitude over the case's static deflection; the dampers' curves fill the plot, the
    // bare structure's resonance runs off its top.
    let static_x = s.force / s.stiffness();
    let mut series = vec![(
        "bare",
        ratios
            .iter()
            .map(|r| bare(s, *r) / static_x)
            .collect::<Vec<_>>(),
    )];
    for (c, x) in cases.iter().zip(curves) {
        series.push((c.name, x.iter().map(|v| v / (static_x * c.scale)).collect()));
    }
    let top = 1.3
        * series[1..]
            .iter()
            .flat_map(|(_, y)| y.iter().copied())
            .fold(0.0f64, f64::max);
    let svg = plot(
        "structure amplitude / (force / stiffness) against frequency / structure frequency",
        ratios,
        &series,
        (0.0, top),
    );
    (csv, svg)
}

fn history_outputs(h: f64, bare: &[f64], with: &[f64]) -> (String, String) {
    // At most about 4000 rows.
    let every = (bare.len() / 4000).max(1);
    let mut csv = String::from("t,bare,design\n");
    let (mut t, mut xb, mut xw) = (Vec::new(), Vec::new(), Vec::new());
    for k in (0..bare.len()).step_by(every) {
        let _ = writeln!(csv, "{},{},{}", k as f64 * h, bare[k], with[k]);
        t.push(k as f64 * h);
        xb.push(bare[k]);
        xw.push(with[k]);
    }
    let top = xb.iter().fold(0.0f64, |m, v| m.max(v.abs())) * 1.1;
    let svg = plot(
        "structure displacement [m] against time [s]",
        &t,
        &[("bare", xb), ("with the tanks", xw)],
        (-top, top),
    );
    (csv, svg)
}

/// Lines of `series` over `x` as an SVG plot, y clipped to `range`.
fn plot(title: &str, x: &[f64], series: &[(&str, Vec<f64>)], range: (f64, f64)) -> String {
    let (w, h, pad) = (640.0, 400.0, 50.0);
    let (x0, x1) = (x[0], x[x.len() - 1]);
    let (y0, y1) = range;
    let px = |r: f64| pad + (r - x0) / (x1 - x0) * (w - 2.0 * pad);
    let py = |y: f64| h - pad - ((y - y0) / (y1 - y0)).clamp(0.0, 1.0) * (h - 2.0 * pad);
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n\
         <text x=\"{pad}\" y=\"20\">{title}</text>\n\
         <line x1=\"{pad}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/>\n\
         <line x1=\"{pad}\" y1=\"{pad}\" x2=\"{pad}\" y2=\"{}\" stroke=\"black\"/>\n",
        h - pad,
        w - pad,
        h - pad,
        h - pad
    );
    for k in 0..=4 {
        let r = x0 + (x1 - x0) * f64::from(k) / 4.0;
        let y = y0 + (y1 - y0) * f64::from(k) / 4.0;
        let _ = writeln!(
            out,
            "<text x=\"{:.1}\" y=\"{:.1}\">{r:.3}</text><text x=\"2\" y=\"{:.1}\">{y:.3}</text>",
            px(r) - 10.0,
            h - pad + 18.0,
            py(y) + 4.0
        );
    }
    let colours = [
        "black", "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#d62728",
    ];
    for (i, (name, y)) in series.iter().enumerate() {
        let points: Vec<String> = x
            .iter()
            .zip(y)
            .map(|(r, v)| format!("{:.1},{:.1}", px(*r), py(*v)))
            .collect();
        let colour = colours[i % colours.len()];
        let _ = writeln!(
            out,
            "<polyline fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.2\" points=\"{}\"/>\n\
             <text x=\"{:.1}\" y=\"{:.1}\" fill=\"{colour}\">{name}</text>",
            points.join(" "),
            w - pad - 140.0,
            pad + 14.0 * i as f64
        );
    }
    out.push_str("</svg>\n");
    out
}

fn excitation_text(o: &Args, d: &Designed) -> String {
    let s = &d.s;
    match &d.excitation {
        Excitation::Harmonic => format!(
            "harmonic design force {:.4e} N at resonance (static deflection {:.4e} m, bare \
             resonant amplitude {:.4e} m)",
            s.force,
            s.force / s.stiffness(),
            s.force / (2.0 * s.damping * s.stiffness())
        ),
        Excitation::Wind { s0 } => format!(
            "wind: the bare structure's rms acceleration {} m/s^2 at the damper floor, i.e. a \
             white-noise modal force of two-sided density {s0:.4e} N^2 s/rad (rms displacement \
             {:.4e} m); Warburton's white-noise optimum and the random Screens law \
             (zeta_s = 1.880 K sigma)",
            o.wind_rms_accel.unwrap_or(f64::NAN),
            o.wind_rms_accel.unwrap_or(f64::NAN) / (s.omega() * s.omega())
        ),
        Excitation::Record {
            step,
            accel,
            participation,
        } => format!(
            "ground-motion record {} ({} samples every {step} s, peak {:.4} m/s^2; \
             participation factor {participation:.4e} kg); Warburton's harmonic-ground optimum, \
             the Screens law at the linear tuned mass's peak excursion",
            o.record.as_deref().unwrap_or("?"),
            accel.len(),
            accel.iter().fold(0.0f64, |m, v| m.max(v.abs()))
        ),
    }
}

fn report(r: &Run) -> String {
    let (o, d, cases, check, designed, elapsed) =
        (r.o, r.d, r.cases, r.check, r.designed, r.elapsed);
    let (s, g) = (&d.s, &d.design);
    let t = &g.tank;
    let mut out = String::new();
    let _ = writeln!(out, "# TLD design report\n");
    let _ = writeln!(
        out,
        "Structure: {}; modal mass {:.4e} kg (shape 1 at the damper floor), {:.5} Hz, damping \
         {:.4}. Excitation: {}. Limits: water mass ratio {}, tanks at most {} m long and {} m \
         wide, depth ratio {} preferred, {} screens per tank.\n",
        d.source,
        s.mass,
        s.frequency,
        s.damping,
        excitation_text(o, d),
        o.mass_ratio,
        o.max_length,
        o.max_breadth,
        o.depth_ratio,
        o.screens
    );
    let _ = writeln!(out, "## Design\n");
    let _ = writeln!(out, "| quantity | value |\n|---|---|");
    let hz = |w: f64| w / (2.0 * std::f64::consts::PI);
    let rows = [
        ("tanks", format!("{}", g.tanks)),
        ("tank.length a", format!("{:.3} m", t.length)),
        ("tank.breadth b", format!("{:.3} m", t.breadth)),
        (
            "tank.depth h",
            format!("{:.3} m (h/a = {:.3})", t.depth, t.depth_ratio()),
        ),
        (
            "water, all tanks",
            format!("{:.4e} kg", t.liquid_mass() * f64::from(g.tanks)),
        ),
        ("effective mass ratio mu = m_1/M", format!("{:.4}", g.mu)),
        (
            "tank frequency (linear, Eq 2.2)",
            format!("{:.4} Hz", hz(t.fundamental().omega)),
        ),
        (
            "Warburton's tuning ratio, hardening kappa",
            format!("{:.4}, {:.4}", g.gamma, g.kappa),
        ),
        (
            "tuned mass's response X (zeta_s = K X)",
            format!("{:.4e} m", g.sloshing),
        ),
        (
            "equivalent base amplitude A_e (Lambda)",
            format!("{:.4e} m ({:.4})", g.amplitude, g.amplitude / t.length),
        ),
        (
            "zeta_opt, boundary layers' zeta",
            format!("{:.4}, {:.4}", g.zeta_opt, g.zeta_bl),
        ),
        (
            "screens.count, screens.spacing",
            format!("{}, {:.3} m", g.screens.count, g.screens.spacing),
        ),
        (
            "screens.solidity (C_l)",
            format!("{:.3} ({:.2})", g.screens.solidity, g.loss),
        ),
    ];
    for (q, v) in rows {
        let _ = writeln!(out, "| {q} | {v} |");
    }
    // The mechanical models' law: for wind its random form at the tuned mass's rms (MODEL.md
    // 11), otherwise the resonant form at the equivalent base amplitude.
    let mechanical = match &d.excitation {
        Excitation::Wind { .. } => format!(
            "screens.response = Random, amplitude = Fixed, A_e = sigma_X = {:.4e}",
            g.sloshing / RANDOM_SCREENS
        ),
        _ => format!("amplitude = Fixed, A_e = {:.4e}", g.amplitude),
    };
    let _ = writeln!(
        out,
        "\nTLD.fmu parameters: model = ShallowWater (or a mechanical model with damping = \
         Screens, {mechanical}), tank.length = {:.4}, tank.breadth = {:.4}, \
         tank.depth = {:.4}, tanks = {}, screens.count = {}, screens.solidity = {:.4}, \
         screens.spacing = {:.4}.\n",
        t.length,
        t.breadth,
        t.depth,
        g.tanks,
        g.screens.count,
        g.screens.solidity,
        g.screens.spacing
    );
    let _ = writeln!(out, "## Verification by co-simulation\n");
    match check {
        Check::Sweep { ratios, curves } => {
            let bare_peak = ratios.iter().map(|r| bare(&d.sim, *r)).fold(0.0, f64::max);
            let _ = writeln!(
                out,
                "The structure carrying the tanks as model = ShallowWater ({} cells, screens \
                 resolved), slow sweep over {} frequencies, {} periods each; peaks of the \
                 steady amplitude. Predicted by the design (Den Hartog): {:.4e} m at the design \
                 force.\n",
                o.cells, o.points, o.periods, g.predicted
            );
            let _ = writeln!(
                out,
                "| case | peak amplitude [m] | per unit force, over the bare structure's | at frequency ratio |\n|---|---|---|---|"
            );
            for (c, x) in cases.iter().zip(curves) {
                let (k, peak) = x
                    .iter()
                    .enumerate()
                    .fold((0, 0.0f64), |b, (k, v)| if *v > b.1 { (k, *v) } else { b });
                let _ = writeln!(
                    out,
                    "| {} | {peak:.4e} | {:.3} | {:.3} |",
                    c.name,
                    peak / c.scale / bare_peak,
                    ratios[k]
                );
            }
        }
        Check::Histories { h, rows, .. } => {
            let (what, pred) = match d.excitation {
                Excitation::Wind { .. } => (
                    format!(
                        "one realisation (seed {}) of the white-noise force, band-limited to \
                         0.3-3 times the structure's frequency, {} s (the first eighth not \
                         measured)",
                        o.seed, o.duration
                    ),
                    format!("rms {:.4e} m", g.predicted),
                ),
                _ => (
                    "the record".to_string(),
                    format!("peak {:.4e} m", g.predicted),
                ),
            };
            let _ = writeln!(
                out,
                "The structure carrying the tanks as model = ShallowWater ({} cells, screens \
                 resolved) and the bare structure under {what}, step {h:.4} s. Predicted with \
                 the optimal linear damper: {pred}.\n",
                o.cells
            );
            let _ = writeln!(
                out,
                "| case | rms [m] with / bare | ratio | peak [m] with / bare | ratio |\n|---|---|---|---|---|"
            );
            for (c, row) in cases.iter().zip(rows) {
                let _ = writeln!(
                    out,
                    "| {} | {:.4e} / {:.4e} | {:.3} | {:.4e} / {:.4e} | {:.3} |",
                    c.name,
                    row.with.0,
                    row.bare.0,
                    row.with.0 / row.bare.0,
                    row.with.1,
                    row.bare.1,
                    row.with.1 / row.bare.1
                );
            }
        }
    }
    let _ = writeln!(
        out,
        "\n![response](response.svg)\n\nThe design took {:.3} s, the whole run {:.1} s of wall \
         time ({} threads on this machine's cores).",
        designed.as_secs_f64(),
        elapsed.as_secs_f64(),
        cases.len()
    );
    out
}
