#!/usr/bin/python3
"""What a newcomer waits for (issue 37): `scripts/run-default.sh` in a fresh clone of this
repository at REV, with ccache disabled (as on a machine that never built delayspec), the
packages already installed. Prints the date, the load, the machine, then the wall time until
the multipliers are printed, the whole script's wall time (the Python module included) and the
CPU seconds of everything it ran.

    scripts/first_number_time.py [--rev HEAD] [--source .]

Several --rev values are measured one after the other in the same run (before and after)."""
import argparse
import os
import subprocess
import time

from fresh_clone import children_cpu_seconds, cold_environment, fresh_clone
from machine_stamp import machine_stamp


def measure(source, rev):
    with fresh_clone(source, rev, "delayspec_first_number_") as clone:
        env = cold_environment()
        before = children_cpu_seconds()
        start = time.monotonic()
        first = None
        p = subprocess.Popen(["bash", os.path.join(clone, "scripts", "run-default.sh")], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        for line in p.stdout:
            if first is None and "Floquet multipliers" in line:
                first = time.monotonic() - start
        p.wait()
        total = time.monotonic() - start
        cpu = children_cpu_seconds() - before
        if p.returncode != 0:
            raise SystemExit(f"run-default.sh at {rev} exited {p.returncode}")
        return first, total, cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rev", action="append", help="revision to clone (repeatable; default HEAD)")
    ap.add_argument("--source", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    args = ap.parse_args()
    revs = args.rev or ["HEAD"]
    print(machine_stamp("fresh clone, ccache disabled, packages installed"))
    print(f"# {'revision':12s} {'multipliers (s)':>16s} {'whole script (s)':>17s} {'CPU (s)':>8s}")
    for rev in revs:
        label = subprocess.run(["git", "-C", args.source, "rev-parse", "--short", rev], check=True,
                               capture_output=True, text=True).stdout.strip()
        first, total, cpu = measure(args.source, rev)
        print(f"  {label:12s} {first if first is not None else float('nan'):16.0f} {total:17.0f} {cpu:8.0f}")
    print(f"# load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
