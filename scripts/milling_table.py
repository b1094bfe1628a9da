#!/usr/bin/python3
"""Speed against error of delayspec and the classic discretisations, from `delayspec bench --json`
runs of the milling benchmark points (docs/milling.md).

    scripts/milling_table.py [--complex] LABEL=bench1.json [LABEL=bench2.json ...]

Prints, per point, the error of |mu_1| (`abs_error`: the stability boundary |mu_1| = 1 depends on
it; with --complex the error of the complex mu_1, phase included) and the seconds per point (eigen-solve plus, for delayspec,
forming the step maps: what a chart pays per point) of each method at each N, then, for error
targets 1e-2 .. 1e-6, the seconds of the coarsest row from which the method stays within the
target at every finer N it ran (what refining until converged costs: a coarse row that is
accurate by luck, as the erratic methods have, does not count; no interpolation: a method that
does not settle within its rows gets a dash) and the ratio to delayspec's.
"""
import json
import math
import sys

TARGETS = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
METHODS = ["arpack", "sdm0", "fdm1"]


def seconds(row):
    return row["seconds"] + (row["setup_seconds"] or 0)


def main(args):
    field = "abs_error"
    if args and args[0] == "--complex":
        field, args = "error", args[1:]
    for arg in args:
        label, path = arg.rsplit("=", 1)
        bench = json.load(open(path))
        rows = [dict(r, error=r[field]) for r in bench["rows"] if r["status"] == "ok" and r[field] is not None]
        print(f"\n#### {label}\n")
        print("| N (m) | " + " | ".join(f"{m} error | {m} s" for m in METHODS) + " |")
        print("|---|" + "---|---|" * len(METHODS))
        for N in sorted({r["N"] for r in rows}):
            cells = []
            for m in METHODS:
                r = next((r for r in rows if r["N"] == N and r["solver"] == m), None)
                cells += [f"{r['error']:.2e}", f"{seconds(r):.2e}"] if r else ["", ""]
            print(f"| {N} | " + " | ".join(cells) + " |")
        print("\n| error target | " + " | ".join(f"{m} s (N)" for m in METHODS) + " | sdm0 / delayspec | fdm1 / delayspec |")
        print("|---|" + "---|" * (len(METHODS) + 2))
        for target in TARGETS:
            best, at = {}, {}
            for m in METHODS:
                mine = sorted((r for r in rows if r["solver"] == m), key=lambda r: r["N"])
                settled = [i for i in range(len(mine)) if all(r["error"] <= target for r in mine[i:])]
                best[m] = seconds(mine[settled[0]]) if settled else math.nan
                at[m] = mine[settled[0]]["N"] if settled else None
            ratio = lambda m: f"{best[m] / best['arpack']:.2g}x" if not math.isnan(best[m] / best["arpack"]) else "-"
            cells = [f"{best[m]:.2e} ({at[m]})" if not math.isnan(best[m]) else "-" for m in METHODS]
            print(f"| {target:.0e} | " + " | ".join(cells) + f" | {ratio('sdm0')} | {ratio('fdm1')} |")


if __name__ == "__main__":
    main(sys.argv[1:])
