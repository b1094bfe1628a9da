#!/usr/bin/python3
"""What floquet's error bars cost (issue 32, item 1: aim <= 1.4x the single solve): the same
`delayspec floquet` with `error_bars = on` and `off`, run in turn (on, off, on, off, ...) so that a
drift of the machine's speed falls on both, and the ratio taken pair by pair; the median of the
ratios is printed with the date, the load and the machine, and each case's achieved bar.

    scripts/error_bar_cost.py [--delayspec build/delayspec] [--runs 7]

Cases: the impact orbit at k = 1 (tau = T), nev = 6, at N = 200 and N = 10^5 (Krylov, auto
solver), and the linear DDE at N = 200 with the dense solver."""
import argparse
import json
import statistics
import subprocess
import time

from machine_stamp import machine_stamp

CASES = [
    ("impact k=1 N=200", ["--set", "k=1", "--set", "N=200"]),
    ("impact k=1 N=100000", ["--set", "k=1", "--set", "N=100000"]),
    ("linear dense N=200", ["--set", "model=linear", "--set", "N=200", "--set", "solver=dense"]),
]


def wall(cmd):
    t0 = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return time.perf_counter() - t0, out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--delayspec", default="build/delayspec")
    ap.add_argument("--runs", type=int, default=7)
    args = ap.parse_args()
    print(machine_stamp(f"{args.runs} pairs"))
    print(f"# {'case':24s} {'off s':>8s} {'on s':>8s} {'on/off':>7s}  bar of |mu_1| at N (verdict)")
    for name, keys in CASES:
        base = [args.delayspec, "floquet", "--json", "--set", "nev=6"] + keys
        wall(base)  # warm-up: libraries in the page cache
        on_times, off_times, ratios = [], [], []
        result = None
        for _ in range(args.runs):
            t_on, out = wall(base)
            t_off, _ = wall(base + ["--set", "error_bars=off"])
            on_times.append(t_on)
            off_times.append(t_off)
            ratios.append(t_on / t_off)
            result = json.loads(out)
        bar = result["multipliers"][0].get("error_estimate")
        print(f"  {name:24s} {statistics.median(off_times):8.3f} {statistics.median(on_times):8.3f} "
              f"{statistics.median(ratios):7.2f}  {bar if bar is not None else 'none'} ({result['verdict']}, "
              f"levels {result['error_bars']['Ns']})")


if __name__ == "__main__":
    main()
