#!/usr/bin/env python3
"""Scores of a cargo-mutants run with and without a set of tests, from the run's own logs.

usage: scripts/mutants_without.py OUTPUT_DIR PATTERN [PATTERN...]

OUTPUT_DIR is a run's mutants.out (scripts/mutants runs cargo test with --no-fail-fast, so every
failing test of a caught mutant is in its log). A caught mutant counts as caught "without" when
at least one failing test's name contains none of the PATTERNs (e.g. `wiring_tests` and
`wiring::`: the score the tests had before issue 30's were added). Timeouts count as caught in
both columns. Prints a Markdown table per file.
"""
import collections
import json
import os
import re
import sys

if len(sys.argv) < 3 or sys.argv[1] in ("-h", "--help"):
    print(__doc__.strip())
    sys.exit(0 if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help") else 2)
out, patterns = sys.argv[1], sys.argv[2:]
outcomes = json.load(open(os.path.join(out, "outcomes.json")))["outcomes"]
failed = re.compile(r"^test (\S+) \.\.\. FAILED$")
# A test binary's name stands before its results in cargo's output: "Running tests/wiring.rs".
running = re.compile(r"^\s*Running (\S+)")
rows = collections.defaultdict(collections.Counter)
for o in outcomes:
    mutant = o["scenario"].get("Mutant") if isinstance(o["scenario"], dict) else None
    if not mutant:
        continue
    f = mutant["file"]
    kind = o["summary"]
    if kind == "CaughtMutant":
        names = []
        binary = ""
        for line in open(os.path.join(out, o["log_path"]), errors="replace"):
            m = running.match(line)
            if m:
                binary = m.group(1)
            m = failed.match(line.strip())
            if m:
                names.append(f"{binary}::{m.group(1)}")
        rows[f]["caught"] += 1
        if any(not any(p in n for p in patterns) for n in names):
            rows[f]["without"] += 1
    elif kind == "MissedMutant":
        rows[f]["missed"] += 1
    elif kind == "Timeout":
        rows[f]["timeout"] += 1
    elif kind == "Unviable":
        rows[f]["unviable"] += 1

print(f"| file | viable | caught or timed out | score | without {', '.join(patterns)} | score without |")
print("| --- | ---: | ---: | ---: | ---: | ---: |")
total = collections.Counter()
for f in sorted(rows):
    c = rows[f]
    viable = c["caught"] + c["missed"] + c["timeout"]
    caught = c["caught"] + c["timeout"]
    before = c["without"] + c["timeout"]
    total.update({"viable": viable, "caught": caught, "before": before})
    if viable:
        print(f"| {f} | {viable} | {caught} | {100 * caught / viable:.1f} % | {before} | {100 * before / viable:.1f} % |")
v = total["viable"]
if v:
    print(f"| all | {v} | {total['caught']} | {100 * total['caught'] / v:.1f} % | {total['before']} | {100 * total['before'] / v:.1f} % |")
