//! tld-scenes: runs one FMU binary through a scene and prints every output at every step as
//! the hex of its bits, so that the binaries of different platforms (run natively or under an
//! emulator) can be compared bit for bit (scripts/platforms.py writes the scenes and compares).
//!
//! Usage: tld-scenes <library> <scene file> [--save <step> <file> | --restore <step> <file>]
//!
//! The scene file, one directive a line (numbers as the hex of their bits, so that no decimal
//! conversion stands between platforms):
//!   guid <guid>
//!   integer <vr> <value>                 set before initialisation
//!   real <vr> <bits>                     set before initialisation
//!   input <vr> <amplitude bits> <period> a periodic input, set before each step (below)
//!   output <vr>                          printed after each step, in the order given
//!   steps <h bits> <count>               the steps: step k goes from k*h to (k+1)*h
//!
//! The input of period P steps at step k: s = 2 (k mod P) / P - 1, u = A s (1 - s^2), a smooth
//! periodic wave computed with +, -, *, / only (IEEE 754 exact rounding: the same bits on every
//! platform, where sin would depend on each platform's libm).
//!
//! --save k file: after step k-1 (at time k*h), the state serialised into file.
//! --restore k file: the instance initialised as the scene says, then given the state from file,
//! and run from step k on: its lines must equal the full run's from step k.

use std::process::ExitCode;

use fmi2_host::{Instance, Library, Value};

#[derive(Default)]
struct Scene {
    guid: String,
    parameters: Vec<(u32, Value)>,
    inputs: Vec<(u32, f64, u64)>,
    outputs: Vec<u32>,
    h: f64,
    count: u64,
}

fn bits(word: &str) -> Result<f64, String> {
    u64::from_str_radix(word, 16)
        .map(f64::from_bits)
        .map_err(|_| format!("{word}: not the hex of a double's bits"))
}

fn number<T: std::str::FromStr>(word: &str) -> Result<T, String> {
    word.parse().map_err(|_| format!("{word}: not a number"))
}

fn parse(text: &str) -> Result<Scene, String> {
    let mut scene = Scene::default();
    for (i, line) in text.lines().enumerate() {
        let w: Vec<&str> = line.split_whitespace().collect();
        let bad = || format!("line {}: {line}", i + 1);
        match w.as_slice() {
            [] => {}
            ["guid", g] => scene.guid = g.to_string(),
            ["integer", vr, v] => scene
                .parameters
                .push((number(vr)?, Value::Integer(number(v)?))),
            ["real", vr, v] => scene.parameters.push((number(vr)?, Value::Real(bits(v)?))),
            ["input", vr, a, p] => {
                let period: u64 = number(p)?;
                if period == 0 {
                    return Err(bad());
                }
                scene.inputs.push((number(vr)?, bits(a)?, period));
            }
            ["output", vr] => scene.outputs.push(number(vr)?),
            ["steps", h, n] => (scene.h, scene.count) = (bits(h)?, number(n)?),
            _ => return Err(bad()),
        }
    }
    if scene.guid.is_empty() || scene.outputs.is_empty() || scene.count == 0 {
        return Err("a scene needs a guid, outputs and steps".into());
    }
    Ok(scene)
}

/// The periodic input of amplitude `a` and period `p` steps at step `k` (module docs).
fn input(a: f64, p: u64, k: u64) -> f64 {
    let s = 2.0 * (k % p) as f64 / p as f64 - 1.0;
    a * s * (1.0 - s * s)
}

enum Mode {
    Run,
    Save(u64, String),
    Restore(u64, String),
}

fn run(library: &str, scene: &Scene, mode: &Mode) -> Result<(), String> {
    // SAFETY: the library is one of the workspace's FMU binaries (scripts/platforms.py).
    let lib = unsafe { Library::load(library, &scene.guid, None) }?;
    let mut inst = Instance::new(&lib, "scene")?;
    inst.initialize(&scene.parameters)?;
    let first = match mode {
        Mode::Restore(k, file) => {
            let bytes = std::fs::read(file).map_err(|e| format!("read {file}: {e}"))?;
            inst.restore_state(&bytes)?;
            *k
        }
        _ => 0,
    };
    let mut values = vec![0.0; scene.outputs.len()];
    let mut line = String::new();
    for k in first..scene.count {
        if let Mode::Save(at, file) = mode
            && *at == k
        {
            let bytes = inst.serialize_state()?;
            std::fs::write(file, bytes).map_err(|e| format!("write {file}: {e}"))?;
        }
        for &(vr, a, p) in &scene.inputs {
            inst.set_real(&[vr], &[input(a, p, k)])?;
        }
        inst.do_step(k as f64 * scene.h, scene.h)?;
        inst.get_real(&scene.outputs, &mut values)?;
        line.clear();
        line.push_str(&k.to_string());
        for v in &values {
            line.push_str(&format!(" {:016x}", v.to_bits()));
        }
        println!("{line}");
    }
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let mode = match args.get(3..).unwrap_or_default() {
        [] => Ok(Mode::Run),
        [flag, k, file] if flag == "--save" => number(k).map(|k| Mode::Save(k, file.clone())),
        [flag, k, file] if flag == "--restore" => number(k).map(|k| Mode::Restore(k, file.clone())),
        _ => Err(String::new()),
    };
    let (Some(library), Some(scene_file), Ok(mode)) = (args.get(1), args.get(2), mode) else {
        eprintln!(
            "usage: tld-scenes <library> <scene file> [--save <step> <file> | --restore <step> <file>]"
        );
        return ExitCode::from(2);
    };
    fmi2_host::print_messages();
    let outcome = std::fs::read_to_string(scene_file)
        .map_err(|e| format!("read {scene_file}: {e}"))
        .and_then(|text| parse(&text))
        .and_then(|scene| run(library, &scene, &mode));
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tld-scenes: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_input_is_a_zero_mean_periodic_wave() {
        let p = 40;
        let u: Vec<f64> = (0..2 * p).map(|k| input(2.0, p, k)).collect();
        assert_eq!(u[..p as usize], u[p as usize..], "periodic");
        assert_eq!(u[0], 0.0);
        assert!(u.iter().sum::<f64>().abs() < 1e-12, "zero mean");
        let peak = u.iter().cloned().fold(0.0, f64::max);
        // the peak of s (1 - s^2) is 2 / (3 sqrt 3) = 0.385, at s = 1 / sqrt 3
        assert!((peak - 2.0 * 0.3849).abs() < 0.01, "{peak}");
    }

    #[test]
    fn scenes_parse_and_refuse() {
        let s = parse(
            "guid {x}\ninteger 6 3\nreal 1 3ff0000000000000\ninput 50 4000000000000000 40\n\
             output 60\noutput 63\nsteps 3f847ae147ae147b 100\n",
        )
        .unwrap();
        assert_eq!(
            s.parameters,
            [(6, Value::Integer(3)), (1, Value::Real(1.0))]
        );
        assert_eq!((s.inputs[0].1, s.inputs[0].2), (2.0, 40));
        assert_eq!((s.outputs.clone(), s.h, s.count), (vec![60, 63], 0.01, 100));
        for bad in [
            "guid {x}\noutput 60\n",
            "guid {x}\noutput 60\nsteps 1 0\n",
            "guid {x}\noutput 60\nsteps 1 10\nreal 1 zz\n",
            "guid {x}\noutput 60\nsteps 1 10\ninput 50 1 0\n",
            "guid {x}\noutput 60\nsteps 1 10\nfrobnicate\n",
        ] {
            assert!(parse(bad).is_err(), "{bad}");
        }
    }
}
