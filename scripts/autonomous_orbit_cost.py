#!/usr/bin/python3
"""What an orbit of unknown period costs at large N against a forced orbit of the same size
(issue 35: an autonomous orbit and its top 6 multipliers at N = 10^5 within 2x the time of a
forced orbit of the same size). `floquet` at N = 10^5 without error bars, nev = 6, whole process,
each case in turn (a, b, c, a, ...) so that a drift of the machine's speed falls on all; the
median of the runs with the date, the load and the machine, and the program's own `seconds`.

    scripts/autonomous_orbit_cost.py [--delayspec build/delayspec] [--runs 7] [--N 100000]

The cases, all d = 1 with the delay tau = 8, K = N P / tau steps per period and a history of
n = N + 1 entries:
  Mackey-Glass, built-in, autonomous: period_guess = P (the orbit's period is 25.766)
  Mackey-Glass as equations, autonomous: the same, period_guess = P
  Mackey-Glass as equations, forced: + 0.01 cos(2 pi t / P), period P, the orbit locked to it
with P = 25.77. The equation scenes are written to a temporary directory and compiled once
before the timing (a compiled model is cached: what a user waits for on every later run)."""
import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time

from machine_stamp import machine_stamp

P = 25.77
SCENE = """model = "equations"
x0 = 1.1
[equations]
state = ["x"]
parameters = {{ beta = 0.2, gamma = 0.1, n = 10, tau = 8, P = {P}, eps = {eps} }}
period = "P"
delay = "tau"
rhs = ["beta*x_tau/(1 + x_tau^n) - gamma*x{forcing}"]
history = {{ x = 1.1 }}
"""


def cases(directory):
    autonomous = os.path.join(directory, "mackey_glass_autonomous.toml")
    forced = os.path.join(directory, "mackey_glass_forced.toml")
    with open(autonomous, "w") as f:
        f.write(SCENE.format(P=P, eps=0, forcing=""))
    with open(forced, "w") as f:
        f.write(SCENE.format(P=P, eps=0.01, forcing=" + eps*cos(2*pi*t/P)"))
    guess = ["--set", f"period_guess={P}"]
    return [
        ("mackey-glass (built-in), autonomous", ["--set", "model=mackey-glass", "--set", "tau=8", "--set", "x0=1.1", *guess]),
        ("mackey-glass (equations), autonomous", [autonomous, *guess]),
        ("mackey-glass (equations), forced", [forced]),
    ]


def run(delayspec, args, N):
    start = time.perf_counter()
    out = subprocess.run([delayspec, "floquet", *args, "--json", "--set", f"N={N}", "--set", "error_bars=off",
                          "--set", "nev=6"], check=True, capture_output=True, text=True).stdout
    j = json.loads(out)
    return time.perf_counter() - start, j


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--delayspec", default="build/delayspec")
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--N", type=int, default=100000)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as directory:
        todo = cases(directory)
        first = {}
        for name, case in todo:
            first[name] = run(args.delayspec, case, args.N)[1]  # compiles the equation models once
        wall = {name: [] for name, _ in todo}
        own = {name: [] for name, _ in todo}
        for _ in range(args.runs):
            for name, case in todo:
                w, j = run(args.delayspec, case, args.N)
                wall[name].append(w)
                own[name].append(j["seconds"])
    print(machine_stamp(f"{args.runs} runs each, N = {args.N}, nev = 6, error_bars = off"))
    print(f"# {'case':40s} {'n':>8s} {'orbit':>9s} {'whole s':>8s} {'(largest)':>10s} {'own s':>7s}  mu_1")
    for name, _ in todo:
        j = first[name]
        n = j["dimension"]  # the history's size, d (M + 1)
        method = j["orbit"]["method"].split(" ")[0] if isinstance(j.get("orbit"), dict) else j.get("orbit_method", "")
        print(f"  {name:40s} {n:8d} {method:>9s} {statistics.median(wall[name]):8.3f} {max(wall[name]):10.3f} "
              f"{statistics.median(own[name]):7.3f}  {j['multipliers'][0]['re']:+.6f}")
    forced = statistics.median(wall["mackey-glass (equations), forced"])
    for name in ("mackey-glass (built-in), autonomous", "mackey-glass (equations), autonomous"):
        print(f"# {name} / forced: {statistics.median(wall[name]) / forced:.2f}")
    print(f"# load at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
