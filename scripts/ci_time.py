#!/usr/bin/python3
"""What CI waits for: `scripts/test.sh` (the README's second command, which `.ci/run` runs) in a
fresh clone of this repository at REV, with ccache disabled (a CI machine starts cold), the
packages already installed. Prints the date, the load, the machine, then the wall time of each
phase, found by the lines ctest prints: the Release build, its tests, the install checks and
the sanitizer build, the sanitizer tests; the whole script's wall and CPU time. CI's budget is
45 minutes on 2 cores.

    scripts/ci_time.py [--rev HEAD] [--source .]"""
import argparse
import os
import subprocess
import time

from fresh_clone import children_cpu_seconds, cold_environment, fresh_clone
from machine_stamp import machine_stamp


def measure(source, rev):
    with fresh_clone(source, rev, "delayspec_ci_time_") as clone:
        env = cold_environment()
        before = children_cpu_seconds()
        start = time.monotonic()
        marks = []  # (what, seconds since start): each ctest's start and end
        tail = []
        p = subprocess.Popen(["bash", os.path.join(clone, "scripts", "test.sh")], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        for line in p.stdout:
            tail = (tail + [line])[-40:]
            if line.startswith("Test project "):
                marks.append(("start", time.monotonic() - start))
            elif line.startswith("Total Test time"):
                marks.append(("end", time.monotonic() - start))
        p.wait()
        total = time.monotonic() - start
        cpu = children_cpu_seconds() - before
        if p.returncode != 0 or [m[0] for m in marks] != ["start", "end", "start", "end"]:
            raise SystemExit(f"test.sh at {rev} exited {p.returncode}; its last lines:\n" + "".join(tail))
        t = [m[1] for m in marks]
        return [("Release build", t[0]), ("Release tests", t[1] - t[0]),
                ("install checks + sanitizer build", t[2] - t[1]), ("sanitizer tests", t[3] - t[2]),
                ("whole script", total), ("CPU of everything", cpu)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rev", default="HEAD", help="revision to clone (default HEAD)")
    ap.add_argument("--source", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    args = ap.parse_args()
    label = subprocess.run(["git", "-C", args.source, "rev-parse", "--short", args.rev], check=True,
                           capture_output=True, text=True).stdout.strip()
    print(machine_stamp(f"scripts/test.sh at {label}: fresh clone, ccache disabled, packages installed"))
    for what, seconds in measure(args.source, args.rev):
        print(f"  {what:34s} {seconds:6.0f} s")
    print(f"# load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
