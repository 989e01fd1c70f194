"""Where things are: the package is installed in editable mode from the repository it lives in
(scripts/pyenv), so the repository is two levels above this file."""
from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
# the contract: the XML the FMU is built from and packs unchanged
MODEL_DESCRIPTION = REPO / "modelDescription" / "modelDescription.xml"
# what scripts/package writes; TLD_FMU_PATH overrides it (to test or drive another build)
FMU = Path(os.environ.get("TLD_FMU_PATH") or REPO / "target" / "fmu" / "TLD.fmu")
# the reference structure for TLD.fmu, packed by the same command
BUILDING_FMU = Path(os.environ.get("BUILDING_FMU_PATH") or REPO / "target" / "fmu" / "Building.fmu")


def cargo_executable(name: str, release: bool = False) -> Path:
    """The workspace's binary `name` (tld-freqresp, tld-bench, ...), built or found up to date
    by cargo; its path as cargo reports it (so CARGO_TARGET_DIR and profiles are respected)."""
    cmd = ["cargo", "build", "--quiet", "--bin", name, "--message-format=json"]
    if release:
        cmd.append("--release")
    out = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{out.stderr}")
    for line in out.stdout.splitlines():
        msg = json.loads(line)
        if msg.get("reason") == "compiler-artifact" and msg.get("executable") \
                and msg["target"]["name"] == name:
            return Path(msg["executable"])
    raise RuntimeError(f"cargo reported no executable {name}")
