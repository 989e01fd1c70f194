//! The shallow-water scheme's vectorised builds against the baseline, bit for bit: the
//! passes at every state of a violent run, and whole steps, the positivity fallback's included.

use super::*;

/// The right-hand side and the substep's passes (MUSCL-Hancock and its fallback) are the same
/// bit for bit whichever build of them runs: the baseline, AVX2, AVX-512F (those this CPU
/// has): no fused multiply-adds, nothing reassociated. At every state of a violent run, with
/// bores and dry cells (`cargo test --release` tests the vectorised code; a debug build has
/// none).
#[test]
fn vectorised_passes_are_bit_for_bit_the_baseline() {
    let ch = lab(40);
    let grid = ch.grid();
    let run = violent(40, 300, 0.01, 0.1);
    let mut faces = scheme::Faces::new(40);
    let (mut dry, mut builds) = (0, vec![]);
    for (k, (f, _, _)) in run.iter().enumerate() {
        dry += f.depth.iter().filter(|&&h| h < 1e-3 * ch.depth).count();
        let a = 3.0 * (k as f64 * 0.1).sin();
        let mut results = vec![];
        scheme::each_build(
            &grid,
            &f.depth,
            &f.discharge,
            a,
            1e-3,
            &mut faces,
            |name, s, faces, steps| {
                let (dh, dq) = faces.rates();
                let all = dh.iter().chain(dq).chain(faces.mass_fluxes());
                let all = all.chain(&s.wall).chain([&s.mass_flux, &s.speed]);
                let all = all.chain(steps.iter().flat_map(|(s, next)| {
                    let sweep = s.wall.iter().chain([&s.mass_flux, &s.speed]);
                    sweep.chain(next.iter().copied().flatten())
                }));
                results.push((
                    name.to_string(),
                    all.map(|x| x.to_bits()).collect::<Vec<_>>(),
                ));
            },
        );
        for (name, bits) in &results[1..] {
            assert_eq!(bits, &results[0].1, "step {k}: {name} against the baseline");
        }
        builds = results.into_iter().map(|(name, _)| name).collect();
    }
    eprintln!("builds compared: {builds:?}");
    assert!(dry > 0, "the run must dry cells");
}

/// The whole communication step (substeps, drag, screens, films), compiled for each instruction
/// set, gives the same bits from every build: at each state of a violent run with dry cells,
/// a 10 ms step with input derivatives from there; and from each state of a flow leaving a
/// wall at 3 c0, whose steps take the positivity fallback.
#[test]
fn vectorised_steps_are_bit_for_bit_the_baseline() {
    let ch = lab(40);
    let w = omega_1(&ch);
    let run = violent(40, 300, 0.01, 0.1);
    let mut draining = ch.at_rest();
    draining
        .discharge
        .fill(3.0 * (ch.g_e * ch.depth).sqrt() * ch.depth);
    let mut states: Vec<(Flow, BaseAcceleration)> = run
        .iter()
        .enumerate()
        .step_by(7)
        .map(|(k, (f, _, _))| (f.clone(), harmonic(0.1, w, k as f64 * 0.01)))
        .collect();
    for _ in 0..20 {
        states.push((draining.clone(), held(0.0)));
        ch.advance(&mut draining, 0.01, &held(0.0), 0.3, 1_000_000)
            .expect("step");
    }
    let (mut builds, mut fallbacks) = (vec![], 0);
    for (k, (f, base)) in states.iter().enumerate() {
        let results = ch.each_build(f, 0.01, base, 0.3);
        let bits = |(_, r, g): &(&str, Result<Advanced, SolveError>, Flow)| {
            let d = r.as_ref().expect("step");
            let all = g
                .depth
                .iter()
                .chain(&g.discharge)
                .chain([&d.impulse, &d.work]);
            let counts = (d.substeps, d.rejected, d.fallbacks);
            (all.map(|x| x.to_bits()).collect::<Vec<_>>(), counts)
        };
        let first = bits(&results[0]);
        for r in &results[1..] {
            assert_eq!(bits(r), first, "state {k}: {} against the baseline", r.0);
        }
        fallbacks += first.1.2;
        builds = results.iter().map(|r| r.0).collect();
    }
    eprintln!("builds compared: {builds:?}; {fallbacks} fallbacks among the steps");
    assert!(fallbacks > 0);
}
