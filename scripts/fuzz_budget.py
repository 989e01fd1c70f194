"""Runs libFuzzer targets (built by scripts/fuzz) side by side, each for a budget of CPU
seconds, and reports what each did. CPU time, not wall time: on a shared machine a target gets
what the others leave it. A target's process is stopped with SIGINT (libFuzzer then prints its
final statistics and exits) when its user + system time reaches what is left of its budget; one
that stops early on a finding is started again on the same corpus (at most MAX_RESTARTS times),
so that a finding does not end the search.

Usage: python3 scripts/fuzz_budget.py BIN_DIR WORK_DIR SECONDS TARGET... (scripts/fuzz runs it)
"""

import os
import re
import signal
import subprocess
import sys
import time

MAX_RESTARTS = 20
TICK = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid):
    """User + system time of a running process (and of its children it waited for)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    # fields[0] is the state (field 3); utime, stime, cutime, cstime are fields 14..17.
    return sum(int(x) for x in fields[11:15]) / TICK


class Target:
    def __init__(self, name, bin_dir, work, budget):
        self.name, self.budget = name, budget
        self.binary = os.path.join(bin_dir, name)
        self.corpus = os.path.join(work, "corpus", name)
        self.artifacts = os.path.join(work, "artifacts", name)
        self.log_path = os.path.join(work, "logs", name + ".log")
        for d in (self.corpus, self.artifacts, os.path.dirname(self.log_path)):
            os.makedirs(d, exist_ok=True)
        self.log = open(self.log_path, "w")
        self.used = 0.0
        self.runs = 0
        self.execs = 0
        self.findings = []
        self.cov = self.ft = None
        self.proc = None
        self.before = set(os.listdir(self.artifacts))

    def start(self):
        self.runs += 1
        self.log.write(f"\n== run {self.runs}, {self.budget - self.used:.0f} CPU s left\n")
        self.log.flush()
        args = [self.binary, "-print_final_stats=1", "-timeout=10",
                f"-artifact_prefix={self.artifacts}/"]
        if self.name.startswith("calls_"):
            # Inputs of any length up to 2 KiB (tens of calls) from the start: libFuzzer's
            # default grows the length limit slowly from a few bytes, a couple of calls.
            args += ["-len_control=0", "-max_len=2048"]
        args.append(self.corpus)
        self.proc = subprocess.Popen(args, stdout=self.log, stderr=subprocess.STDOUT)
        self.start_used = self.used

    def stop_if_spent(self):
        if self.proc and self.start_used + cpu_seconds(self.proc.pid) >= self.budget:
            # os.kill, not Popen.send_signal (which would reap the process before os.wait4).
            os.kill(self.proc.pid, signal.SIGINT)

    def reap(self):
        """If the process ended: account for it; start it again if it stopped on a finding
        with budget left. Returns True while the target is still running."""
        if self.proc is None:
            return False
        pid, status, usage = os.wait4(self.proc.pid, os.WNOHANG)
        if pid == 0:
            return True
        self.used = self.start_used + usage.ru_utime + usage.ru_stime
        self.proc = None
        self.log.flush()
        code = os.waitstatus_to_exitcode(status)
        # 0: done, 72: interrupted (libFuzzer's -interrupted_exitcode), -2: killed by SIGINT.
        if code not in (0, 72, -2) and self.used < self.budget * 0.98 and self.runs <= MAX_RESTARTS:
            self.start()
            return True
        return False

    def summarise(self):
        text = open(self.log_path, errors="replace").read()
        # Per run: libFuzzer's final count, or (a run killed without one) its last status line.
        for run in text.split("\n== run ")[1:]:
            final = re.findall(r"stat::number_of_executed_units: (\d+)", run)
            status = re.findall(r"^#(\d+)", run, re.M)
            self.execs += int((final or status or ["0"])[-1])
        last = re.findall(r"cov: (\d+) ft: (\d+) corp: (\d+)", text)
        if last:
            self.cov, self.ft, self.corp = (int(x) for x in last[-1])
        else:
            self.corp = len(os.listdir(self.corpus))
        self.findings = sorted(set(os.listdir(self.artifacts)) - self.before)


def main():
    if any(a in ("-h", "--help") for a in sys.argv[1:]) or len(sys.argv) < 5:
        print(__doc__.strip())
        sys.exit(0 if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help") else 2)
    bin_dir, work, seconds, *names = sys.argv[1:]
    targets = [Target(n, bin_dir, work, float(seconds)) for n in names]
    wall = time.time()
    for t in targets:
        t.start()
    while True:
        running = False
        for t in targets:
            t.stop_if_spent()
            running |= t.reap()
        if not running:
            break
        time.sleep(0.5)
    wall = time.time() - wall
    rows = []
    total_cpu = total_execs = 0
    for t in targets:
        t.summarise()
        total_cpu += t.used
        total_execs += t.execs
        rows.append(f"{t.name:22} {t.used:8.0f} {t.runs:5} {t.execs:10} {t.execs / max(t.used, 1e-9):10.0f}"
                    f" {t.cov or 0:6} {t.ft or 0:6} {t.corp:6}  {len(t.findings)}"
                    + "".join(f"\n    finding: {t.artifacts}/{f}" for f in t.findings))
    print(f"{'target':22} {'CPU s':>8} {'runs':>5} {'execs':>10} {'exec/CPUs':>10} {'cov':>6} {'ft':>6} {'corpus':>6}  findings")
    print("\n".join(rows))
    print(f"total: {total_cpu:.0f} CPU s ({total_cpu / 3600:.2f} CPU-hours), {total_execs} execs,"
          f" {wall:.0f} s wall; logs in {work}/logs/")
    return 1 if any(t.findings for t in targets) else 0


if __name__ == "__main__":
    sys.exit(main())
