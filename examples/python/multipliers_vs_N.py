#!/usr/bin/env python3
"""The leading Floquet multipliers of the soft-impact oscillator's period-1 orbit
(data/scenes/default.toml, k = 0.2) at several resolutions N, side by side with their change
from the previous N: the discretisation converges at second order, so once N resolves the orbit
(here from N = 400 on) each doubling of N shrinks the change about fourfold (docs/design.md).
delayspec.converge does this study with Richardson extrapolation; this script shows the plain
loop over delayspec.floquet.

    python3 examples/python/multipliers_vs_N.py                 # N = 200 400 800 1600 (a second)
    python3 examples/python/multipliers_vs_N.py --Ns 20 40 80   # seconds

Needs the module on the path: PYTHONPATH=build/python (after the build) or an installed package.
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import delayspec  # noqa: E402

SCENE = pathlib.Path(__file__).resolve().parents[2] / "data" / "scenes" / "default.toml"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=str(SCENE), help="scene file (default: data/scenes/default.toml)")
    parser.add_argument("--Ns", type=int, nargs="+", default=[200, 400, 800, 1600], help="the resolutions")
    parser.add_argument("--nev", type=int, default=4, help="multipliers per N")
    parser.add_argument("--output", default="multipliers_vs_N.png", help="the figure (PNG)")
    args = parser.parse_args()

    rows = np.array([delayspec.floquet(args.scene, N=N, nev=args.nev).multipliers for N in args.Ns])  # (Ns, nev)
    print(f"{'N':>6}  " + "  ".join(f"{'mu_' + str(i + 1):>30}" for i in range(args.nev)) + "   |change of mu_1|")
    for j, N in enumerate(args.Ns):
        change = f"{abs(rows[j, 0] - rows[j - 1, 0]):.3e}" if j else ""
        print(f"{N:6d}  " + "  ".join(f"{mu.real:+.12f}{mu.imag:+.12f}j" for mu in rows[j]) + f"   {change}")

    fig, ax = plt.subplots(figsize=(5, 5))
    circle = np.exp(1j * np.linspace(0, 2 * np.pi, 400))
    ax.plot(circle.real, circle.imag, color="gray", linewidth=0.5)
    for j, N in enumerate(args.Ns):
        ax.plot(rows[j].real, rows[j].imag, "o", markersize=8 - 6 * j / max(1, len(args.Ns) - 1),
                fillstyle="none", label=f"N = {N}")
    ax.set_aspect("equal")
    ax.set_xlabel("Re mu")
    ax.set_ylabel("Im mu")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
