//! Writes the seed corpora of the deserialise targets: states the FMUs save, serialised, for
//! every TLD model (Fixed and Tracked amplitude) and buildings of 1, 3 and 20 storeys, in
//! Co-Simulation and Model Exchange, before, in and after initialisation, with and without a
//! few steps; each behind the target's first byte (lib.rs, `deserialize`), sealed.
//! Usage: seeds <corpus directory> (writes <dir>/deserialize_tld/, <dir>/deserialize_building/)

use std::path::Path;

use building_model::description::vr as bvr;
use fmi2_slave::Slave;
use tld_fmu::fmi::vars::{ModelKindItem, vr};
use tld_fuzz::calls::{Call, Int, Len, Real, Run, Step, Vr};
use tld_fuzz::{Host, OK};

/// The states of `S` with each of `parameters` (value references and Integer values) set.
fn states<S: Slave>(parameters: &[Vec<(u32, i32)>]) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for set in parameters {
        for model_exchange in [false, true] {
            for depth in 0..3u8 {
                for steps in [0, 5] {
                    let mut run = Run::new(Host::<S>::new(model_exchange, false));
                    run.perform_checked(&Call::SetInteger {
                        vrs: set.iter().map(|&(r, _)| Vr::Any(r)).collect(),
                        values: set.iter().map(|&(_, v)| Int::Any(v)).collect(),
                    });
                    run.host.initialise(depth);
                    if depth == 2 && model_exchange && steps > 0 {
                        run.perform_checked(&Call::NewDiscreteStates);
                        run.perform_checked(&Call::EnterContinuousTimeMode);
                    }
                    for k in 1..=steps {
                        if model_exchange {
                            run.perform_checked(&Call::SetTime {
                                t: Real::Milli(10 * k),
                            });
                            run.perform_checked(&Call::SetStates {
                                values: vec![Real::Milli(k); S::STATES],
                                len: Len::Right,
                            });
                            run.perform_checked(&Call::CompletedIntegratorStep {
                                no_set_prior: true,
                            });
                        } else {
                            run.perform_checked(&Call::DoStep {
                                offset: Some(Real::Milli(0)),
                                h: Step::Usual(1),
                                no_set_prior: false,
                            });
                        }
                    }
                    let state = run.host.serialised();
                    // Every state an instance saves loads into a new instance of its kind.
                    let mut fresh = Host::<S>::new(model_exchange, false);
                    assert_eq!(fresh.load(&state), (OK, Some(OK)), "{set:?} depth {depth}");
                    let flags = u8::from(model_exchange) | depth << 1 | 16;
                    let mut bytes = vec![flags];
                    bytes.extend(state);
                    out.push(bytes);
                }
            }
        }
    }
    out.sort();
    out.dedup();
    out
}

fn write(dir: &Path, states: &[Vec<u8>]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    for (i, bytes) in states.iter().enumerate() {
        std::fs::write(dir.join(format!("seed-{i:03}")), bytes)?;
    }
    println!("{}: {} seed states", dir.display(), states.len());
    Ok(())
}

fn main() -> std::io::Result<()> {
    let Some(root) = std::env::args().nth(1) else {
        eprintln!("usage: seeds <corpus directory>");
        std::process::exit(2);
    };
    let root = Path::new(&root);
    let tld: Vec<Vec<(u32, i32)>> = ModelKindItem::ALL
        .iter()
        .flat_map(|m| {
            [1, 2].map(|amplitude| vec![(vr::MODEL, m.value() as i32), (vr::AMPLITUDE, amplitude)])
        })
        .collect();
    write(
        &root.join("deserialize_tld"),
        &states::<tld_fmu::fmi::Tld>(&tld),
    )?;
    let building: Vec<Vec<(u32, i32)>> = [(1, 1), (3, 2), (20, 20)]
        .iter()
        .map(|&(storeys, floor)| vec![(bvr::STOREYS, storeys), (bvr::TLD_FLOOR, floor)])
        .collect();
    write(
        &root.join("deserialize_building"),
        &states::<building_model::Building>(&building),
    )
}
