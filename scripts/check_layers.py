#!/usr/bin/python3
"""Fails on an include that runs up a layer (docs/design.md, "The layers").

    check_layers.py [SOURCE_DIR]

Each folder of src/ has a level; a file may include a header of its own folder or of a folder
of a lower level, never one of the same level elsewhere or of a higher level. So the folders form
a graph without a cycle whose order is the table below, and a file that reaches up (the key store
calling the command table, say) is named with the line to mend. Private headers are included by
their path under src/ ("scene/keys/config.hpp"), public ones as "delayspec/...". Exit 0 when every
include keeps to the order, 1 with the list otherwise. ctest runs it as `layers`.
"""
import os
import re
import sys

# (folder under the source tree, level): the longest matching prefix decides a file's folder.
LEVELS = [
    ("include/delayspec", 0),     # the public headers of the engine
    ("src/engine", 0),            # the library: models, steppers, maps, analyses
    ("src/scene/keys", 1),        # Config, the key store (knows no command)
    ("src/scene/loading", 1),     # opening a shared object by name, with its version check
    ("src/modules/equations", 2),  # plug-in: the symbolic front end (GiNaC)
    ("src/modules/mpi", 2),       # plug-in: the MPI calls
    ("src/modules/models", 2),    # library: the analyses of the built-in models but the impact model
    ("src/modules/prebuilt", 2),  # library: the analyses of the prebuilt equation-model shapes
    ("src/scene/output", 3),      # JSON, CSV, metadata, the atomic writer, progress
    ("src/scene/equations", 4),   # model = equations: the key side, the compiled model's cache
    ("src/scene/problem", 5),     # keys -> problem and typed options; the runs at several N
    ("src/scene/points", 6),      # the point loop: threads, ranks, the files of points
    ("src/scene/commands", 7),    # one file per command, the command table, the key registry
    ("src/cli", 8),               # the program: main, plot
    ("python", 8),                # the Python module
]
# The engine's public headers and its sources are one layer.
ENGINE = {"include/delayspec", "src/engine"}
# Generated at configure time (CMakeLists.txt): no folder of the tree.
GENERATED = {"delayspec/version.hpp", "equation_toolchain.hpp"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def folder_of(path):
    best = None
    for prefix, level in LEVELS:
        if (path == prefix or path.startswith(prefix + "/")) and (best is None or len(prefix) > len(best[0])):
            best = (prefix, level)
    return best


def target_of(include, including_file):
    if include in GENERATED:
        return None
    if include.startswith("delayspec/"):
        return "include/" + include
    return "src/" + include


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    problems, files = [], 0
    for top in ("include", "src", "python"):
        for folder, _, names in os.walk(os.path.join(root, top)):
            for name in sorted(names):
                if not name.endswith((".cpp", ".hpp")):
                    continue
                path = os.path.relpath(os.path.join(folder, name), root)
                home = folder_of(path)
                if home is None:
                    if not path.startswith("src/sanitizer/"):
                        problems.append(f"{path}: in no folder of the layer table (scripts/check_layers.py)")
                    continue
                files += 1
                text = open(os.path.join(root, path), encoding="utf-8").read()
                for match in INCLUDE.finditer(text):
                    include = match.group(1)
                    line = text.count("\n", 0, match.start()) + 1
                    target = target_of(include, path)
                    if target is None:
                        continue
                    if not os.path.exists(os.path.join(root, target)):
                        problems.append(f"{path}:{line}: #include \"{include}\" is not a path under src/ or "
                                        f"include/ (private headers are included by their path from src/)")
                        continue
                    there = folder_of(target)
                    if there is None or there[0] == home[0] or {there[0], home[0]} == ENGINE:
                        continue
                    if there[1] >= home[1]:
                        problems.append(f"{path}:{line}: includes {target}: {there[0]} (level {there[1]}) is not "
                                        f"below {home[0]} (level {home[1]})")
    for p in problems:
        print(p)
    print(f"layers: {files} files, {len(problems)} include(s) out of order")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
