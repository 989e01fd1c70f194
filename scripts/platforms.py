"""The cross-platform check (docs/PLATFORMS.md): every binary of the all-platform FMUs
(scripts/package --all-platforms) through the same scenes, on its own platform (linux64
natively, win64 under wine64, aarch64 under qemu-aarch64), all outputs at all steps compared
bit for bit; and a state serialised on each platform restored and continued on every other.

Each run is tld-scenes (host/src/bin/scenes.rs) built for that platform, loading the binary
as extracted from target/fmu/<FMU>.fmu. Scenes: every item of TLD.fmu's `model` enumeration
under a periodic base acceleration near and off its sloshing resonance, and Building.fmu under
ground acceleration and a TLD force; inputs computed with + - * / only (no libm: see
scenes.rs). Exit status 1 if any output differs in any bit or a restored run departs from the
uninterrupted one.

Usage: scripts/platforms.py [--steps N] [--fmu-dir DIR] [--report FILE]
(scripts/cross-test builds what it needs and runs it.)"""

import argparse
import os
import struct
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from tqdm import tqdm

REPO = Path(__file__).resolve().parent.parent
CROSS = REPO / "target" / "cross"

# platform: (runner command, binary inside the FMU)
PLATFORMS = {
    "linux64": ([str(REPO / "target" / "x86_64-unknown-linux-gnu" / "release" / "tld-scenes")], "binaries/linux64/{id}.so"),
    "win64": (["/usr/lib/wine/wine64", str(CROSS / "x86_64-pc-windows-gnu" / "release" / "tld-scenes.exe")],
              "binaries/win64/{id}.dll"),
    "aarch64-linux": (["qemu-aarch64", "-L", "/usr/aarch64-linux-gnu",
                       str(CROSS / "aarch64-unknown-linux-gnu" / "release" / "tld-scenes")],
                      "binaries/aarch64-linux/{id}.so"),
}


def bits(x):
    return f"{struct.unpack('<Q', struct.pack('<d', x))[0]:016x}"


def value(h):
    """The double whose bits are the hex `h`."""
    return struct.unpack("<d", struct.pack("<Q", int(h, 16)))[0]


def describe(fmu):
    """The GUID, the value references by name, the Real outputs, the enumerations' items."""
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    vrs, outputs = {}, []
    for v in root.iter("ScalarVariable"):
        vrs[v.get("name")] = int(v.get("valueReference"))
        # the Real outputs (tld-scenes reads Reals: TLD.fmu's one Integer output, impacts,
        # counts what impact.z, a Real output, shows)
        if v.get("causality") == "output" and v.find("Real") is not None:
            outputs.append(v.get("name"))
    items = {}
    for t in root.iter("SimpleType"):
        for i, item in enumerate(t.iter("Item")):
            items.setdefault(t.get("name"), {})[item.get("name")] = int(item.get("value", i + 1))
    return root.get("guid"), vrs, outputs, items


def scenes(fmu_dir, steps):
    """(label, FMU id, scene text, output names) for every scene."""
    out = []
    h = 0.01
    guid, vrs, outputs, items = describe(fmu_dir / "TLD.fmu")
    models = next(v for k, v in items.items() if "Linear" in v and "ShallowWater" in v)
    head = f"guid {guid}\n" + "".join(f"output {vrs[o]}\n" for o in outputs)
    for name, value in models.items():
        # at the default tank's first sloshing mode (0.90 Hz: period 1.11 s) and off it (0.6 s)
        for tag, amp, period in [("resonant", 0.5, 111), ("off", 2.0, 60)]:
            text = head + f"integer {vrs['model']} {value}\n" \
                f"input {vrs['base.a']} {bits(amp)} {period}\nsteps {bits(h)} {steps}\n"
            out.append((f"TLD {name} {tag}", "TLD", text, outputs))
    guid, vrs, outputs, _ = describe(fmu_dir / "Building.fmu")
    text = f"guid {guid}\n" + "".join(f"output {vrs[o]}\n" for o in outputs) + \
        f"input {vrs['ground.a']} {bits(2.0)} 180\ninput {vrs['tld.force']} {bits(4.0e4)} 97\n" \
        f"steps {bits(h)} {steps}\n"
    out.append(("Building ground+tld", "Building", text, outputs))
    return out


def run(platform, library, scene_file, extra=()):
    cmd, _ = PLATFORMS[platform]
    env = dict(os.environ, WINEDEBUG="-all")
    env.setdefault("WINEPREFIX", str(REPO / "target" / "wine"))
    r = subprocess.run(cmd + [str(library), str(scene_file), *map(str, extra)],
                       capture_output=True, text=True, env=env)
    if r.returncode != 0:
        raise SystemExit(f"{platform}: {' '.join(cmd)} failed ({r.returncode}):\n{r.stderr}")
    return [line.split() for line in r.stdout.splitlines()]


def ulps(a, b):
    """The distance of two doubles (hex bits) in units in the last place."""
    def ordered(h):
        i = int(h, 16)
        return i if i < 1 << 63 else (1 << 63) - i
    return abs(ordered(a) - ordered(b))


# The platforms whose C library's math functions (sin, cos, exp, tanh, pow, ...) are not
# glibc's: win64 takes them from msvcrt.dll and MinGW-w64's libm, whose last bits differ; the
# model's chaotic runs (impacts, the shallow-water solver) then grow those differences. Their
# outputs must stay within LIBM_TOLERANCE of each output's range over the run (the worst seen:
# 1.3e-14, docs/PLATFORMS.md); linux64 and aarch64-linux, both on glibc's libm, must agree bit
# for bit.
LIBM_DIFFERS = {"win64"}
LIBM_TOLERANCE = 1e-10


def compare(pairs, outputs):
    """The worst difference over the pairs of runs (lists of lines): in ulps, relative to the
    output's range over the run, and where (output name and step)."""
    worst_ulp, worst_rel, where = 0, 0.0, ""
    for a, b in pairs:
        for i, name in enumerate(outputs):
            xs = [value(line[i + 1]) for line in a]
            scale = max((abs(x) for x in xs), default=0.0) or 1.0
            for la, lb in zip(a, b):
                if la[i + 1] == lb[i + 1]:
                    continue
                u = ulps(la[i + 1], lb[i + 1])
                x, y = value(la[i + 1]), value(lb[i + 1])
                rel = abs(x - y) / scale
                if u > worst_ulp:
                    worst_ulp, where = u, f"{name} at step {la[0]}"
                worst_rel = max(worst_rel, rel)
    return worst_ulp, worst_rel, where


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--fmu-dir", type=Path, default=REPO / "target" / "fmu")
    ap.add_argument("--report", type=Path, help="write the summary (Markdown) here too")
    args = ap.parse_args()
    for platform, (cmd, _) in PLATFORMS.items():
        exe = Path(cmd[-1])
        if not exe.is_file():
            raise SystemExit(f"{exe} missing: scripts/cross-test builds the runners ({platform})")
    work = Path(tempfile.mkdtemp(prefix="tld-platforms-"))
    libs = {}
    for fmu_id in ("TLD", "Building"):
        with zipfile.ZipFile(args.fmu_dir / f"{fmu_id}.fmu") as z:
            for platform, (_, inside) in PLATFORMS.items():
                name = inside.format(id=fmu_id)
                if name not in z.namelist():
                    raise SystemExit(f"{fmu_id}.fmu has no {name}: scripts/package --all-platforms")
                z.extract(name, work / platform)
                libs[platform, fmu_id] = work / platform / name
    all_scenes = scenes(args.fmu_dir, args.steps)
    failures, rows, state_runs = [], [], 0
    t0 = time.monotonic()
    save_at = args.steps // 2
    pool = ThreadPoolExecutor(max_workers=len(PLATFORMS))
    for label, fmu_id, text, outputs in tqdm(all_scenes, desc="scenes", unit="scene"):
        scene = work / (label.replace(" ", "_") + ".scene")
        scene.write_text(text)
        # the runs are independent processes, mostly waiting on the emulators' start-up:
        # run side by side
        full = dict(zip(PLATFORMS, pool.map(
            lambda p: run(p, libs[p, fmu_id], scene,
                          ["--save", save_at, work / f"{scene.stem}.{p}.state"]), PLATFORMS)))
        states = {p: (work / f"{scene.stem}.{p}.state").read_bytes() for p in PLATFORMS}
        for p in PLATFORMS:
            if len(full[p]) != args.steps:
                failures.append(f"{label}: {p} printed {len(full[p])} steps, not {args.steps}")
        # the state saved by each platform, restored and continued on every platform; on its
        # own platform the continuation must be the uninterrupted run's, bit for bit
        transfers = [(saved, p) for saved in PLATFORMS for p in PLATFORMS]
        cont = dict(zip(transfers, pool.map(
            lambda sp: run(sp[1], libs[sp[1], fmu_id], scene,
                           ["--restore", save_at, work / f"{scene.stem}.{sp[0]}.state"]),
            transfers)))
        state_runs += len(transfers)
        for saved in PLATFORMS:
            if cont[saved, saved] != full[saved][save_at:]:
                failures.append(f"{label}: state restored on {saved} departs from its own run")
        cells = []
        for p in PLATFORMS:
            if p == "linux64":
                continue
            # p against linux64: the whole runs, and each state's continuations
            pairs = [(full["linux64"], full[p])] + \
                [(cont[s, "linux64"], cont[s, p]) for s in PLATFORMS]
            worst_ulp, worst_rel, where = compare(pairs, outputs)
            if states[p] == states["linux64"]:
                same_state = "state bytes equal"
            else:
                same_state = "state bytes differ"
            if worst_ulp == 0:
                cells.append(f"bit-identical, {same_state}")
                continue
            cells.append(f"{worst_ulp} ulp, {worst_rel:.1e} of range ({where}), {same_state}")
            if p not in LIBM_DIFFERS:
                failures.append(f"{label}: {p} differs from linux64 by {worst_ulp} ulp ({where})")
            elif worst_rel > LIBM_TOLERANCE:
                failures.append(f"{label}: {p} differs from linux64 by {worst_rel:.1e} of the "
                                f"output's range ({where}), more than {LIBM_TOLERANCE}")
        rows.append(f"| {label} | {len(outputs)} | {args.steps} | " + " | ".join(cells) + " |")
    summary = "\n".join([
        f"cross-platform check (scripts/platforms.py --steps {args.steps}): "
        f"{len(all_scenes)} scenes on {', '.join(PLATFORMS)}, {state_runs} state transfers "
        f"(saved at step {save_at} on each platform, continued on each), "
        f"{time.monotonic() - t0:.0f} s",
        "",
        "| scene | outputs | steps | win64 vs linux64 | aarch64-linux vs linux64 |",
        "|---|---|---|---|---|",
        *rows,
    ])
    print(summary)
    if args.report:
        args.report.write_text(summary + "\n")
    if failures:
        print("\n".join(["FAILED:"] + failures), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
