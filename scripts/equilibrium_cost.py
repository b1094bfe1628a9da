#!/usr/bin/python3
"""What `delayspec equilibrium` costs a user (issue 35: under 20 ms whole process for d <= 4 and a
few delays, 6 refined roots): the whole process, start to exit, timed for each case in turn
(a, b, c, a, b, c, ...) so that a drift of the machine's speed falls on all; the median and the
largest of the runs are printed with the date, the load and the machine, beside the program's own
`seconds` (its computation alone).

    scripts/equilibrium_cost.py [--delayspec build/delayspec] [--runs 21]

The equation scene is compiled once before the timing (a compiled model is cached: what a user
waits for on every later run)."""
import argparse
import json
import os
import statistics
import subprocess
import time

from machine_stamp import machine_stamp

HERE = os.path.dirname(os.path.abspath(__file__))
CASES = [
    ("linear, d = 1, 1 delay", ["--set", "model=linear", "--set", "b=-3"]),
    ("mackey-glass, d = 1, 1 delay", ["--set", "model=mackey-glass", "--set", "equilibrium_guess=1.2"]),
    ("neuron ring (equations), d = 4, 3 delays", [os.path.join(HERE, "..", "data", "scenes", "equilibrium_neuron_ring.toml")]),
]


def run(delayspec, args):
    start = time.perf_counter()
    out = subprocess.run([delayspec, "equilibrium", "--json", *args], check=True, capture_output=True, text=True).stdout
    return time.perf_counter() - start, json.loads(out)["seconds"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--delayspec", default="build/delayspec")
    ap.add_argument("--runs", type=int, default=21)
    args = ap.parse_args()
    for _, case in CASES:
        run(args.delayspec, case)  # compiles the equation model once; warms the file cache
    wall = {name: [] for name, _ in CASES}
    own = {name: [] for name, _ in CASES}
    for _ in range(args.runs):
        for name, case in CASES:
            w, s = run(args.delayspec, case)
            wall[name].append(w * 1e3)
            own[name].append(s * 1e3)
    print(machine_stamp(f"{args.runs} runs each, N = 100, nroots = 6"))
    print(f"# {'case':42s} {'whole process ms':>17s} {'(largest)':>10s} {'computation ms':>15s}")
    for name, _ in CASES:
        print(f"  {name:42s} {statistics.median(wall[name]):17.1f} {max(wall[name]):10.1f} "
              f"{statistics.median(own[name]):15.2f}")
    base = []
    for _ in range(args.runs):
        start = time.perf_counter()
        subprocess.run(["/bin/true"], check=True)
        base.append((time.perf_counter() - start) * 1e3)
    print(f"  {'(starting /bin/true from here, for scale)':42s} {statistics.median(base):17.1f} {max(base):10.1f}")
    print(f"# load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
