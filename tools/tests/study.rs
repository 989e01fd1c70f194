//! tld-study against the FMU library cargo builds with this test (target/<profile>/deps, the
//! cdylib of the tld-fmu dependency), over its JSON-lines protocol: the bare structure's RK4
//! against the closed-form steady state, a damper that damps, instances reused through
//! fmi2Reset without a trace, and a run the FMU refuses named without losing the next one.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

use serde_json::{Value, json};
use tld_fmu::fmi::vars::VARIABLES;

const STUDY: &str = env!("CARGO_BIN_EXE_tld-study");
const XML: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../modelDescription/modelDescription.xml"
));

fn vr(name: &str) -> u32 {
    VARIABLES
        .iter()
        .find(|v| v.name == name)
        .map(|v| v.vr)
        .unwrap_or_else(|| panic!("no variable {name}"))
}

fn guid() -> &'static str {
    let start = XML.find("guid=\"").expect("guid in the XML") + 6;
    let len = XML[start..].find('"').expect("guid's end");
    &XML[start..start + len]
}

fn library() -> std::path::PathBuf {
    let exe = std::env::current_exe().expect("test executable");
    let deps = exe.parent().expect("target/<profile>/deps");
    let lib = deps.join(format!(
        "{}tld_fmu{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    assert!(lib.is_file(), "{} missing", lib.display());
    lib
}

struct Master {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
}

impl Master {
    fn start() -> Self {
        let mut child = Command::new(STUDY)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("start tld-study");
        let stdin = child.stdin.take().expect("stdin");
        let stdout = BufReader::new(child.stdout.take().expect("stdout"));
        let mut m = Master {
            child,
            stdin,
            stdout,
        };
        let names = [
            "base.a",
            "base.v",
            "base.x",
            "force",
            "force.mean",
            "mass.inactive",
        ];
        let vrs: serde_json::Map<String, Value> = names
            .iter()
            .map(|n| (n.to_string(), json!(vr(n))))
            .collect();
        let r = m.ask(&json!({"load": {"library": library(), "guid": guid(),
                                       "resources": "", "vr": vrs}}));
        assert!(r.get("loaded").is_some(), "{r}");
        m
    }

    fn ask(&mut self, v: &Value) -> Value {
        writeln!(self.stdin, "{v}").expect("write");
        self.stdin.flush().expect("flush");
        let mut line = String::new();
        self.stdout.read_line(&mut line).expect("read");
        serde_json::from_str(&line).expect("a JSON answer")
    }

    fn runs(&mut self, runs: &[Value]) -> Vec<Value> {
        let r = self.ask(&json!({ "runs": runs }));
        r["results"].as_array().expect("results").clone()
    }
}

impl Drop for Master {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

const M: f64 = 100.0;
const W_N: f64 = std::f64::consts::TAU;
const ZETA: f64 = 0.05;

/// A one-mode structure (m, k = m w_n^2, c = 2 zeta m w_n) with the given dampers.
fn run(name: &str, dampers: Value, inactive: f64, w: f64, amplitude: Value) -> Value {
    let m = M + inactive;
    json!({"name": name, "minv": [1.0 / m], "c": [[2.0 * ZETA * M * W_N]], "k": [[M * W_N * W_N]],
           "dampers": dampers, "ground": {"w": w, "amplitude": amplitude},
           "step": 1e-3, "duration": 40.0, "tail": 10.0, "derivatives": true})
}

fn tank(tanks: i32, inactive: f64) -> Value {
    json!([{"floor": 0, "params": [{"vr": vr("tanks"), "integer": tanks}], "inactive": inactive}])
}

fn peak(r: &Value) -> f64 {
    r["peak"][0]
        .as_f64()
        .unwrap_or_else(|| panic!("no peak: {r}"))
}

#[test]
fn the_bare_structure_reaches_its_closed_form_steady_state() {
    let mut m = Master::start();
    let (w, a) = (0.9 * W_N, 1e-3);
    let got = peak(&m.runs(&[run("bare", json!([]), 0.0, w, json!(a))])[0]);
    let (k, c) = (M * W_N * W_N, 2.0 * ZETA * M * W_N);
    let exact = M * w * w * a / ((k - M * w * w).powi(2) + (c * w).powi(2)).sqrt();
    // the transient has decayed to exp(-zeta w_n 30 s) ~ 1e-4; sampling at 1 ms loses < 1e-5
    assert!(
        (got - exact).abs() / exact < 3e-4,
        "peak {got} against the steady state {exact}"
    );
}

/// mass.inactive of `tanks` tanks, as the master reports it when the structure was built with
/// another value (its check of the caller's structure).
fn inactive(m: &mut Master, tanks: i32) -> f64 {
    let probe = m.runs(&[run("probe", tank(tanks, -1.0), -1.0, W_N, json!(1e-4))]);
    let msg = probe[0]["error"]
        .as_str()
        .expect("a mass.inactive mismatch");
    assert!(
        msg.starts_with("probe: damper 0: the FMU reports mass.inactive = "),
        "{msg}"
    );
    msg.split("mass.inactive = ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .expect("a number")
}

#[test]
fn a_damper_damps_and_a_reused_instance_gives_the_same_numbers() {
    let mut m = Master::start();
    let inactive = inactive(&mut m, 4);
    let tuned = run("tuned", tank(4, inactive), inactive, W_N, json!(1e-4));
    let bare = run("bare", json!([]), 0.0, W_N, json!(1e-4));
    let r = m.runs(&[tuned.clone(), bare, tuned]);
    let (damped, undamped, again) = (peak(&r[0]), peak(&r[1]), peak(&r[2]));
    assert!(
        damped > 0.0 && damped < 0.9 * undamped,
        "{damped} vs {undamped}"
    );
    assert_eq!(damped.to_bits(), again.to_bits(), "fmi2Reset left a trace");
    assert_eq!(r[2]["instances"], 1);
    assert_eq!(r[0]["steps"], 40_000);
}

#[test]
fn a_refused_run_is_named_and_the_next_one_runs() {
    let mut m = Master::start();
    let one = inactive(&mut m, 1);
    let mut bad = run("bad tail", json!([]), 0.0, W_N, json!(1e-3));
    bad["tail"] = json!(50.0);
    let r = m.runs(&[
        // no damper to refuse NaN: the bare structure's peak is NaN (null), as numpy's max gives
        run("NaN ground, bare", json!([]), 0.0, W_N, json!("NaN")),
        bad,
        run("run 7", tank(1, one), one, W_N, json!("NaN")),
        run("fine", tank(1, one), one, W_N, json!(1e-3)),
    ]);
    assert!(r[0]["peak"][0].is_null(), "{}", r[0]);
    let e = r[1]["error"].as_str().unwrap_or_default();
    assert!(e.starts_with("bad tail: tail 50 s"), "{e}");
    let e = r[2]["error"].as_str().unwrap_or_default();
    assert!(
        e.starts_with("run 7: the damper refused a step at t = 0")
            || e.starts_with("run 7: the damper refused its inputs at t = 0"),
        "{e}"
    );
    assert!(peak(&r[3]) > 0.0);
}
