//! The tools answer --help with their usage, refuse unknown options, and honour the options
//! the plots depend on (the CSV's frequency range, a calibration data file with a header).

use std::process::Command;

fn run(bin: &str, args: &[&str]) -> (bool, String, String) {
    let out = Command::new(bin).args(args).output().expect("run the tool");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const FREQRESP: &str = env!("CARGO_BIN_EXE_tld-freqresp");
const CALIBRATE: &str = env!("CARGO_BIN_EXE_tld-calibrate");

fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("tld-tools-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn help_exits_zero_with_usage_and_every_option() {
    for (bin, options) in [
        (
            FREQRESP,
            &[
                "--eta",
                "--phi",
                "--zeta",
                "--A",
                "--from",
                "--to",
                "--coupled",
                "--Omega",
                "w_f",
            ][..],
        ),
        (
            CALIBRATE,
            &["--data", "--length", "--csv", "Lambda,kappa,zeta", "header"][..],
        ),
    ] {
        for flag in ["--help", "-h"] {
            let (ok, out, err) = run(bin, &[flag]);
            assert!(ok, "{bin} {flag} failed: {err}");
            assert!(out.contains("Usage:"), "{bin} {flag}: no usage in\n{out}");
            for o in options {
                assert!(out.contains(o), "{bin} --help does not mention {o}:\n{out}");
            }
        }
        let (ok, _, err) = run(bin, &["--no-such-option"]);
        assert!(!ok && err.contains("--no-such-option"), "{bin}: {err}");
    }
}

#[test]
fn freqresp_csv_stays_between_from_and_to_and_names_its_parameters() {
    let path = tmp("freqresp.csv");
    let p = path.to_str().unwrap();
    let (ok, _, err) = run(
        FREQRESP,
        &["--from", "1.0", "--to", "1.2", "--eta", "3", "--csv", p],
    );
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap();
    assert!(
        head.starts_with("# omega_f=") && head.contains("eta=3") && head.contains("from=1"),
        "{head}"
    );
    assert_eq!(lines.next(), Some("w_ratio,x,stable"));
    let mut n = 0;
    for l in lines {
        let w: f64 = l.split(',').next().unwrap().parse().unwrap();
        assert!((1.0..=1.2).contains(&w), "{l}");
        n += 1;
    }
    assert!(n > 100);
    // --coupled writes its own CSV (it used to leave the previous one to be re-plotted)
    let (ok, out, err) = run(
        FREQRESP,
        &[
            "--coupled",
            "--from",
            "0.9",
            "--to",
            "1.1",
            "--points",
            "5",
            "--csv",
            p,
        ],
    );
    assert!(ok && out.contains("\"rows\""), "{err}");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("# coupled=1") && text.lines().nth(1) == Some("w_ratio,with,without"),
        "{text}"
    );
    assert_eq!(text.lines().count(), 7);
}

#[test]
fn calibrate_accepts_a_header_and_writes_the_fit() {
    let data = tmp("data.csv");
    std::fs::write(
        &data,
        "Lambda,kappa,zeta\n0.005,1.0359,0.0783\n0.01,1.0409,0.0994\n0.02,1.0460,0.1272\n0.05,1.1916,0.1757\n0.08,1.3402,0.2066\n",
    )
    .unwrap();
    let out_csv = tmp("calibration.csv");
    let (ok, out, err) = run(
        CALIBRATE,
        &[
            "--data",
            data.to_str().unwrap(),
            "--csv",
            out_csv.to_str().unwrap(),
        ],
    );
    assert!(ok, "{err}");
    assert!(out.starts_with("fit: phi = "), "{out}");
    let text = std::fs::read_to_string(&out_csv).unwrap();
    assert!(
        text.starts_with("# phi=") && text.contains("nsd_c=") && text.lines().count() == 7,
        "{text}"
    );
}
