//! Packs an FMU of the workspace, TLD.fmu or Building.fmu (chosen by the output's file name):
//! modelDescription.xml, binaries/<platform>/<modelIdentifier>.<so|dll|dylib> for each library
//! given (checked first: binary.rs) and documentation/index.html (prose from its
//! modelDescription/documentation.html, variable table from the generated table).
//!
//! Usage: tld-package <output .fmu> [<platform>=]<library> ... (scripts/package; without
//! arguments, the usage)

mod binary;

use std::io::Write;
use std::path::Path;

use binary::Platform;

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
        eprintln!("usage: tld-package <TLD.fmu | Building.fmu> [<platform>=]<library> ...");
        eprintln!(
            "  <platform>: the folder under binaries/: linux64 (x86_64 Linux), aarch64-linux,"
        );
        eprintln!(
            "  win64, darwin64 (macOS, x86_64, arm64 or universal). Without it, the file name"
        );
        eprintln!("  says: *.so -> linux64, *.dll -> win64, *.dylib -> darwin64. Each library is");
        eprintln!(
            "  checked (format and machine of its folder, a shared library, exports only fmi2*"
        );
        eprintln!("  and callback_log) and goes in as binaries/<platform>/TLD.<so|dll|dylib>");
        eprintln!("  (Building.* for Building.fmu). The FMU is written whole or not at all.");
        std::process::exit(2);
    }
    if let Err(e) = pack(Path::new(&args[1]), &args[2..]) {
        eprintln!("tld-package: {e}");
        std::process::exit(1);
    }
}

/// One argument's platform and library: `<platform>=<path>`, or a path whose suffix says.
fn platform_of(arg: &str) -> Result<(Platform, &Path), String> {
    if let Some((folder, path)) = arg.split_once('=') {
        let platform = Platform::from_folder(folder).ok_or_else(|| {
            let known: Vec<&str> = Platform::ALL.iter().map(|p| p.folder()).collect();
            format!("{arg}: no platform {folder} (known: {})", known.join(", "))
        })?;
        return Ok((platform, Path::new(path)));
    }
    let path = Path::new(arg);
    let ext = path.extension().and_then(|e| e.to_str());
    [Platform::Linux64, Platform::Win64, Platform::Darwin64]
        .into_iter()
        .find(|p| Some(p.suffix()) == ext)
        .map(|p| (p, path))
        .ok_or_else(|| {
            format!("{arg}: not a .so, .dll or .dylib (name the platform: <platform>={arg})")
        })
}

/// Packs `out` from `libraries` (arguments `[<platform>=]<path>`), every library checked first;
/// the archive is written to a temporary file beside `out` and renamed onto it at the end, so
/// that a failure leaves any previous `out` as it was and no partial file.
fn pack(out: &Path, libraries: &[String]) -> Result<(), Box<dyn std::error::Error>> {
    let fmu = fmu_for(out)?;
    let mut binaries: Vec<(String, Vec<u8>, &Path)> = Vec::new();
    for arg in libraries {
        let (platform, library) = platform_of(arg)?;
        let inside = format!(
            "binaries/{}/{}.{}",
            platform.folder(),
            fmu.id,
            platform.suffix()
        );
        if binaries.iter().any(|(i, _, _)| *i == inside) {
            return Err(format!("two libraries for {inside}").into());
        }
        let bytes = std::fs::read(library)
            .map_err(|e| format!("cannot read {}: {e}", library.display()))?;
        binary::check(&bytes, platform, &library.display().to_string())?;
        binaries.push((inside, bytes, library));
    }
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut part = out.as_os_str().to_owned();
    part.push(".part");
    let part = std::path::PathBuf::from(part);
    let written = write(&part, fmu, &binaries).and_then(|()| {
        std::fs::rename(&part, out).map_err(|e| {
            format!("cannot rename {} to {}: {e}", part.display(), out.display()).into()
        })
    });
    if written.is_err() {
        let _ = std::fs::remove_file(&part);
    }
    written?;
    println!("wrote {}", out.display());
    Ok(())
}

/// The archive: modelDescription.xml, the binaries, documentation/index.html.
fn write(
    path: &Path,
    fmu: &Fmu,
    binaries: &[(String, Vec<u8>, &Path)],
) -> Result<(), Box<dyn std::error::Error>> {
    let doc = fmu
        .doc
        .replace("{{VARIABLES}}", &variable_table(fmu.variables));
    let file = std::fs::File::create(path)
        .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options)?;
    zip.write_all(fmu.xml.as_bytes())?;
    for (inside, bytes, library) in binaries {
        zip.start_file(inside.as_str(), options.unix_permissions(0o755))?;
        zip.write_all(bytes)?;
        println!(
            "  {inside}: {} bytes from {}",
            bytes.len(),
            library.display()
        );
    }
    zip.start_file("documentation/index.html", options)?;
    zip.write_all(doc.as_bytes())?;
    zip.finish()?.sync_all()?;
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

    /// A fresh directory under the target directory for one test's files.
    fn scratch(name: &str) -> std::path::PathBuf {
        let exe = std::env::current_exe().unwrap();
        let dir = exe.parent().unwrap().join(format!("package-test-{name}"));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names_in(fmu: &Path) -> Vec<String> {
        let zip = zip::ZipArchive::new(std::fs::File::open(fmu).unwrap()).unwrap();
        let mut names: Vec<String> = zip.file_names().map(String::from).collect();
        names.sort();
        names
    }

    /// A macOS binary built elsewhere goes in as binaries/darwin64/<id>.dylib, checked.
    #[test]
    fn a_darwin64_binary_built_elsewhere_is_packed() {
        let dir = scratch("darwin");
        let names = binary::tests::fmi2_names(&[]);
        let dylib = dir.join("libtld_fmu.dylib");
        let file = binary::tests::macho_file(0x0100_000c, 6, &binary::tests::refs(&names));
        std::fs::write(&dylib, file).unwrap();
        let out = dir.join("TLD.fmu");
        pack(&out, &[format!("darwin64={}", dylib.display())]).unwrap();
        assert_eq!(
            names_in(&out),
            [
                "binaries/darwin64/TLD.dylib",
                "documentation/index.html",
                "modelDescription.xml"
            ]
        );
        // the suffix alone says darwin64 too
        pack(&out, &[dylib.display().to_string()]).unwrap();
        assert!(names_in(&out).contains(&"binaries/darwin64/TLD.dylib".to_string()));
    }

    /// A library refused for its folder (here a Linux executable given as darwin64) fails the
    /// whole FMU: the previous archive stays as it was and no partial file is left.
    #[test]
    fn a_refused_library_leaves_no_partial_fmu() {
        let dir = scratch("refused");
        let names = binary::tests::fmi2_names(&[]);
        let dylib = dir.join("good.dylib");
        let file = binary::tests::macho_file(0x0100_0007, 6, &binary::tests::refs(&names));
        std::fs::write(&dylib, file).unwrap();
        let out = dir.join("Building.fmu");
        pack(&out, &[dylib.display().to_string()]).unwrap();
        let before = std::fs::read(&out).unwrap();
        let elf = std::env::current_exe().unwrap();
        for args in [
            vec![format!("darwin64={}", elf.display())],
            vec![
                dylib.display().to_string(),
                format!("win64={}", dylib.display()),
            ],
            vec![format!("linux32={}", dylib.display())],
            vec![dylib.display().to_string(), dylib.display().to_string()],
            vec![dir.join("missing.so").display().to_string()],
        ] {
            let e = pack(&out, &args).unwrap_err().to_string();
            assert!(!e.is_empty());
            assert_eq!(std::fs::read(&out).unwrap(), before, "{args:?}: {e}");
            let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
            assert_eq!(left.len(), 2, "{args:?}: only good.dylib and Building.fmu");
        }
        let e = pack(&out, &[format!("darwin64={}", elf.display())]).unwrap_err();
        assert!(
            e.to_string()
                .contains("is ELF for x86_64, binaries/darwin64 needs Mach-O"),
            "{e}"
        );
    }
}
