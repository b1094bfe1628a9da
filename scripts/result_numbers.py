#!/usr/bin/python3
"""Records the numbers every shipped scene and every documented command computes, and compares two
such records: the check that a change meant to move code (not numbers) left every result as it was.

    result_numbers.py record --delayspec BUILD/delayspec --source SOURCE_DIR --out NUMBERS.json
    result_numbers.py compare BEFORE.json AFTER.json [--rtol 1e-12]

`record` runs `delayspec run SCENE` for every data/scenes/*.toml (with the size overrides of
SCENE_SIZES below, so that the whole record takes a few minutes on 2 cores), then the doc-test's
commands of README.md and docs/tutorial.md (scripts/doc_test.py --keep), and flattens every JSON and
CSV file they wrote into {"file: path": value}. What depends on the machine or the moment (timings,
dates, revisions, absolute paths, memory) is left out: KEY_NOT_COMPARED.

`compare` prints every value that differs: numbers by more than rtol relative (or 1e-15 absolute,
for values at round-off), anything else at all. Exit 0 when none does, 1 otherwise. 1e-12 relative:
a move of code changes no arithmetic, so the results agree to the last bits; the margin covers a
compiler that contracts or reorders differently across the new translation units.
"""
import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile

# Smaller grids for the scenes whose full size takes minutes; every code path is still run.
SCENE_SIZES = {
    "fig6_1": ["basin_x_points=7", "basin_y_points=7"],
    "fig6_2": ["sweep_points=12"],
    "fig6_2_zoom": ["sweep_points=12"],
    "fig6_4": ["sweep_points=12"],
    "mathieu_chart": ["chart_x_points=12", "chart_y_points=12"],
    "milling_lobes": ["chart_x_points=12", "chart_y_points=8"],
    "milling_lobes_full": ["chart_x_points=12", "chart_y_points=8"],
}
KEY_NOT_COMPARED = re.compile(r"seconds|_utc|revision|wall|memory|rss|elapsed|hostname|scene$|"
                              r"delayspec_version|threads|output_directory|command_line|\bcwd\b")


def flatten(value, path, out):
    if isinstance(value, dict):
        for k, v in value.items():
            flatten(v, f"{path}.{k}" if path else k, out)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            flatten(v, f"{path}.{i}", out)
    elif not KEY_NOT_COMPARED.search(path):
        out[path] = value


def numbers_of_tree(root, prefix, out, scratch):
    """Every value of the JSON and CSV files under root, into out; the scratch directory's path,
    which differs from run to run, written as <scratch>."""
    for folder, _, files in os.walk(root):
        for name in sorted(files):
            where = os.path.join(folder, name)
            rel = prefix + os.path.relpath(where, root)
            if name.endswith(".json"):
                try:
                    with open(where, encoding="utf-8") as f:
                        data = json.load(f)
                except (OSError, ValueError) as e:
                    out[rel] = f"unreadable: {e}"
                    continue
                flat = {}
                flatten(data, "", flat)
                out.update({f"{rel}: {k}": v.replace(scratch, "<scratch>") if isinstance(v, str) else v
                            for k, v in flat.items()})
            elif name.endswith(".csv"):
                with open(where, encoding="utf-8", newline="") as f:
                    rows = list(csv.reader(l for l in f if not l.startswith("#")))
                header = rows[0] if rows else []
                for r, row in enumerate(rows[1:], start=1):
                    for c, cell in enumerate(row):
                        column = header[c] if c < len(header) else str(c)
                        if KEY_NOT_COMPARED.search(column):
                            continue
                        try:
                            out[f"{rel}: {r}.{column}"] = float(cell)
                        except ValueError:
                            out[f"{rel}: {r}.{column}"] = cell


def record(a):
    program = os.path.abspath(a.delayspec)
    source = os.path.abspath(a.source)
    numbers = {}
    with tempfile.TemporaryDirectory(prefix="delayspec_numbers_") as scratch:
        scenes = sorted(f for f in os.listdir(os.path.join(source, "data", "scenes")) if f.endswith(".toml"))
        for scene in scenes:
            name = scene[:-5]
            sets = [w for kv in SCENE_SIZES.get(name, []) for w in ("--set", kv)]
            out = os.path.join(scratch, "scenes", name)
            p = subprocess.run([program, "run", os.path.join(source, "data", "scenes", scene), "--out", out] + sets,
                               capture_output=True, text=True, timeout=1200)
            print(f"  {scene}: exit {p.returncode}", file=sys.stderr)
            numbers[f"scenes/{name}: exit"] = p.returncode
            numbers_of_tree(out, f"scenes/{name}/", numbers, scratch)
        docs = os.path.join(scratch, "docs")
        p = subprocess.run(["/usr/bin/python3", os.path.join(source, "scripts", "doc_test.py"), "--delayspec", program,
                            "--source", source, "--keep", docs, "README.md", "docs/tutorial.md"],
                           capture_output=True, text=True, timeout=1800)
        print(f"  doc-test commands: exit {p.returncode}", file=sys.stderr)
        numbers["docs: exit"] = p.returncode
        numbers_of_tree(docs, "docs/", numbers, scratch)
    with open(a.out, "w", encoding="utf-8") as f:
        json.dump(numbers, f, indent=0, sort_keys=True)
    print(f"{len(numbers)} values recorded in {a.out}")
    return 0


def agree(x, y, rtol):
    if isinstance(x, bool) or isinstance(y, bool) or not isinstance(x, (int, float)) or not isinstance(y, (int, float)):
        return x == y
    if math.isnan(x) or math.isnan(y):
        return math.isnan(x) and math.isnan(y)
    return abs(x - y) <= max(rtol * max(abs(x), abs(y)), 1e-15)


def compare(a):
    with open(a.before, encoding="utf-8") as f:
        before = json.load(f)
    with open(a.after, encoding="utf-8") as f:
        after = json.load(f)
    differ = [k for k in sorted(set(before) | set(after))
              if k not in before or k not in after or not agree(before[k], after[k], a.rtol)]
    for k in differ:
        print(f"{k}: {before.get(k, '(absent)')!r} -> {after.get(k, '(absent)')!r}")
    print(f"{len(before)} values before, {len(after)} after; {len(differ)} differ (rtol {a.rtol:g})")
    return 1 if differ else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    r = sub.add_parser("record")
    r.add_argument("--delayspec", required=True)
    r.add_argument("--source", required=True)
    r.add_argument("--out", required=True)
    c = sub.add_parser("compare")
    c.add_argument("before")
    c.add_argument("after")
    c.add_argument("--rtol", type=float, default=1e-12)
    a = parser.parse_args()
    return record(a) if a.verb == "record" else compare(a)


if __name__ == "__main__":
    sys.exit(main())
