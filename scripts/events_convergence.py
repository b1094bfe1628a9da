#!/usr/bin/env python3
"""Convergence of the leading Floquet multiplier on the paper's period-1 orbit with impacts
(tau = T, e = 1.26, k = 1 by default) against N, for several contact_substeps and events off.
Reproduces the convergence table of docs/events.md. Calls build/delayspec (or $DELAYSPEC);
the reference is the Richardson value (order 2) of the finest two N of the largest m.

  /usr/bin/python3 scripts/events_convergence.py [--k 1] [--Ns 400,...,25600] [--ms 1,2,4,8]
"""
import argparse, json, math, os, subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("DELAYSPEC", os.path.join(ROOT, "build", "delayspec"))


def leading(k, N, extra):
    args = [BIN, "floquet", os.path.join(ROOT, "data/scenes/default.toml"), "--set", f"k={k}", "--set", f"N={N}",
            "--set", "orbit=newton", "--set", "orbit_guess_periods=30", "--set", "nev=2", "--json"]
    for e in extra:
        args += ["--set", e]
    p = subprocess.run(args, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(args)}: exit {p.returncode}: {p.stderr.strip()}")
    m = json.loads(p.stdout)["multipliers"][0]
    return complex(m["re"], abs(m["im"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--k", default="1")
    ap.add_argument("--Ns", default="400,800,1600,3200,6400,12800,25600")
    ap.add_argument("--ms", default="1,2,4,8")
    a = ap.parse_args()
    Ns = [int(x) for x in a.Ns.split(",")]
    runs = {f"m={m}": [f"contact_substeps={m}"] for m in a.ms.split(",")}
    runs["off"] = ["events=off"]
    mu = {label: [leading(a.k, N, extra) for N in Ns] for label, extra in runs.items()}
    finest = mu[f"m={a.ms.split(',')[-1]}"]
    ref = finest[-1] + (finest[-1] - finest[-2]) / 3
    print(f"reference (Richardson of {list(runs)[-2]} at N = {Ns[-2]}, {Ns[-1]}): {ref.real:.10f} + {ref.imag:.10f}i, "
          f"|mu_1| = {abs(ref):.10f}")
    print("| N | " + " | ".join(runs) + " |")
    for i, N in enumerate(Ns):
        print(f"| {N} | " + " | ".join(f"{abs(mu[l][i] - ref):.2e}" for l in runs) + " |")
    for l in runs:
        e = [abs(z - ref) for z in mu[l]]
        two = " ".join(f"{math.log2(e[i] / e[i + 1]):.2f}" for i in range(len(e) - 1))
        d = [abs(mu[l][i] - mu[l][i + 1]) for i in range(len(Ns) - 1)]
        three = " ".join(f"{math.log2(d[i] / d[i + 1]):.2f}" for i in range(len(d) - 1))
        en2 = [x * N * N for x, N in zip(e, Ns)]
        print(f"{l}: two-point orders {two}; three-point {three}; e N^2 in [{min(en2):.0f}, {max(en2):.0f}]")


if __name__ == "__main__":
    main()
