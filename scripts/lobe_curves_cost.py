#!/usr/bin/python3
"""The a/D = 0.05 milling lobe diagram (5000-25000 rpm) as a grid chart and as curves, side by side
(issue 36, item 2): `chart data/scenes/milling_lobes.toml` (200 x 100 points, N = 200, one thread,
error_bars = off: |mu_1| at N alone, as the curves' levels give their own bars; no --out, so that
neither's time includes writing files) and `boundary
data/scenes/milling_lobes_curves.toml` (one thread; a start at 40 speeds, every lobe followed, each point
extrapolated from the levels of boundary_Ns: the scene's N = 100, 200, 400, and any other sets
given with --levels), run in turn so that a drift of the machine's speed falls on all. Printed
with the date, the load and the machine: each one's wall time (median) and its ratio to the
chart's, and its boundary accuracy: the chart's half a depth row (the boundary's place within the
grid; its N's own error comes on top), the curves' largest and median error estimates in depth
and in speed, the share of curve points that have one, how many are within issue 36's aim (1e-6
mm), and where the curves' time goes (the starts' search, the tracing, the error bars: the
command's own phase times, last run). The chart is also timed at its defaults (error_bars = on:
each |mu_1| with its bar and verdict, as the curves' points carry theirs), for the ratio to that.

    scripts/lobe_curves_cost.py [--delayspec build/delayspec] [--runs 3] [--levels 50,100,200 200,400,800]"""
import argparse
import json
import os
import statistics
import subprocess
import time

from machine_stamp import machine_stamp

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "data", "scenes")
SCENE_LEVELS = "100,200,400"  # milling_lobes_curves.toml's boundary_Ns
AIM = 1e-9  # m: issue 36's aim for every point's error estimate, 1e-6 mm


def timed(cmd):
    """Wall seconds of cmd, and what it printed."""
    t0 = time.perf_counter()
    done = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return time.perf_counter() - t0, done.stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--delayspec", default="build/delayspec")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--levels", nargs="*", default=[], help="more boundary_Ns sets, e.g. 200,400,800")
    args = ap.parse_args()
    level_sets = [SCENE_LEVELS] + [levels for levels in args.levels if levels != SCENE_LEVELS]
    print(machine_stamp(f"{args.runs} runs each, in turn"))
    chart_times, chart_bar_times, curve_times, results = [], [], {levels: [] for levels in level_sets}, {}
    # Neither writes files (no --out): with --out the chart also writes a file per point for
    # --resume (20000 here), seconds of system time of their own on this machine.
    for i in range(args.runs):
        seconds, _ = timed([args.delayspec, "chart", os.path.join(SCENES, "milling_lobes.toml"), "--quiet",
                            "--set", "threads=1", "--set", "error_bars=off"])
        chart_times.append(seconds)
        seconds, _ = timed([args.delayspec, "chart", os.path.join(SCENES, "milling_lobes.toml"), "--quiet",
                            "--set", "threads=1"])
        chart_bar_times.append(seconds)
        for levels in level_sets:
            finest = levels.split(",")[-1]
            seconds, printed = timed([args.delayspec, "boundary", os.path.join(SCENES, "milling_lobes_curves.toml"),
                                      "--quiet", "--json", "--set", "threads=1", "--set", f"boundary_Ns={levels}",
                                      "--set", f"N={finest}"])
            curve_times[levels].append(seconds)
            results[levels] = json.loads(printed)
    chart = statistics.median(chart_times)
    y_range = results[SCENE_LEVELS]["y_range"]
    print(f"# {'method':44s} {'seconds':>8s} {'/chart':>7s}  boundary accuracy")
    print(f"  {'chart, 200 x 100 points, N = 200, 1 thread':44s} {chart:8.2f} {1:7.2f}  "
          f"half a depth row: {abs(y_range[1] - y_range[0]) / 99 / 2:.1e} m (plus the error at N = 200)")
    chart_bars = statistics.median(chart_bar_times)
    print(f"  {'chart, the same, error_bars = on (default)':44s} {chart_bars:8.2f} {chart_bars / chart:7.2f}  "
          f"the same, and each point's |mu_1| with its bar and verdict")
    for levels in level_sets:
        curves = results[levels]
        points = [p for c in curves["curves"] for p in c["points"]]
        with_bar = [p for p in points if p["error_estimate"] is not None]
        seconds = statistics.median(curve_times[levels])
        phases = curves["phase_seconds"]
        aim = sum(1 for p in with_bar if p["error_estimate"] <= AIM)
        print(f"  {'boundary, 40 starts, N = ' + levels.replace(',', ', '):44s} {seconds:8.2f} {seconds / chart:7.2f}  "
              f"{len(curves['curves'])} curves, {len(points)} points, {len(with_bar)} with an estimate, {aim} of "
              f"them <= {AIM:.0e} m: largest "
              f"{max(p['error_estimate'] for p in with_bar):.1e} m in depth, "
              f"{max(p['x_error_estimate'] for p in with_bar):.1e} rpm in speed; median "
              f"{statistics.median(p['error_estimate'] for p in with_bar):.1e} m, "
              f"{statistics.median(p['x_error_estimate'] for p in with_bar):.1e} rpm; "
              f"search {phases['search']:.2f} s, tracing {phases['trace']:.2f} s, error bars {phases['study']:.2f} s")
    print(f"# load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
