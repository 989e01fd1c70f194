//! `tld-design --building FILE`: a building configuration (scripts/examples/building.toml,
//! tower.toml) read as python/tld_fmu/building.py reads it: floor masses and storey stiffnesses
//! from the ground up, Rayleigh damping fixed at modes 1 and 2, the first damper's floor
//! (1-based; the top floor if there is none). Its first mode is building-model's.

use building_model::structure::{Building, Design, FirstMode, Harmonic};

#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    pub masses: Vec<f64>,
    pub stiffnesses: Vec<f64>,
    pub rayleigh: [f64; 2],
    pub floor: usize,
}

fn numbers(table: &toml::Table, key: &str) -> Result<Vec<f64>, String> {
    let list = table
        .get(key)
        .and_then(|v| v.as_array())
        .ok_or(format!("[building] {key} = [...] is missing"))?;
    list.iter()
        .map(|v| {
            v.as_float()
                .or(v.as_integer().map(|i| i as f64))
                .ok_or(format!("[building] {key}: {v:?} is not a number"))
        })
        .collect()
}

impl Config {
    pub fn parse(text: &str) -> Result<Config, String> {
        let doc: toml::Table = text.parse().map_err(|e| format!("{e}"))?;
        let b = doc
            .get("building")
            .and_then(|v| v.as_table())
            .ok_or("no [building] table")?;
        let masses = numbers(b, "masses")?;
        let rayleigh = match numbers(b, "rayleigh")?[..] {
            [z1, z2] => [z1, z2],
            _ => return Err("[building] rayleigh = [zeta1, zeta2]".into()),
        };
        let floor = match doc
            .get("dampers")
            .and_then(|v| v.as_array())
            .and_then(|d| d.first())
        {
            Some(d) => d
                .get("floor")
                .and_then(|f| f.as_integer())
                .and_then(|f| usize::try_from(f).ok())
                .ok_or("[[dampers]] floor = <1-based floor> is missing")?,
            None => masses.len(),
        };
        Ok(Config {
            stiffnesses: numbers(b, "stiffnesses")?,
            masses,
            rayleigh,
            floor,
        })
    }

    pub fn read(path: &str) -> Result<Config, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
        Config::parse(&text).map_err(|e| format!("{path}: {e}"))
    }

    /// The first mode with `inactive` kg moving rigidly with the damper's floor.
    pub fn mode(&self, inactive: f64) -> Result<FirstMode, String> {
        Building::new(&Design {
            masses: self.masses.clone(),
            stiffnesses: self.stiffnesses.clone(),
            zeta: self.rayleigh,
            damper_floor: self.floor,
            damper_mass: inactive,
            ground: Harmonic::default(),
        })?
        .first_mode()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example(name: &str) -> Config {
        Config::read(&format!(
            "{}/../scripts/examples/{name}",
            env!("CARGO_MANIFEST_DIR")
        ))
        .expect("example")
    }

    /// The example files' first modes against python/tld_fmu/building.py's matrices and
    /// numpy's eigh (Building(...), np_eig; the roof-normalised generalised mass phi^T M phi
    /// and L = phi^T M 1 from its eigenvector), computed separately: building.toml 5.638177926645
    /// rad/s, 94.879223638603 kg, L 119.924962033828 kg; tower.toml 0.199996480781 Hz,
    /// 2.3781081711497e7 kg, L 3.1792259511214e7 kg, and with the ten tanks' inactive water
    /// (441.2 t less Eq 2.1's 336.818 t) on the roof 0.199558445490 Hz, 2.3825213587074e7 kg
    /// (tower.toml's comment: 0.19956 Hz). Both damped 1 % in mode 1 (Rayleigh).
    #[test]
    fn example_modes_match_the_python() {
        let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-9;
        let b = example("building.toml").mode(0.0).expect("mode");
        assert!(close(b.omega, 5.638177926645487), "{}", b.omega);
        assert!(close(b.mass, 94.87922363860304), "{}", b.mass);
        assert!(close(b.participation, 119.92496203382788));
        assert!((b.damping - 0.01).abs() < 1e-12);
        let tower = example("tower.toml");
        assert_eq!(tower.floor, 20);
        let t = tower.mode(0.0).expect("mode");
        let hz = |w: f64| w / (2.0 * std::f64::consts::PI);
        assert!(close(hz(t.omega), 0.1999964807810225), "{}", hz(t.omega));
        assert!(close(t.mass, 23781081.711496856), "{}", t.mass);
        assert!(close(t.participation, 31792259.511214256));
        let w = tower.mode(441200.0 - 336817.9069824365).expect("mode");
        assert!(close(hz(w.omega), 0.19955844548956808), "{}", hz(w.omega));
        assert!(close(w.mass, 23825213.587073572));
    }

    #[test]
    fn bad_files_say_why() {
        let e = Config::parse("[building]\nmasses = [1.0]\nrayleigh = [0.01, 0.01]\n")
            .expect_err("no stiffnesses");
        assert!(e.contains("stiffnesses"), "{e}");
        let e = Config::parse("[building]\nmasses = [1.0]\nstiffnesses = [2.0]\nrayleigh = [0.01]")
            .expect_err("one ratio");
        assert!(e.contains("rayleigh"), "{e}");
        let c = Config::parse(
            "[building]\nmasses = [1.0, 1]\nstiffnesses = [2.0, 2.0]\nrayleigh = [0.01, 0.01]\n\
             [[dampers]]\nfloor = 3\n",
        )
        .expect("parses");
        assert!(c.mode(0.0).expect_err("no floor 3").contains("floor"));
    }
}
