#!/usr/bin/env python3
"""The paper's Fig. 6.2: the two leading Lyapunov exponents (per forcing period) of the
soft-impact oscillator with delayed feedback (tau = T) against the gain k, with the Poincare
section x(jT) above them: delayspec.sweep on data/scenes/fig6_2.toml, plotted with matplotlib.

    python3 examples/python/fig6_2_exponents.py                      # the figure's resolution (minutes)
    python3 examples/python/fig6_2_exponents.py --N 40 --points 8 --transient 50 --periods 100  # seconds

Needs the module on the path: PYTHONPATH=build/python (after the build) or an installed package.
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import delayspec  # noqa: E402

SCENE = pathlib.Path(__file__).resolve().parents[2] / "data" / "scenes" / "fig6_2.toml"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=str(SCENE), help="scene file (default: data/scenes/fig6_2.toml)")
    parser.add_argument("--N", type=int, help="steps per delay (scene: 400)")
    parser.add_argument("--points", type=int, help="values of k (scene: 71)")
    parser.add_argument("--transient", type=int, help="periods discarded (scene: 1000)")
    parser.add_argument("--periods", type=int, help="periods averaged (scene: 2000)")
    parser.add_argument("--output", default="fig6_2_exponents.png", help="the figure (PNG)")
    args = parser.parse_args()

    # None leaves a key at the scene's value.
    r = delayspec.sweep(args.scene, N=args.N, sweep_points=args.points, transient=args.transient,
                        periods=args.periods)
    k = r.parameter                    # (points,)
    exponents = r.exponents_per_period  # (points, 2): lambda_1, lambda_2 per forcing period
    errors = r.standard_error_per_period

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    section = r.section_x              # (points, section_points): x(jT) after the transient
    top.plot(np.repeat(k, section.shape[1]), section.ravel(), ",k")
    top.set_ylabel("x(jT)")
    for i in range(exponents.shape[1]):
        bottom.errorbar(k, exponents[:, i], yerr=errors[:, i], marker=".", capsize=2, label=f"$\\lambda_{i + 1}$")
    bottom.axhline(0, color="gray", linewidth=0.5)
    bottom.set_xlabel("k")
    bottom.set_ylabel("Lyapunov exponent per period")
    bottom.legend()
    fig.suptitle(f"soft-impact oscillator, tau = T, N = {r.N}")
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)

    print(f"{'k':>8} {'lambda_1':>12} {'lambda_2':>12}")
    for kk, (l1, l2) in zip(k, exponents):
        print(f"{kk:8.3f} {l1:12.5f} {l2:12.5f}")
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
