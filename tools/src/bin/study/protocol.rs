//! The request/answer lines of tld-study (see main.rs) and the state between them: the loaded
//! FMU library and its instance pool.

use serde::Deserialize;
use serde_json::{Value as Json, json};

use crate::fmu::{self, Library, Vrs};
use crate::master::{self, Pool, Run};

#[derive(Deserialize)]
#[serde(deny_unknown_fields, rename_all = "lowercase")]
enum Request {
    Load(Load),
    Runs(Vec<Run>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Load {
    library: String,
    guid: String,
    resources: String,
    vr: Vrs,
}

/// The loaded library and its instances (each keeps its binary loaded while it lives).
#[derive(Default)]
pub struct Server {
    pool: Pool,
    lib: Option<Library>,
}

pub fn error_line(message: &str) -> String {
    json!({ "error": message }).to_string()
}

/// A number of a request: a JSON number, or "NaN", "Infinity", "-Infinity" (JSON has none).
pub fn number<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum N {
        F(f64),
        S(String),
    }
    match N::deserialize(d)? {
        N::F(x) => Ok(x),
        N::S(s) => match s.as_str() {
            "NaN" => Ok(f64::NAN),
            "Infinity" => Ok(f64::INFINITY),
            "-Infinity" => Ok(f64::NEG_INFINITY),
            other => Err(serde::de::Error::custom(format!(
                "{other:?} is no number (non-finite ones: \"NaN\", \"Infinity\", \"-Infinity\")"
            ))),
        },
    }
}

pub fn some_number<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    number(d).map(Some)
}

pub fn numbers<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    #[derive(Deserialize)]
    struct W(#[serde(deserialize_with = "number")] f64);
    Ok(Vec::<W>::deserialize(d)?.into_iter().map(|w| w.0).collect())
}

pub fn matrix<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<Vec<f64>>, D::Error> {
    #[derive(Deserialize)]
    struct Row(#[serde(deserialize_with = "numbers")] Vec<f64>);
    Ok(Vec::<Row>::deserialize(d)?
        .into_iter()
        .map(|r| r.0)
        .collect())
}

impl Server {
    /// Answer one request line.
    pub fn handle(&mut self, line: &str) -> String {
        let request: Request = match serde_json::from_str(line) {
            Ok(r) => r,
            Err(e) => return error_line(&format!("bad request: {e}")),
        };
        match request {
            Request::Load(l) => {
                // instances of an earlier library go first
                self.pool = Pool::default();
                self.lib = None;
                match Library::load(&l.library, &l.guid, &l.resources, l.vr) {
                    Ok(lib) => {
                        self.lib = Some(lib);
                        json!({ "loaded": l.library }).to_string()
                    }
                    Err(e) => error_line(&e),
                }
            }
            Request::Runs(runs) => {
                let Some(lib) = self.lib.as_ref() else {
                    return error_line("no FMU loaded: send {\"load\": ...} first");
                };
                let results: Vec<Json> = runs
                    .iter()
                    .map(|run| {
                        fmu::take_messages();
                        match master::simulate(lib, &mut self.pool, run) {
                            // the FMU's warnings of a run that succeeded go back with it: the
                            // client shows them (a result built on a warned configuration)
                            Ok(o) => json!({
                                "peak": o.peak,
                                "steps": o.steps,
                                "do_step_seconds": o.do_step_seconds,
                                "instances": self.pool.instances.len(),
                                "warnings": fmu::take_messages(),
                            }),
                            Err(e) => {
                                let log = fmu::take_messages();
                                let log = if log.is_empty() {
                                    String::new()
                                } else {
                                    format!(" (FMU: {log})")
                                };
                                json!({ "error": format!("{}: {e}{log}", run.name) })
                            }
                        }
                    })
                    .collect();
                json!({ "results": results }).to_string()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_json(extra: &str) -> String {
        format!(
            r#"{{"runs": [{{"name": "run 7", "minv": [0.01], "c": [[0.1]], "k": [[100.0]],
               "dampers": [], "ground": {{"w": 1.0, "amplitude": "NaN"}}, "step": 0.01,
               "duration": 1.0, "tail": 0.5, "derivatives": false{extra}}}]}}"#
        )
    }

    #[test]
    fn runs_before_a_load_are_refused() {
        let mut s = Server::default();
        let r = s.handle(&run_json(""));
        assert!(r.contains("no FMU loaded"), "{r}");
    }

    #[test]
    fn unknown_fields_and_bad_numbers_are_named() {
        let mut s = Server::default();
        let r = s.handle(&run_json(r#", "dampling": 1"#));
        assert!(r.contains("unknown field") && r.contains("dampling"), "{r}");
        let r = s.handle(&run_json("").replace("\"NaN\"", "\"lots\""));
        assert!(r.contains("\\\"lots\\\" is no number"), "{r}");
        let r = s.handle(
            "{\"load\": {\"library\": \"/nonexistent/TLD.so\", \"guid\": \"g\", \
            \"resources\": \"\", \"vr\": {\"base.a\": 1, \"base.v\": 2, \"base.x\": 3, \
            \"force\": 4, \"force.mean\": 5, \"mass.inactive\": 6}}}",
        );
        assert!(
            r.contains("\"error\"") && r.contains("/nonexistent/TLD.so"),
            "{r}"
        );
    }

    #[test]
    fn non_finite_numbers_parse() {
        let run: serde_json::Value = serde_json::from_str(&run_json("")).unwrap();
        let run: Run = serde_json::from_value(run["runs"][0].clone()).unwrap();
        assert!(run.ground.amplitude.is_nan());
        assert_eq!(run.minv, [0.01]);
    }
}
