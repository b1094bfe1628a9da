#!/usr/bin/python3
"""What a second delay costs (issue 34): bench/bench_several_delays's one-delay and two-delay
cases (the same d = 2 oscillator, N = 1000 steps per the longest delay), run in turn (one, two,
one, two, ...) so that a drift of the machine's speed falls on both, the ratio two / one taken pair
by pair; the median of the ratios is printed with the date, the load and the machine.

    scripts/several_delays_cost.py [--bench build/bench_several_delays] [--runs 5]

Rows: the fused Lyapunov step (two tangent vectors, QR excluded: ns per step), the monodromy
applied to one vector and to a block of 8 (ns per step per vector)."""
import argparse
import json
import os
import statistics
import subprocess

from machine_stamp import machine_stamp

CASES = [
    ("Lyapunov step, 2 exponents", "LyapunovStep{}$", "step_ns"),
    ("apply, 1 vector", "Apply{}/1$", "ns_per_step_vector"),
    ("apply_block, 8 vectors", "Apply{}/8$", "ns_per_step_vector"),
]


def measure(bench, pattern, counter):
    out = subprocess.run([bench, f"--benchmark_filter={pattern}", "--benchmark_format=json"], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)["benchmarks"][0][counter]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bench", default="build/bench_several_delays")
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    print(machine_stamp(f"{args.runs} pairs, N = 1000"))
    print(f"# {'case':28s} {'one delay':>10s} {'two delays':>11s} {'ratio':>6s} (range)")
    for name, pattern, counter in CASES:
        one, two, ratios = [], [], []
        for _ in range(args.runs):
            a = measure(args.bench, pattern.format("OneDelay"), counter)
            b = measure(args.bench, pattern.format("TwoDelays"), counter)
            one.append(a)
            two.append(b)
            ratios.append(b / a)
        print(f"  {name:28s} {statistics.median(one):10.2f} {statistics.median(two):11.2f} "
              f"{statistics.median(ratios):6.2f} ({min(ratios):.2f}-{max(ratios):.2f})")
    print(f"# load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
