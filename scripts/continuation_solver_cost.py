#!/usr/bin/python3
"""Continuation's two correctors side by side (issue 36, items 3 and 4): the sparse LU of the
bordered system and GMRES on it condensed onto the map's history (continue_solver = lu, krylov),
on a fractional delay (data/scenes/continue_pwsdde_k.toml: tau = 3.8, the period-2 orbit) and an
aligned one (data/scenes/continue_tau_half_k.toml: tau = T / 2), one N at a time, in turn, so
that a drift of the machine's speed falls on both. Printed with the date, the load and the
machine, per scene and N: the unknowns d K, each solver's branch time (cost_finest_N's
branch_seconds, median of the runs), the ratio, the factorisations and GMRES products, and how
far the two branches are apart (largest difference of the points' parameters and of the located
bifurcations, when both have the same points). Then the whole command with the issue's levels,
`continue_Ns = 200, 400, 800`, with each solver, and with krylov at 400, 800, 1600, 3200; and
(--large alone, or in the full run) the PWSDDE branch at 3200, 6400, 12800, 25600 (d K up to
211644; orbit = auto: nested shooting, no matrix factored above its coarsest level).

    scripts/continuation_solver_cost.py [--delayspec build/delayspec] [--runs 3] [--quick | --large]"""
import argparse
import json
import os
import statistics
import subprocess
import time

from machine_stamp import machine_stamp

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "data", "scenes")
FRACTIONAL, ALIGNED = "continue_pwsdde_k.toml", "continue_tau_half_k.toml"


def run(delayspec, scene, settings):
    cmd = [delayspec, "continue", os.path.join(SCENES, scene), "--json", "--quiet"]
    for key, value in settings.items():
        cmd += ["--set", f"{key}={value}"]
    t0 = time.perf_counter()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out), time.perf_counter() - t0


def apart(a, b):
    """Largest difference of the points' parameters and of the bifurcations' (finest N), or None."""
    pa, pb = [p["parameter"] for p in a["points"]], [p["parameter"] for p in b["points"]]
    ba, bb = a["bifurcations"], b["bifurcations"]
    if len(pa) != len(pb) or [x["type"] for x in ba] != [x["type"] for x in bb]:
        return None
    points = max(abs(x - y) for x, y in zip(pa, pb))
    located = max([abs(x["parameter"] - y["parameter"]) for x, y in zip(ba, bb)] +
                  [abs(u["parameter"] - v["parameter"]) for x, y in zip(ba, bb) for u, v in zip(x["by_N"], y["by_N"])],
                  default=0.0)
    return points, located


def per_N(args, scene, Ns):
    print(f"# {scene}: one N, continue_Ns = N")
    print(f"# {'N':>5s} {'d K':>6s} {'lu s':>8s} {'krylov s':>9s} {'ratio':>6s} {'LUs':>5s} {'products':>8s} "
          f"{'points apart':>12s} {'located apart':>13s}")
    for N in Ns:
        times = {"lu": [], "krylov": []}
        last = {}
        for _ in range(args.runs):
            for solver in ("lu", "krylov"):
                result, _ = run(args.delayspec, scene, {"continue_solver": solver, "continue_Ns": N, "N": N})
                times[solver].append(result["cost_finest_N"]["branch_seconds"])
                last[solver] = result
        lu, kr = statistics.median(times["lu"]), statistics.median(times["krylov"])
        unknowns = last["lu"]["cost_finest_N"]["unknowns"]
        d = apart(last["lu"], last["krylov"])
        gap = f"{d[0]:12.1e} {d[1]:13.1e}" if d else f"{'differ':>12s} {'':>13s}"
        print(f"  {N:5d} {unknowns:6d} {lu:8.3f} {kr:9.3f} {lu / kr:6.1f} "
              f"{last['lu']['cost_finest_N']['factorisations']:5d} {last['krylov']['cost_finest_N']['gmres_products']:8d} "
              f"{gap}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--delayspec", default="build/delayspec")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="one run, N up to 400, no whole commands")
    ap.add_argument("--large", action="store_true", help="only the PWSDDE branch at N up to 25600")
    args = ap.parse_args()
    if args.quick:
        args.runs = 1
    print(machine_stamp(f"{args.runs} run(s) each, the solvers in turn"))
    if args.large:
        return large(args)
    Ns = [25, 50, 100, 200, 400] + ([] if args.quick else [800])
    per_N(args, FRACTIONAL, Ns)
    per_N(args, ALIGNED, Ns)
    if args.quick:
        return
    print("# the whole command (wall seconds): data/scenes/continue_pwsdde_k.toml")
    lu, lu_s = run(args.delayspec, FRACTIONAL, {"continue_solver": "lu", "continue_Ns": "200,400,800"})
    kr, kr_s = run(args.delayspec, FRACTIONAL, {"continue_solver": "krylov", "continue_Ns": "200,400,800"})
    fine, fine_s = run(args.delayspec, FRACTIONAL, {"continue_solver": "krylov", "continue_Ns": "400,800,1600,3200"})
    d = apart(lu, kr)
    print(f"  continue_Ns = 200,400,800           lu {lu_s:8.2f}   krylov {kr_s:6.2f}   ratio {lu_s / kr_s:5.1f}   "
          f"apart: points {d[0]:.1e}, located {d[1]:.1e}" if d else "  the branches differ")
    print(f"  continue_Ns = 400,800,1600,3200     krylov {fine_s:6.2f}")
    for b in fine["bifurcations"]:
        print(f"    {b['type']:16s} {b['extrapolated']:.12f} +- {b['error_estimate']:.1e} (order {b['observed_order']:.2f})"
              f"   with 200,400,800: +- {next(x['error_estimate'] for x in kr['bifurcations'] if x['type'] == b['type']):.1e}")
    large(args)


def large(args):
    """The PWSDDE branch with krylov at large N, its bifurcations with their error bars."""
    Ns = "3200,6400,12800,25600"
    result, seconds = run(args.delayspec, FRACTIONAL, {"continue_solver": "krylov", "orbit": "auto", "continue_Ns": Ns})
    cost = result["cost_finest_N"]
    print(f"# data/scenes/continue_pwsdde_k.toml, continue_Ns = {Ns}, orbit = auto, krylov")
    print(f"  wall {seconds:.2f} s; finest N: d K = {cost['unknowns']}, branch {cost['branch_seconds']:.2f} s, "
          f"{cost['newton_iterations']} corrector iterations, {cost['gmres_products']} GMRES products, "
          f"{cost['factorisations']} factorisations")
    for b in result["bifurcations"]:
        print(f"    {b['type']:16s} {b['extrapolated']:.12f} +- {b['error_estimate']:.1e} (order {b['observed_order']:.2f})")
    print(f"# load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
