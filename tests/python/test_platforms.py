"""The platform folders of the packed FMUs (docs/PLATFORMS.md), as FMI 2.0 hosts and the FMU
Compliance Checker expect them: known folder names, one binary per folder named after the
modelIdentifier, each of its folder's format and machine; after `scripts/package
--all-platforms`: linux64, win64 (importing Windows system DLLs only) and aarch64-linux in each
FMU, and target/fmu/aarch64-linux/<id>.fmu carrying the same aarch64 binary as linux64 (the
folder fmpy and FMIL load FMI 2.0 binaries from on aarch64 Linux), valid for fmpy too."""
import struct
import subprocess
import zipfile
from pathlib import Path

import pytest
from fmpy.validation import validate_fmu

# folder: (suffix, ELF e_machine or PE machine accepted)
FOLDERS = {
    "linux64": ("so", {62, 183}),       # x86_64; aarch64 in the aarch64 hosts' FMU
    "aarch64-linux": ("so", {183}),
    "win64": ("dll", {0x8664}),
    "darwin64": ("dylib", None),         # built elsewhere (docs/PLATFORMS.md)
}
WINDOWS_SYSTEM = {"kernel32.dll", "ntdll.dll", "msvcrt.dll", "userenv.dll", "ws2_32.dll",
                  "advapi32.dll", "bcrypt.dll", "bcryptprimitives.dll"}


def _machine(data: bytes) -> int:
    if data[:4] == b"\x7fELF":
        return struct.unpack_from("<H", data, 18)[0]
    if data[:2] == b"MZ":
        pe = struct.unpack_from("<I", data, 0x3C)[0]
        assert data[pe:pe + 4] == b"PE\0\0"
        return struct.unpack_from("<H", data, pe + 4)[0]
    raise AssertionError("neither ELF nor PE")


def _binaries(fmu: Path) -> dict[str, tuple[str, bytes]]:
    """folder -> (file name, bytes) of every binary in the FMU; fails on two in one folder."""
    out = {}
    with zipfile.ZipFile(fmu) as z:
        for name in z.namelist():
            parts = name.split("/")
            if parts[0] != "binaries" or name.endswith("/"):
                continue
            assert len(parts) == 3, f"{name}: binaries/<platform>/<file> expected"
            assert parts[1] not in out, f"{fmu.name}: two files in binaries/{parts[1]}"
            out[parts[1]] = (parts[2], z.read(name))
    return out


@pytest.fixture(params=["TLD", "Building"])
def fmu(request, fmu_path, building_path) -> Path:
    return fmu_path if request.param == "TLD" else building_path


def test_every_folder_is_a_known_platform_with_one_binary_of_its_machine(fmu):
    binaries = _binaries(fmu)
    model_id = fmu.stem
    assert "linux64" in binaries
    for folder, (name, data) in binaries.items():
        assert folder in FOLDERS, f"{fmu.name}: unknown platform folder {folder}"
        suffix, machines = FOLDERS[folder]
        assert name == f"{model_id}.{suffix}", f"{fmu.name}: binaries/{folder}/{name}"
        if machines is not None:
            assert _machine(data) in machines, f"{folder}/{name}: machine {_machine(data):#x}"
    # the x86_64 build is the one in the main FMU's linux64
    assert _machine(binaries["linux64"][1]) == 62


def _all_platforms(fmu):
    if "win64" not in _binaries(fmu):
        pytest.skip("packed without --all-platforms (scripts/package --all-platforms packs them)")


def test_all_platform_fmus_carry_win64_and_aarch64(fmu, tmp_path):
    _all_platforms(fmu)
    binaries = _binaries(fmu)
    assert set(binaries) == {"linux64", "win64", "aarch64-linux"}
    # the aarch64 hosts' FMU: the same aarch64 binary, in linux64, and nothing else
    aarch64_fmu = fmu.parent / "aarch64-linux" / fmu.name
    other = _binaries(aarch64_fmu)
    assert set(other) == {"linux64"}
    assert other["linux64"][1] == binaries["aarch64-linux"][1]
    with zipfile.ZipFile(fmu) as a, zipfile.ZipFile(aarch64_fmu) as b:
        assert a.read("modelDescription.xml") == b.read("modelDescription.xml")
    assert validate_fmu(str(aarch64_fmu)) == []
    # the DLL imports nothing a Windows user lacks (no MinGW runtime DLL)
    dll = tmp_path / binaries["win64"][0]
    dll.write_bytes(binaries["win64"][1])
    dump = subprocess.run(["objdump", "-p", str(dll)], capture_output=True, text=True,
                          check=True).stdout
    imports = {line.split()[-1].lower() for line in dump.splitlines() if "DLL Name:" in line}
    assert imports, "objdump found no imports: not a DLL?"
    others = {d for d in imports if d not in WINDOWS_SYSTEM and not d.startswith("api-ms-win-")}
    assert not others, f"imports DLLs that are not part of Windows: {others}"


def test_fmpy_validates_the_multi_platform_fmu(fmu):
    assert validate_fmu(str(fmu)) == []
