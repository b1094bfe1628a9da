#!/usr/bin/env python3
"""Summarise a `delayspec sweep` directory: per parameter the two leading exponents (per period),
their standard errors, and the number of distinct Poincare values x(jT) among the recorded
section points (clustered at a relative tolerance of 1e-6): 1 = period-1, p = period-p,
'many' = chaotic or quasi-periodic. Prints a Markdown table; with --runs, collapses runs of equal
classification into ranges.

    python3 scripts/lyapunov_summary.py results/fig6_2 [--runs]
"""
import csv
import json
import sys
from pathlib import Path


def period_of(xs, tol=1e-6):
    distinct = []
    for x in xs:
        if not any(abs(x - d) <= tol * (1 + abs(d)) for d in distinct):
            distinct.append(x)
        if len(distinct) > 12:
            return "many"
    return str(len(distinct))


def rows(directory):
    summary = json.loads((Path(directory) / "sweep.json").read_text())
    out = []
    for p in summary["points"]:
        if "error" in p:
            out.append((p["parameter"], None, None, None, None, "failed"))
            continue
        l, se = p["exponents_per_period"], p["standard_error_per_period"]
        out.append((p["parameter"], l[0], se[0], l[1] if len(l) > 1 else None, se[1] if len(se) > 1 else None,
                    period_of(p["section_x"])))
    return summary, out


def main():
    directory = sys.argv[1]
    summary, table = rows(directory)
    print(f"sweep of {summary['sweep_key']} ({summary['model']}, N = {summary['N']}, transient {summary['transient']},"
          f" periods {summary['periods']}, {summary['seconds']:.0f} s with {summary['threads']} threads)\n")
    if "--runs" in sys.argv:
        print("| parameter range | points | distinct x(jT) | lambda1 range (per period) |")
        print("|---|---|---|---|")
        start = 0
        for i in range(1, len(table) + 1):
            if i == len(table) or table[i][5] != table[start][5]:
                seg = table[start:i]
                l1 = [r[1] for r in seg if r[1] is not None]
                lr = f"{min(l1):+.3f} .. {max(l1):+.3f}" if l1 else "-"
                print(f"| {seg[0][0]:.5g} .. {seg[-1][0]:.5g} | {len(seg)} | {seg[0][5]} | {lr} |")
                start = i
        return
    print("| parameter | lambda1 | se1 | lambda2 | se2 | distinct x(jT) |")
    print("|---|---|---|---|---|---|")
    for r in table:
        f = lambda v: "-" if v is None else f"{v:+.4f}"
        g = lambda v: "-" if v is None else f"{v:.1e}"
        print(f"| {r[0]:.5g} | {f(r[1])} | {g(r[2])} | {f(r[3])} | {g(r[4])} | {r[5]} |")


if __name__ == "__main__":
    main()
