//! What the packaging tool checks of a library before it goes into an FMU's
//! binaries/<platform>/ folder, read from the file's own headers (no binutils for other
//! platforms needed): the object format, machine and kind (a shared library) the platform
//! folder asks for, and the names it exports: the fmi2* functions and fmi-sys's callback_log
//! only.
//!
//! Formats: ELF64 little-endian (.dynsym), PE32+ (the export directory), Mach-O 64-bit
//! little-endian, thin or universal (LC_SYMTAB's external defined symbols, whose C names carry
//! a leading underscore).

/// The platform folders the tool packs, with the binary each must hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Platform {
    /// 64-bit Linux (FMI 2.0's linux64): x86_64, or aarch64 in an FMU for aarch64 hosts, which
    /// look for FMI 2.0 binaries in linux64 too (fmpy, FMIL: docs/PLATFORMS.md)
    Linux64,
    /// aarch64 Linux (FMI 3.0's name; FMI 2.0 names no folder for it)
    Aarch64Linux,
    /// x86_64 Windows (FMI 2.0's win64)
    Win64,
    /// macOS, x86_64 or arm64 or both in a universal binary (FMI 2.0's darwin64)
    Darwin64,
}

impl Platform {
    pub const ALL: [Platform; 4] = [
        Platform::Linux64,
        Platform::Aarch64Linux,
        Platform::Win64,
        Platform::Darwin64,
    ];

    /// The folder under binaries/.
    pub fn folder(self) -> &'static str {
        match self {
            Platform::Linux64 => "linux64",
            Platform::Aarch64Linux => "aarch64-linux",
            Platform::Win64 => "win64",
            Platform::Darwin64 => "darwin64",
        }
    }

    /// The library's file name suffix in that folder.
    pub fn suffix(self) -> &'static str {
        match self {
            Platform::Linux64 | Platform::Aarch64Linux => "so",
            Platform::Win64 => "dll",
            Platform::Darwin64 => "dylib",
        }
    }

    pub fn from_folder(name: &str) -> Option<Platform> {
        Platform::ALL.into_iter().find(|p| p.folder() == name)
    }
}

/// What a file holds, as far as the checks care.
#[derive(Debug, PartialEq, Eq)]
pub struct Binary {
    /// the platforms' word for the machine: "x86_64", "aarch64", ...
    pub machines: Vec<&'static str>,
    /// "ELF", "PE", "Mach-O"
    pub format: &'static str,
    /// a shared library (ELF ET_DYN, a PE DLL, a Mach-O MH_DYLIB)
    pub shared: bool,
    /// the names it exports (C names: Mach-O's leading underscore removed)
    pub exports: Vec<String>,
}

/// The check of `bytes` (the file `what`) for `platform`: Ok, or every reason it fails.
pub fn check(bytes: &[u8], platform: Platform, what: &str) -> Result<Binary, String> {
    let bin = read(bytes).map_err(|e| format!("{what}: {e}"))?;
    let (format, machines): (&str, &[&str]) = match platform {
        Platform::Linux64 => ("ELF", &["x86_64", "aarch64"]),
        Platform::Aarch64Linux => ("ELF", &["aarch64"]),
        Platform::Win64 => ("PE", &["x86_64"]),
        Platform::Darwin64 => ("Mach-O", &["x86_64", "aarch64"]),
    };
    let mut wrong = Vec::new();
    if bin.format != format || bin.machines.iter().any(|m| !machines.contains(m)) {
        wrong.push(format!(
            "is {} for {}, binaries/{} needs {format} for {}",
            bin.format,
            bin.machines.join("+"),
            platform.folder(),
            machines.join(" or ")
        ));
    }
    if !bin.shared {
        wrong.push("is no shared library".to_string());
    }
    let fmi = bin.exports.iter().filter(|n| n.starts_with("fmi2")).count();
    let other: Vec<&str> = bin
        .exports
        .iter()
        .map(String::as_str)
        .filter(|n| !n.starts_with("fmi2") && *n != "callback_log")
        .collect();
    if fmi != FMI2_FUNCTIONS {
        wrong.push(format!(
            "exports {fmi} fmi2* functions, not the {FMI2_FUNCTIONS} of FMI 2.0"
        ));
    }
    if !other.is_empty() {
        wrong.push(format!("exports more than fmi2*: {}", other.join(", ")));
    }
    if wrong.is_empty() {
        Ok(bin)
    } else {
        Err(format!("{what}: {}", wrong.join("; ")))
    }
}

/// Every FMI 2.0 function, Model Exchange's included (they log and refuse).
pub const FMI2_FUNCTIONS: usize = 44;

/// Bounds-checked little- or big-endian reads.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn take<const N: usize>(&self, at: usize) -> Result<[u8; N], String> {
        at.checked_add(N)
            .and_then(|end| self.0.get(at..end))
            .and_then(|s| s.try_into().ok())
            .ok_or_else(|| format!("truncated (offset {at})"))
    }
    fn u16(&self, at: usize) -> Result<u16, String> {
        self.take(at).map(u16::from_le_bytes)
    }
    fn u32(&self, at: usize) -> Result<u32, String> {
        self.take(at).map(u32::from_le_bytes)
    }
    fn u32be(&self, at: usize) -> Result<u32, String> {
        self.take(at).map(u32::from_be_bytes)
    }
    fn u64(&self, at: usize) -> Result<u64, String> {
        self.take(at).map(u64::from_le_bytes)
    }
    fn at(&self, at: u64) -> Result<usize, String> {
        usize::try_from(at).map_err(|_| format!("offset {at} out of range"))
    }
    /// The NUL-terminated string at `at`.
    fn cstr(&self, at: usize) -> Result<String, String> {
        let rest = self
            .0
            .get(at..)
            .ok_or_else(|| format!("no string at {at}"))?;
        let end = rest
            .iter()
            .position(|&b| b == 0)
            .ok_or_else(|| format!("unterminated string at {at}"))?;
        Ok(String::from_utf8_lossy(&rest[..end]).into_owned())
    }
}

/// The format, machine(s), kind and exports of a binary.
pub fn read(bytes: &[u8]) -> Result<Binary, String> {
    let b = Bytes(bytes);
    match bytes.get(..4) {
        Some([0x7f, b'E', b'L', b'F']) => elf(&b),
        Some([b'M', b'Z', ..]) => pe(&b),
        Some([0xcf, 0xfa, 0xed, 0xfe]) => macho(&b, 0),
        Some([0xca, 0xfe, 0xba, 0xbe]) => universal(&b),
        _ => Err("neither ELF, PE nor Mach-O".to_string()),
    }
}

fn elf(b: &Bytes) -> Result<Binary, String> {
    if b.take::<2>(4)? != [2, 1] {
        return Err("an ELF file, but not 64-bit little-endian".to_string());
    }
    let machine = match b.u16(18)? {
        62 => "x86_64",
        183 => "aarch64",
        _ => "another machine",
    };
    let shared = b.u16(16)? == 3; // ET_DYN
    let shoff = b.at(b.u64(0x28)?)?;
    let shentsize = usize::from(b.u16(0x3a)?);
    let shnum = usize::from(b.u16(0x3c)?);
    let section = |i: usize| shoff + i * shentsize;
    let mut exports = Vec::new();
    for i in 0..shnum {
        let s = section(i);
        if b.u32(s + 4)? != 11 {
            continue; // not SHT_DYNSYM
        }
        let (off, size) = (b.at(b.u64(s + 0x18)?)?, b.at(b.u64(s + 0x20)?)?);
        let strtab = section(b.u32(s + 0x28)? as usize);
        let stroff = b.at(b.u64(strtab + 0x18)?)?;
        for sym in (off..off + size).step_by(24).skip(1) {
            let info = b.take::<1>(sym + 4)?[0];
            let (bind, shndx) = (info >> 4, b.u16(sym + 6)?);
            // global or weak, defined here
            if (bind == 1 || bind == 2) && shndx != 0 {
                exports.push(b.cstr(stroff + b.u32(sym)? as usize)?);
            }
        }
    }
    Ok(Binary {
        machines: vec![machine],
        format: "ELF",
        shared,
        exports,
    })
}

fn pe(b: &Bytes) -> Result<Binary, String> {
    let pe = b.u32(0x3c)? as usize;
    if b.take::<4>(pe)? != *b"PE\0\0" {
        return Err("MZ but no PE header".to_string());
    }
    let coff = pe + 4;
    let machine = match b.u16(coff)? {
        0x8664 => "x86_64",
        0xaa64 => "aarch64",
        _ => "another machine",
    };
    let sections = usize::from(b.u16(coff + 2)?);
    let optional = coff + 20;
    let shared = b.u16(coff + 18)? & 0x2000 != 0; // IMAGE_FILE_DLL
    if b.u16(optional)? != 0x20b {
        return Err("a PE file, but not PE32+ (64-bit)".to_string());
    }
    let section_table = optional + usize::from(b.u16(coff + 16)?);
    // a relative virtual address to a file offset, through the section table
    let file = |rva: u32| -> Result<usize, String> {
        for i in 0..sections {
            let s = section_table + 40 * i;
            let (size, va, raw) = (b.u32(s + 8)?, b.u32(s + 12)?, b.u32(s + 20)?);
            if rva >= va && rva - va < size {
                return Ok((rva - va + raw) as usize);
            }
        }
        Err(format!("address {rva:#x} in no section"))
    };
    let mut exports = Vec::new();
    let dir_rva = b.u32(optional + 112)?; // data directory 0: the export table
    if dir_rva != 0 {
        let dir = file(dir_rva)?;
        let (count, names) = (b.u32(dir + 24)?, b.u32(dir + 32)?);
        let names = file(names)?;
        for i in 0..count as usize {
            exports.push(b.cstr(file(b.u32(names + 4 * i)?)?)?);
        }
    }
    Ok(Binary {
        machines: vec![machine],
        format: "PE",
        shared,
        exports,
    })
}

fn macho_machine(cputype: u32) -> &'static str {
    match cputype {
        0x0100_0007 => "x86_64",
        0x0100_000c => "aarch64",
        _ => "another machine",
    }
}

/// A thin 64-bit Mach-O file starting at `base`.
fn macho(b: &Bytes, base: usize) -> Result<Binary, String> {
    if b.take::<4>(base)? != [0xcf, 0xfa, 0xed, 0xfe] {
        return Err("not a 64-bit little-endian Mach-O file".to_string());
    }
    let machine = macho_machine(b.u32(base + 4)?);
    let shared = b.u32(base + 12)? == 6; // MH_DYLIB
    let ncmds = b.u32(base + 16)?;
    let mut cmd = base + 32;
    let mut exports = Vec::new();
    for _ in 0..ncmds {
        let (kind, size) = (b.u32(cmd)?, b.u32(cmd + 4)? as usize);
        if kind == 2 {
            // LC_SYMTAB: nlist_64 entries, 16 bytes each
            let (symoff, nsyms) = (b.u32(cmd + 8)? as usize, b.u32(cmd + 12)? as usize);
            let stroff = b.u32(cmd + 16)? as usize;
            for i in 0..nsyms {
                let n = base + symoff + 16 * i;
                let n_type = b.take::<1>(n + 4)?[0];
                // N_EXT, N_SECT (defined in a section), no debugging entry (N_STAB)
                if n_type & 0xe0 == 0 && n_type & 0x01 != 0 && n_type & 0x0e == 0x0e {
                    let name = b.cstr(base + stroff + b.u32(n)? as usize)?;
                    exports.push(name.strip_prefix('_').unwrap_or(&name).to_string());
                }
            }
        }
        if size == 0 {
            return Err("a Mach-O load command of size 0".to_string());
        }
        cmd += size;
    }
    Ok(Binary {
        machines: vec![machine],
        format: "Mach-O",
        shared,
        exports,
    })
}

/// A universal (fat) Mach-O file: every slice is read; the exports are the first slice's, and
/// every slice must export the same names.
fn universal(b: &Bytes) -> Result<Binary, String> {
    let n = b.u32be(4)? as usize;
    let mut slices = Vec::new();
    for i in 0..n {
        let arch = 8 + 20 * i;
        slices.push(macho(b, b.u32be(arch + 8)? as usize)?);
    }
    let first = slices
        .first()
        .ok_or_else(|| "a universal Mach-O file without slices".to_string())?;
    let sorted = |s: &Binary| {
        let mut e = s.exports.clone();
        e.sort();
        e
    };
    if slices.iter().any(|s| sorted(s) != sorted(first)) {
        return Err("the slices of a universal Mach-O file export different names".to_string());
    }
    Ok(Binary {
        machines: slices.iter().flat_map(|s| s.machines.clone()).collect(),
        format: "Mach-O",
        shared: slices.iter().all(|s| s.shared),
        exports: first.exports.clone(),
    })
}

#[cfg(test)]
pub mod tests {
    use super::*;

    /// A minimal 64-bit Mach-O file of `cputype` and `filetype` whose symbol table holds
    /// `names` as external symbols defined in a section, and a local symbol `_hidden`.
    pub fn macho_file(cputype: u32, filetype: u32, names: &[&str]) -> Vec<u8> {
        let mut strings = vec![0u8];
        let mut symbols = Vec::new();
        let mut add = |name: &str, n_type: u8| {
            let at = strings.len() as u32;
            strings.extend_from_slice(format!("_{name}").as_bytes());
            strings.push(0);
            symbols.extend_from_slice(&at.to_le_bytes());
            symbols.extend_from_slice(&[n_type, 1, 0, 0]);
            symbols.extend_from_slice(&0u64.to_le_bytes());
        };
        for n in names {
            add(n, 0x0f); // N_SECT | N_EXT
        }
        add("hidden", 0x0e); // N_SECT, local
        let nsyms = names.len() as u32 + 1;
        let symoff = 32 + 24;
        let stroff = symoff + symbols.len() as u32;
        let mut f = Vec::new();
        for w in [0xfeed_facf, cputype, 3, filetype, 1, 24, 0, 0] {
            f.extend_from_slice(&u32::to_le_bytes(w));
        }
        for w in [2, 24, symoff, nsyms, stroff, strings.len() as u32] {
            f.extend_from_slice(&u32::to_le_bytes(w));
        }
        f.extend_from_slice(&symbols);
        f.extend_from_slice(&strings);
        f
    }

    /// `slices` in a universal file.
    fn universal_file(slices: &[(u32, Vec<u8>)]) -> Vec<u8> {
        let mut f = Vec::new();
        f.extend_from_slice(&0xcafe_babeu32.to_be_bytes());
        f.extend_from_slice(&(slices.len() as u32).to_be_bytes());
        let mut offset = 4096u32;
        let mut bodies = Vec::new();
        for (cpu, body) in slices {
            for w in [*cpu, 3, offset, body.len() as u32, 12] {
                f.extend_from_slice(&w.to_be_bytes());
            }
            bodies.push((offset, body));
            offset += (body.len() as u32).div_ceil(4096) * 4096;
        }
        for (at, body) in bodies {
            f.resize(at as usize, 0);
            f.extend_from_slice(body);
        }
        f
    }

    pub fn fmi2_names(extra: &[&'static str]) -> Vec<String> {
        (0..FMI2_FUNCTIONS)
            .map(|i| format!("fmi2F{i}"))
            .chain(["callback_log".to_string()])
            .chain(extra.iter().map(|s| s.to_string()))
            .collect()
    }

    pub fn refs(names: &[String]) -> Vec<&str> {
        names.iter().map(String::as_str).collect()
    }

    #[test]
    fn a_macos_dylib_with_only_fmi2_exports_passes_for_darwin64() {
        let names = fmi2_names(&[]);
        for cpu in [0x0100_0007, 0x0100_000c] {
            let file = macho_file(cpu, 6, &refs(&names));
            let bin = check(&file, Platform::Darwin64, "lib").expect("passes");
            assert_eq!(
                bin.exports, names,
                "the leading underscore goes, _hidden is local"
            );
        }
        let fat = universal_file(&[
            (0x0100_0007, macho_file(0x0100_0007, 6, &refs(&names))),
            (0x0100_000c, macho_file(0x0100_000c, 6, &refs(&names))),
        ]);
        let bin = check(&fat, Platform::Darwin64, "fat").expect("passes");
        assert_eq!(bin.machines, ["x86_64", "aarch64"]);
    }

    #[test]
    fn a_macos_binary_is_refused_for_what_it_lacks() {
        let extra = fmi2_names(&["helper"]);
        let e = check(
            &macho_file(0x0100_0007, 6, &refs(&extra)),
            Platform::Darwin64,
            "lib",
        )
        .unwrap_err();
        assert!(e.contains("exports more than fmi2*: helper"), "{e}");
        let names = fmi2_names(&[]);
        let few = &refs(&names)[1..];
        let e = check(&macho_file(0x0100_0007, 6, few), Platform::Darwin64, "lib").unwrap_err();
        assert!(e.contains("exports 43 fmi2* functions"), "{e}");
        // an executable (MH_EXECUTE), not a dylib
        let e = check(
            &macho_file(0x0100_0007, 2, &refs(&names)),
            Platform::Darwin64,
            "lib",
        )
        .unwrap_err();
        assert!(e.contains("no shared library"), "{e}");
        // a Mach-O file for another machine (x86, 32-bit cputype 7), and one in the wrong folder
        let e = check(&macho_file(7, 6, &refs(&names)), Platform::Darwin64, "lib").unwrap_err();
        assert!(e.contains("another machine"), "{e}");
        let good = macho_file(0x0100_0007, 6, &refs(&names));
        let e = check(&good, Platform::Linux64, "lib").unwrap_err();
        assert!(
            e.contains("binaries/linux64 needs ELF for x86_64 or aarch64"),
            "{e}"
        );
        // slices that differ
        let fat = universal_file(&[
            (0x0100_0007, good.clone()),
            (0x0100_000c, macho_file(0x0100_000c, 6, few)),
        ]);
        assert!(check(&fat, Platform::Darwin64, "fat").is_err());
        // garbage and truncation (the last cut ends inside callback_log): an error, no panic
        assert!(read(b"not a binary").is_err());
        for cut in [8, 40, 60, good.len() - 12] {
            assert!(read(&good[..cut]).is_err(), "cut at {cut}");
        }
    }

    #[test]
    fn the_platform_folders_round_trip() {
        for p in Platform::ALL {
            assert_eq!(Platform::from_folder(p.folder()), Some(p));
        }
        assert_eq!(Platform::from_folder("linux32"), None);
    }
}
