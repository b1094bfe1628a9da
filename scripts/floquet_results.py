#!/usr/bin/env python3
"""Reproduces the tables of docs/floquet-results.md with the delayspec program.

  python3 scripts/floquet_results.py paper   [--Ns 400,1600,6400] [--ks 0,0.05,...]
  python3 scripts/floquet_results.py pwsdde  [--Ns 100,200,...]
  python3 scripts/floquet_results.py k0-reference

`paper`: the paper's period-1 orbit (data/scenes/paper-period1.toml), leading multipliers
against k at each N. `pwsdde`: the period-2 benchmark orbit (data/scenes/pwsdde-period2.toml),
its two leading multipliers against N, differences between successive N, observed order and
Richardson extrapolation. `k0-reference`: the k = 0 multipliers of the paper's orbit from an
independent computation (the delay does not act at k = 0: a 2-d ODE, RK4 with the contact
boundaries located by bisection, variational equations alongside), no delayspec code involved.
Extra `--set KEY=VALUE` arguments are passed to every run (e.g. --set events=off).
"""
import argparse
import json
import math
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("DELAYSPEC", os.path.join(ROOT, "build", "delayspec"))


def floquet(scene, sets):
    args = [BIN, "floquet", os.path.join(ROOT, "data", "scenes", scene), "--json"]
    for s in sets:
        args += ["--set", s]
    p = subprocess.run(args, capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr.strip()
    return json.loads(p.stdout), None


def mu(m):
    return complex(m["re"], m["im"])


def fmt(z, digits=10):
    if abs(z.imag) < 1e-14:
        return f"{z.real:+.{digits}f}"
    return f"{z.real:+.{digits}f} {'+' if z.imag >= 0 else '-'} {abs(z.imag):.{digits}f}i"


def paper(args):
    print(f"| k | N | mu_1 | abs(mu_1) | mu_3 | abs(mu_3) | Newton it. | orbit residual |")
    print("|---|---|---|---|---|---|---|---|")
    for k in args.ks:
        for N in args.Ns:
            j, err = floquet("paper-period1.toml", [f"k={k}", f"N={N}"] + args.set)
            if j is None:
                print(f"| {k} | {N} | failed: {err} | | | | | |")
                continue
            ms = [mu(m) for m in j["multipliers"]]
            # mu_1 and mu_3: the leading member of the first and second conjugate pair / real value
            second = next((z for z in ms[1:] if abs(z - ms[0].conjugate()) > 1e-9 * abs(ms[0])), ms[1])
            o = j["orbit"]
            print(f"| {k} | {N} | {fmt(ms[0], 6)} | {abs(ms[0]):.6f} | {fmt(second, 6)} | {abs(second):.6f} | "
                  f"{o.get('newton_iterations', '-')} | {o['residual']:.1e} |")
        sys.stdout.flush()


def pwsdde(args):
    rows = []
    print("| N | h | mu_1 | mu_2 | mu_1(N) - mu_1(N/2) | mu_2(N) - mu_2(N/2) | Newton it. | seconds |")
    print("|---|---|---|---|---|---|---|---|")
    for N in args.Ns:
        j, err = floquet("pwsdde-period2.toml", [f"N={N}"] + args.set)
        if j is None:
            print(f"| {N} | failed: {err} |")
            continue
        ms = [mu(m) for m in j["multipliers"]]
        rows.append((N, ms[0], ms[1], j['h']))
        d1 = d2 = ""
        if len(rows) >= 2:
            d1 = f"{abs(rows[-1][1] - rows[-2][1]):.2e}"
            d2 = f"{abs(rows[-1][2] - rows[-2][2]):.2e}"
        print(f"| {N} | {j['h']:.3e} | {fmt(ms[0], 12)} | {fmt(ms[1], 12)} | {d1} | {d2} | "
              f"{j['orbit'].get('newton_iterations', '-')} | {j['seconds']:.2f} |")
        sys.stdout.flush()
    if len(rows) >= 3:
        print()
        print("| N | observed order mu_1 | observed order mu_2 | Richardson mu_1 | Richardson mu_2 |")
        print("|---|---|---|---|---|")
        for i in range(2, len(rows)):
            out = [str(rows[i][0])]
            for c in (1, 2):
                a, b, cc = rows[i - 2][c], rows[i - 1][c], rows[i][c]
                p = math.log2(abs(b - a) / abs(cc - b)) if abs(cc - b) > 0 and abs(b - a) > 0 else float("nan")
                out.append(f"{p:.2f}")
            for c in (1, 2):
                # h^2 extrapolation from the last two N with their actual steps (a fractional delay
                # makes h only approximately halve): mu + (mu - mu_prev) h^2 / (h_prev^2 - h^2)
                h, hp = rows[i][3], rows[i - 1][3]
                out.append(fmt(rows[i][c] + (rows[i][c] - rows[i - 1][c]) * h * h / (hp * hp - h * h), 12))
            print("| " + " | ".join(out) + " |")


# ---- k = 0 reference: the forced soft-impact ODE (no delay acts), independent of delayspec ----
ZETA, E, A, BETA, W = 0.01, 1.26, 0.7, 28.0, 0.802
T = 2 * math.pi / W


def rk4(t, y, h, region):
    def f(tt, yy):
        c = BETA if region == 1 else 0.0
        return [yy[1], A * W * W * math.sin(W * tt) - 2 * ZETA * yy[1] - yy[0] - c * (yy[0] - E),
                yy[4], yy[5], (-1 - c) * yy[2] - 2 * ZETA * yy[4], (-1 - c) * yy[3] - 2 * ZETA * yy[5]]
    k1 = f(t, y)
    k2 = f(t + h / 2, [yi + h / 2 * ki for yi, ki in zip(y, k1)])
    k3 = f(t + h / 2, [yi + h / 2 * ki for yi, ki in zip(y, k2)])
    k4 = f(t + h, [yi + h * ki for yi, ki in zip(y, k3)])
    return [yi + h / 6 * (p + 2 * q + 2 * r + s) for yi, p, q, r, s in zip(y, k1, k2, k3, k4)]


def period_map(x0, v0, steps):
    h = T / steps
    y, t, contact, region = [x0, v0, 1.0, 0.0, 0.0, 1.0], 0.0, 0.0, (1 if x0 > E else 2)
    for i in range(steps):
        t_end = (i + 1) * h
        while t < t_end - 1e-15:
            y1 = rk4(t, y, t_end - t, region)
            new_region = 1 if y1[0] > E else 2
            if new_region == region:
                contact += (t_end - t) if region == 1 else 0.0
                t, y = t_end, y1
                break
            lo, hi = 0.0, t_end - t  # a contact boundary inside: bisect on the step length
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if (1 if rk4(t, y, mid, region)[0] > E else 2) == region:
                    lo = mid
                else:
                    hi = mid
            y = rk4(t, y, hi, region)
            contact += hi if region == 1 else 0.0
            t, region = t + hi, new_region
    return y, contact


def k0_reference(args):
    print("| RK4 steps per period | x(0) | v(0) | mu_1,2 | abs(mu) | contact time |")
    print("|---|---|---|---|---|---|")
    for steps in (2000, 4000, 8000):
        x, v = -0.0566, 1.0101
        for _ in range(30):  # Newton on the 2-d period map
            y, _ = period_map(x, v, steps)
            F = (y[0] - x, y[1] - v)
            J = ((y[2] - 1, y[3]), (y[4], y[5] - 1))
            det = J[0][0] * J[1][1] - J[0][1] * J[1][0]
            dx = (-F[0] * J[1][1] + F[1] * J[0][1]) / det
            dv = (-J[0][0] * F[1] + J[1][0] * F[0]) / det
            x, v = x + dx, v + dv
            if abs(dx) + abs(dv) < 1e-14:
                break
        y, contact = period_map(x, v, steps)
        tr, det = y[2] + y[5], y[2] * y[5] - y[3] * y[4]
        disc = tr * tr / 4 - det
        m = complex(tr / 2, math.sqrt(-disc)) if disc < 0 else complex(tr / 2 + math.sqrt(disc), 0)
        print(f"| {steps} | {x:.12f} | {v:.12f} | {fmt(m, 10)} (and conjugate) | {abs(m):.10f} | {contact:.6f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("part", choices=["paper", "pwsdde", "k0-reference"])
    ap.add_argument("--Ns", default=None, help="comma-separated N values")
    ap.add_argument("--ks", default="0,0.02,0.05,0.07,0.1,0.2,0.3,0.4,0.6,0.8,1.0,1.2,1.4")
    ap.add_argument("--set", action="append", default=[], help="KEY=VALUE passed to every run")
    args = ap.parse_args()
    args.ks = [float(k) for k in args.ks.split(",")]
    default_Ns = {"paper": "400,1600", "pwsdde": "100,200,400,800,1600,3200,6400,12800,25600", "k0-reference": ""}
    args.Ns = [int(n) for n in (args.Ns or default_Ns[args.part]).split(",") if n]
    {"paper": paper, "pwsdde": pwsdde, "k0-reference": k0_reference}[args.part](args)


if __name__ == "__main__":
    main()
