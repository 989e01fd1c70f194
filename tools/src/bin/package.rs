//! Packs TLD.fmu: modelDescription.xml, binaries/linux64/TLD.so and documentation/index.html
//! (prose from modelDescription/documentation.html, variable table from the generated table).
//!
//! Usage: tld-package <output .fmu> <library> [<library> ...] (scripts/package)

use std::io::Write;
use std::path::Path;

use tld_fmu::fmi::vars::{Causality, VARIABLES, VarType, Variable};
use zip::write::SimpleFileOptions;

const XML: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../modelDescription/modelDescription.xml"
));
const DOC: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../modelDescription/documentation.html"
));

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
fn variable_table() -> String {
    let row = |tag: &str, cells: &[String]| {
        let cells: String = cells
            .iter()
            .map(|c| format!("<{tag}>{c}</{tag}>"))
            .collect();
        format!("<tr>{cells}</tr>\n")
    };
    let header = row("th", &COLUMNS.map(String::from));
    let rows: String = VARIABLES.iter().map(|v| row("td", &cells(v))).collect();
    format!("<table>\n{header}{rows}</table>")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: tld-package <TLD.fmu> <library> [<library> ...]");
        eprintln!("  each library's file name says its platform: *.so -> binaries/linux64/TLD.so,");
        eprintln!("  *.dll -> binaries/win64/TLD.dll, *.dylib -> binaries/darwin64/TLD.dylib");
        std::process::exit(2);
    }
    let libraries: Vec<&Path> = args[2..].iter().map(Path::new).collect();
    if let Err(e) = pack(Path::new(&args[1]), &libraries) {
        eprintln!("tld-package: {e}");
        std::process::exit(1);
    }
}

/// Where a built library goes in the FMU (FMI 2.0 section 2.3), from its file name.
fn platform_path(library: &Path) -> Result<&'static str, String> {
    match library.extension().and_then(|e| e.to_str()) {
        Some("so") => Ok("binaries/linux64/TLD.so"),
        Some("dll") => Ok("binaries/win64/TLD.dll"),
        Some("dylib") => Ok("binaries/darwin64/TLD.dylib"),
        _ => Err(format!("{}: not a .so, .dll or .dylib", library.display())),
    }
}

fn pack(out: &Path, libraries: &[&Path]) -> Result<(), Box<dyn std::error::Error>> {
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let doc = DOC.replace("{{VARIABLES}}", &variable_table());
    let file =
        std::fs::File::create(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options)?;
    zip.write_all(XML.as_bytes())?;
    let mut placed: Vec<&str> = Vec::new();
    for library in libraries {
        let inside = platform_path(library)?;
        if placed.contains(&inside) {
            return Err(format!("two libraries for {inside}").into());
        }
        let binary = std::fs::read(library)
            .map_err(|e| format!("cannot read {}: {e}", library.display()))?;
        zip.start_file(inside, options.unix_permissions(0o755))?;
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
        let html = variable_table();
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
        assert!(DOC.contains("{{VARIABLES}}"));
    }
}
