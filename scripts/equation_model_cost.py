#!/usr/bin/python3
"""What an equations model costs against the built-in one (issue 37 item 2): bench/bench_equations's
floquet (N = 3200) and Lyapunov (1e4 periods, N = 1000) runs of the impact model, built-in and
written as equations, and the first compilation of the equations into an empty cache. With
--before, a second bench_equations (another build, e.g. an earlier revision's) is run in turn with
this one (this, before, this, before, ...) so that a drift of the machine falls on both; ratios are
taken pair by pair and their median printed, with the date, the load and the machine.

    scripts/equation_model_cost.py [--bench build/bench_equations] [--before OTHER/bench_equations] [--runs 3]
"""
import argparse
import json
import os
import statistics
import subprocess

from machine_stamp import machine_stamp

CASES = [("floquet N = 3200", "BM_Floquet/{}/3200$", "real_time", 1e-3),
         ("lyapunov 1e4 periods, N = 1000", "BM_Lyapunov/{}/1000", "real_time", 1.0)]


def measure(bench, pattern):
    out = subprocess.run([bench, f"--benchmark_filter={pattern}", "--benchmark_format=json"], check=True,
                         capture_output=True, text=True).stdout
    b = json.loads(out)["benchmarks"][0]
    unit = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
    return b["real_time"] * unit


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bench", default="build/bench_equations")
    ap.add_argument("--before", help="another build's bench_equations, run in turn with --bench")
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    print(machine_stamp(f"{args.runs} run(s) each" + (f", --before {args.before}" if args.before else "")))
    for name, pattern, _, _ in CASES:
        builtin, equations, before, vs_builtin, vs_before = [], [], [], [], []
        for _ in range(args.runs):
            b = measure(args.bench, pattern.format(0))
            e = measure(args.bench, pattern.format(1))
            builtin.append(b)
            equations.append(e)
            vs_builtin.append(e / b)
            if args.before:
                o = measure(args.before, pattern.format(1))
                before.append(o)
                vs_before.append(e / o)
        line = (f"  {name:32s} built-in {statistics.median(builtin):8.4f} s  equations {statistics.median(equations):8.4f} s"
                f"  equations / built-in {statistics.median(vs_builtin):5.2f}")
        if args.before:
            line += f"  | before: equations {statistics.median(before):8.4f} s, now / before {statistics.median(vs_before):5.2f}"
            line += f" ({min(vs_before):.2f}-{max(vs_before):.2f})"
        print(line)
    for label, bench in [("now", args.bench)] + ([("before", args.before)] if args.before else []):
        compile_s = [measure(bench, "BM_Compile") for _ in range(args.runs)]
        print(f"  first compilation of equations_impact.toml ({label}): min {min(compile_s):.2f} s, "
              f"median {statistics.median(compile_s):.2f} s")
    print(f"# load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
