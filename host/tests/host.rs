//! fmi2-host against a library that is not there, one that is no FMU, and TLD.fmu's own binary
//! (the cdylib cargo builds with this test, in target/<profile>/deps).

use fmi2_host::{Instance, Library, Refused, Value};
use tld_fmu::fmi::vars::{GUID, vr};

fn tld() -> String {
    let exe = std::env::current_exe().expect("test executable");
    let lib = exe.parent().expect("target/<profile>/deps").join(format!(
        "{}tld_fmu{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    assert!(lib.is_file(), "{} missing", lib.display());
    lib.to_str().expect("a UTF-8 path").to_string()
}

fn load(path: &str, guid: &str) -> Result<Library, String> {
    // SAFETY: TLD.fmu's binary, or a library whose load fails before any call into it.
    unsafe { Library::load(path, guid, None) }
}

#[test]
fn a_library_that_is_not_there_is_named() {
    let e = load("/nonexistent/TLD.so", GUID).err().expect("an error");
    assert!(e.starts_with("load /nonexistent/TLD.so: "), "{e}");
}

#[cfg(target_os = "linux")]
#[test]
fn a_library_without_the_fmi2_functions_names_the_first_missing_one() {
    // libm: loads (and is loaded already), exports no fmi2 function
    let e = load("libm.so.6", GUID).err().expect("an error");
    assert!(e.starts_with("libm.so.6 has no fmi2Instantiate: "), "{e}");
}

#[test]
fn a_nul_in_a_string_is_an_error() {
    let e = load(&tld(), "{a\0b}").err().expect("an error");
    assert_eq!(e, "the GUID holds a NUL");
    let lib = load(&tld(), GUID).expect("TLD loads");
    let e = Instance::new(&lib, "a\0b").err().expect("an error");
    assert_eq!(e, "instance name holds a NUL");
}

#[test]
fn tld_runs_resets_and_refuses_by_name() {
    let lib = load(&tld(), GUID).expect("TLD loads");
    let mut i = Instance::new(&lib, "host-test").expect("instantiate");
    // the library may go first: the instance keeps the binary loaded
    drop(lib);
    let refused = i.initialize(&[(vr::MASS_INACTIVE, Value::Real(1.0))]);
    assert_eq!(
        refused,
        Err(format!(
            "fmi2SetReal(vr {} = 1) returned status 3",
            vr::MASS_INACTIVE
        ))
    );
    i.reset().expect("reset");
    let run = |i: &mut Instance| -> Result<[f64; 2], String> {
        i.initialize(&[(vr::ETA, Value::Real(3.0))])?;
        for k in 0..10 {
            i.set_real(&[vr::BASE_A], &[0.5])?;
            i.set_real_input_derivatives(&[vr::BASE_A], &[1], &[0.1])?;
            i.do_step(f64::from(k) * 0.01, 0.01)?;
        }
        let mut x = [0.0; 2];
        i.get_real(&[vr::SLOSH_X], &mut x[..1])?;
        i.get_real_output_derivatives(&[vr::FORCE], &[1], &mut x[1..])?;
        Ok(x)
    };
    let first = run(&mut i).expect("a run");
    assert!(
        first[0] != 0.0 && first.iter().all(|x| x.is_finite()),
        "{first:?}"
    );
    i.reset().expect("reset");
    let again = run(&mut i).expect("the run again");
    assert_eq!(first.map(f64::to_bits), again.map(f64::to_bits));
    assert_eq!(
        i.do_step(0.1, -1.0),
        Err(Refused {
            call: "fmi2DoStep",
            status: 3
        })
    );
}
