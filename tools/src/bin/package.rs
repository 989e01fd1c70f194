//! Packs an FMU of the workspace, TLD.fmu or Building.fmu (chosen by the output's file name):
//! modelDescription.xml, binaries/<platform>/<modelIdentifier>.so and documentation/index.html
//! (prose from its modelDescription/documentation.html, variable table from the generated
//! table).
//!
//! Usage: tld-package <output .fmu> <library> [<library> ...] (scripts/package)

use std::io::Write;
use std::path::Path;

use tld_fmu::fmi::vars::{Causality, VarType, Variable};
use zip::write::SimpleFileOptions;

/// One FMU of the workspace: what goes into its archive.
struct Fmu {
    id: &'static str,
    xml: &'static str,
    doc: &'static str,
    variables: &'static [Variable],
}

/// A file of the workspace (the path from its root), built into the tool.
macro_rules! workspace_file {
    ($path:literal) => {
        include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/../", $path))
    };
}

const TLD: Fmu = Fmu {
    id: "TLD",
    xml: workspace_file!("modelDescription/modelDescription.xml"),
    doc: workspace_file!("modelDescription/documentation.html"),
    variables: tld_fmu::fmi::vars::VARIABLES,
};

const BUILDING: Fmu = Fmu {
    id: "Building",
    xml: workspace_file!("building/model/modelDescription/modelDescription.xml"),
    doc: workspace_file!("building/model/modelDescription/documentation.html"),
    variables: building_model::description::VARIABLES,
};

/// The FMU an output file is for: its name is the modelIdentifier's.
fn fmu_for(out: &Path) -> Result<&'static Fmu, String> {
    let stem = out.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
    [&TLD, &BUILDING]
        .into_iter()
        .find(|f| f.id == stem)
        .ok_or_else(|| {
            format!(
                "{}: the FMU's name must be TLD.fmu or Building.fmu",
                out.display()
            )
        })
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The columns of the variable table; [`cells`] fills them in this order.
const COLUMNS: [&str; 9] = [
    "name",
    "value reference",
    "causality",
    "type",
    "unit",
    "start",
    "min",
    "max",
    "description",
];

/// One variable's row of the table, escaped HTML, one entry per column of [`COLUMNS`].
fn cells(v: &Variable) -> [String; COLUMNS.len()] {
    let fmt = |x: Option<f64>| x.map(|x| format!("{x}")).unwrap_or_default();
    let ty = match v.ty {
        VarType::Enumeration => {
            let items: Vec<String> = v
                .items
                .iter()
                .map(|(n, val)| format!("{val} = {n}"))
                .collect();
            format!("Enumeration ({})", items.join(", "))
        }
        other => format!("{other:?}"),
    };
    let causality = match v.causality {
        Causality::CalculatedParameter => "calculatedParameter".to_string(),
        other => format!("{other:?}").to_lowercase(),
    };
    [
        format!("<code>{}</code>", escape(v.name)),
        v.vr.to_string(),
        causality,
        escape(&ty),
        escape(v.unit),
        fmt(v.start),
        fmt(v.min),
        fmt(v.max),
        escape(v.description),
    ]
}

/// The variables as an HTML table, with descriptions taken from the XML.
fn variable_table(variables: &[Variable]) -> String {
    let row = |tag: &str, cells: &[String]| {
        let cells: String = cells
            .iter()
            .map(|c| format!("<{tag}>{c}</{tag}>"))
            .collect();
        format!("<tr>{cells}</tr>\n")
    };
    let header = row("th", &COLUMNS.map(String::from));
    let rows: String = variables.iter().map(|v| row("td", &cells(v))).collect();
    format!("<table>\n{header}{rows}</table>")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: tld-package <TLD.fmu | Building.fmu> <library> [<library> ...]");
        eprintln!("  each library's file name says its platform: *.so -> binaries/linux64/TLD.so,");
        eprintln!("  *.dll -> binaries/win64/TLD.dll, *.dylib -> binaries/darwin64/TLD.dylib");
        eprintln!("  (Building.so, ... for Building.fmu)");
        std::process::exit(2);
    }
    let libraries: Vec<&Path> = args[2..].iter().map(Path::new).collect();
    if let Err(e) = pack(Path::new(&args[1]), &libraries) {
        eprintln!("tld-package: {e}");
        std::process::exit(1);
    }
}

/// Where a built library goes in the FMU (FMI 2.0 section 2.3), from its file name.
fn platform_path(library: &Path, id: &str) -> Result<String, String> {
    match library.extension().and_then(|e| e.to_str()) {
        Some("so") => Ok(format!("binaries/linux64/{id}.so")),
        Some("dll") => Ok(format!("binaries/win64/{id}.dll")),
        Some("dylib") => Ok(format!("binaries/darwin64/{id}.dylib")),
        _ => Err(format!("{}: not a .so, .dll or .dylib", library.display())),
    }
}

fn pack(out: &Path, libraries: &[&Path]) -> Result<(), Box<dyn std::error::Error>> {
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let fmu = fmu_for(out)?;
    let doc = fmu
        .doc
        .replace("{{VARIABLES}}", &variable_table(fmu.variables));
    let file =
        std::fs::File::create(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options)?;
    zip.write_all(fmu.xml.as_bytes())?;
    let mut placed: Vec<String> = Vec::new();
    for library in libraries {
        let inside = platform_path(library, fmu.id)?;
        if placed.contains(&inside) {
            return Err(format!("two libraries for {inside}").into());
        }
        let binary = std::fs::read(library)
            .map_err(|e| format!("cannot read {}: {e}", library.display()))?;
        zip.start_file(inside.as_str(), options.unix_permissions(0o755))?;
        zip.write_all(&binary)?;
        println!(
            "  {inside}: {} bytes from {}",
            binary.len(),
            library.display()
        );
        placed.push(inside);
    }
    zip.start_file("documentation/index.html", options)?;
    zip.write_all(doc.as_bytes())?;
    zip.finish()?;
    println!("wrote {}", out.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The texts of the `<tag>` cells of each row of `html`.
    fn table(html: &str, tag: &str) -> Vec<Vec<String>> {
        let (open, close) = (format!("<{tag}>"), format!("</{tag}>"));
        html.split("<tr>")
            .skip(1)
            .map(|row| {
                row.split(&open)
                    .skip(1)
                    .map(|cell| cell.split(&close).next().unwrap_or("").to_string())
                    .collect::<Vec<_>>()
            })
            .filter(|cells| !cells.is_empty())
            .collect()
    }

    #[test]
    fn every_row_fills_every_column_and_the_unit_column_holds_the_units() {
        const VARIABLES: &[Variable] = TLD.variables;
        let html = variable_table(VARIABLES);
        let header = table(&html, "th");
        assert_eq!(header.len(), 1);
        let header = &header[0];
        let rows = table(&html, "td");
        assert_eq!(rows.len(), VARIABLES.len());
        let col = |name: &str| header.iter().position(|h| h == name).unwrap();
        for (row, v) in rows.iter().zip(VARIABLES) {
            assert_eq!(row.len(), header.len(), "{}: {row:?}", v.name);
            assert_eq!(row[col("name")], format!("<code>{}</code>", v.name));
            assert_eq!(row[col("value reference")], v.vr.to_string());
            assert_eq!(row[col("unit")], v.unit, "{}", v.name);
            assert_eq!(row[col("description")], escape(v.description), "{}", v.name);
        }
        let force = rows.iter().find(|r| r[0] == "<code>force</code>").unwrap();
        assert_eq!(force[col("unit")], "N");
    }

    #[test]
    fn the_documentation_gets_the_table() {
        for fmu in [&TLD, &BUILDING] {
            assert!(fmu.doc.contains("{{VARIABLES}}"), "{}", fmu.id);
            assert!(fmu.xml.contains(&format!("modelIdentifier=\"{}\"", fmu.id)));
        }
    }

    #[test]
    fn the_output_name_chooses_the_fmu() {
        assert_eq!(
            fmu_for(Path::new("target/fmu/Building.fmu")).map(|f| f.id),
            Ok("Building")
        );
        assert_eq!(fmu_for(Path::new("TLD.fmu")).map(|f| f.id), Ok("TLD"));
        assert!(fmu_for(Path::new("Other.fmu")).is_err());
    }
}
