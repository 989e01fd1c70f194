"""Portability of the packaged binary (issue: glibc floor 2.17, exports only fmi2*).

Checks binaries/linux64/TLD.so as it is inside TLD.fmu, with binutils' objdump and nm."""
import ctypes
import re
import subprocess
import zipfile

EXPECTED_FMI2 = 44  # every FMI 2.0 function, Model Exchange ones included (they log and refuse)


def _library(fmu_path, tmp_path):
    with zipfile.ZipFile(fmu_path) as z:
        z.extract("binaries/linux64/TLD.so", tmp_path)
    return tmp_path / "binaries" / "linux64" / "TLD.so"


def _version(v):
    return tuple(int(p) for p in v.split("."))


def test_glibc_floor_is_2_17(fmu_path, tmp_path):
    lib = _library(fmu_path, tmp_path)
    out = subprocess.run(["objdump", "-T", str(lib)], capture_output=True, text=True, check=True).stdout
    versions = sorted({_version(v) for v in re.findall(r"GLIBC_([0-9.]+)", out)})
    print("GLIBC versions needed:", [".".join(map(str, v)) for v in versions])
    assert versions, "objdump found no GLIBC symbol versions: not a glibc-linked library?"
    assert versions[-1] <= (2, 17), f"needs GLIBC_{'.'.join(map(str, versions[-1]))}"


def test_exports_only_fmi2_functions(fmu_path, tmp_path):
    lib = _library(fmu_path, tmp_path)
    out = subprocess.run(["nm", "-D", "--defined-only", str(lib)], capture_output=True, text=True,
                         check=True).stdout
    names = [line.split()[-1] for line in out.splitlines() if line.strip()]
    fmi = [n for n in names if n.startswith("fmi2")]
    other = [n for n in names if not n.startswith("fmi2")]
    assert len(fmi) == EXPECTED_FMI2, fmi
    # callback_log: a #[no_mangle] function of the fmi-sys crate, exported from every cdylib
    # that links it; never called by the FMU (docs/INTERNALS.md, "Exported symbols").
    assert other == ["callback_log"], other


def test_packaged_library_loads(fmu_path, tmp_path):
    lib = ctypes.CDLL(str(_library(fmu_path, tmp_path)))
    lib.fmi2GetVersion.restype = ctypes.c_char_p
    lib.fmi2GetTypesPlatform.restype = ctypes.c_char_p
    assert lib.fmi2GetVersion() == b"2.0"
    assert lib.fmi2GetTypesPlatform() == b"default"
