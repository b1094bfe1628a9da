#!/usr/bin/python3
"""Doc-test: every documented `delayspec` command runs as written, and the numbers the docs
quote are what it computes.

    doc_test.py --delayspec BUILD/delayspec --source SOURCE_DIR [FILE.md ...]

(ctest runs it as `doc_test`; default files: README.md and every page of docs/, in DOCS_IN_ORDER's
order: the tutorial and the key reference first, then the pages as README.md lists them. A page
added to docs/ and not to that list is a failure.)

What is run. Fenced code blocks tagged `sh` (```sh). In them, every line (after joining `\\`
continuations and dropping a trailing `# comment`) that starts with `build/delayspec`, or with
`$ build/delayspec` (a transcript: the lines up to the next `$ ` or the end of the block are the
expected output), is run with the built program, no shell involved: the line is split with
shlex and passed as arguments; `mpirun ARGS build/delayspec ...` runs under the MPI build's
launcher (--mpirun) with the page's ARGS. Every other line (git, sudo bash scripts/..., cmake) is shown
to the reader only. `cp -r SRC DST && build/delayspec ...` is supported (the copy is done here,
inside the scratch directory). Commands run in order, one document after the other, all in one
fresh scratch directory (a reader at the repository root,
one clone: a page that reuses another page's output folder fails) holding `data/` and `docs/` of
the source tree (read-only use) and the `out/` directories the commands write.

Markers (HTML comments, invisible on the rendered page), on the lines before a block:

    <!-- doc-test: set KEY=VALUE ... -->  appends `--set KEY=VALUE ...` to every command of the
                                          block but `plot` (a smaller size than the reader's)
    <!-- doc-test: set@TEXT KEY=VALUE ... -->  the same, only to the commands containing TEXT
    <!-- doc-test: skip REASON -->        the block is not run (say why)
    <!-- doc-test: exit N -->              the block's commands must exit N (default 0)
    <!-- doc-test: help COMMAND -->        the next ```text block is the key list that
                                          `delayspec COMMAND --help` prints (docs/cli.md);
                                          `--update` rewrites such blocks from the program

and anywhere after the block whose output it checks (it is checked once the blocks before it
have run):

    <!-- doc-test expect: FILE PATH = VALUE +- TOL -->

FILE is a JSON file a command wrote (relative to the scratch directory), PATH a dot-separated
path into it (object keys, list indices), VALUE the number the text quotes and TOL the stated
absolute tolerance (written next to the number's own rounding: 0.643 quoted to 3 digits gets
+- 5e-4). A transcript's expected lines must appear in the command's output (stdout + stderr).

Exit status 0 when everything ran and matched; 1 with a list of the failures otherwise.
"""
import argparse
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

MARKER = re.compile(r"<!--\s*doc-test(?P<expect> expect)?:\s*(?P<body>.*?)\s*-->")
EXPECT = re.compile(r"^(?P<file>\S+)\s+(?P<path>\S+)\s*=\s*(?P<value>\S+)\s*\+-\s*(?P<tol>\S+)$")
PROGRAM = "build/delayspec"
# Reading order: what a newcomer runs first, then the pages in README.md's order.
DOCS_IN_ORDER = ["README.md", "docs/tutorial.md", "docs/cli.md", "docs/autonomous.md", "docs/design.md",
                 "docs/models.md", "docs/formats.md", "docs/events.md", "docs/continuation.md", "docs/lyapunov.md",
                 "docs/parallel.md", "docs/milling.md", "docs/python.md", "docs/fuzzing.md",
                 "docs/floquet-results.md", "docs/benchmarks.md"]


class Block:
    def __init__(self, doc, line):
        self.doc, self.line = doc, line
        self.commands = []   # (args, expected output lines)
        self.extra = []      # --set arguments from the marker
        self.skip = None
        self.exit = 0


def parse(doc_path):
    """The runnable blocks and the expectations of one document, in document order."""
    items, pending = [], {"extra": [], "skip": None, "exit": 0, "help": None}
    lines = open(doc_path, encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        line = lines[i]
        for m in MARKER.finditer(line):
            body = m.group("body")
            if m.group("expect"):
                e = EXPECT.match(body)
                if not e:
                    raise SystemExit(f"{doc_path}:{i + 1}: bad expect marker: {body}")
                items.append(("expect", i + 1, e.groupdict()))
            elif body.startswith(("set ", "set@")):
                words = body.split()
                only = words[0][4:] if words[0].startswith("set@") else ""
                pending["extra"] += [(only, kv) for kv in words[1:]]
            elif body.startswith("skip"):
                pending["skip"] = body[4:].strip() or "no reason given"
            elif body.startswith("exit "):
                pending["exit"] = int(body[5:])
            elif body.startswith("help "):
                pending["help"] = body[5:].strip()
            else:
                raise SystemExit(f"{doc_path}:{i + 1}: unknown doc-test marker: {body}")
        if line.strip() == "```text" and pending["help"]:
            start = i + 1
            i += 1
            while i < len(lines) and lines[i].strip() != "```":
                i += 1
            items.append(("help", start, (pending["help"], start, i)))
            pending["help"] = None
        elif line.strip() == "```sh":
            block = Block(doc_path, i + 1)
            block.extra, block.skip, block.exit = pending["extra"], pending["skip"], pending["exit"]
            pending = {"extra": [], "skip": None, "exit": 0, "help": None}
            body = []
            i += 1
            while i < len(lines) and lines[i].strip() != "```":
                body.append(lines[i])
                i += 1
            pending["help"] = None
            block.commands = commands_of(body)
            if block.commands:
                items.append(("block", block.line, block))
        i += 1
    return items


def commands_of(body):
    joined, current = [], ""
    for line in body:
        if line.rstrip().endswith("\\"):
            current += line.rstrip()[:-1] + " "
            continue
        joined.append(current + line)
        current = ""
    commands = []
    for line in joined:
        text = line.strip()
        transcript = text.startswith("$ ")
        if transcript:
            text = text[2:]
            commands.append([text, [], True])
        elif commands and commands[-1][2] and not text.startswith(PROGRAM):
            if text:
                commands[-1][1].append(text)  # expected output of the transcript command
            continue
        else:
            commands.append([text, [], False])
    runnable = []
    for text, expected, _ in commands:
        words = shlex.split(text, comments=True)
        if PROGRAM in words:
            runnable.append((words, expected))
    return runnable


def run_command(words, extra, program, scratch, expected_exit, have_gnuplot, log, mpirun=None):
    """Runs one documented line: (error text or None, output). `mpirun ARGS build/delayspec ...`
    runs under `mpirun` (the MPI build's launcher, --mpirun) with the page's ARGS; without one
    it is logged as not run."""
    output = ""
    for step in split_and(words):
        if step[:2] == ["cp", "-r"] and len(step) == 4:
            src, dst = (os.path.join(scratch, p) for p in step[2:])
            if not os.path.realpath(dst).startswith(os.path.realpath(scratch) + os.sep):
                return f"cp target outside the scratch directory: {step}", output
            shutil.rmtree(dst, ignore_errors=True)
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            shutil.copytree(src, dst)
            continue
        launch = []
        if step and step[0] == "mpirun" and PROGRAM in step:
            if not mpirun:
                log.append(f"  (no MPI build: not run) {' '.join(step)}")
                continue
            launch = [mpirun] + step[1:step.index(PROGRAM)]
            step = step[step.index(PROGRAM):]
        if not step or step[0] != PROGRAM:
            return (f"not a delayspec command (only `{PROGRAM} ...`, `mpirun ... {PROGRAM} ...` and `cp -r` run "
                    f"here): {' '.join(step)}"), output
        if step[1:2] == ["plot"] and not have_gnuplot:
            log.append(f"  (gnuplot missing: not run) delayspec {' '.join(step[1:])}")
            continue
        args = step[1:]
        if step[1:2] != ["plot"]:
            args += [a for only, kv in extra if only in " ".join(step) for a in ("--set", kv)]
        start = time.monotonic()
        p = subprocess.run(launch + [program] + args, cwd=scratch, capture_output=True, text=True, timeout=600)
        shown = " ".join((launch[1:] if launch else []) + ["delayspec"] + args)
        log.append(f"  {time.monotonic() - start:6.1f} s  {'mpirun ' if launch else ''}{shown}  -> exit {p.returncode}")
        output += p.stdout + p.stderr
        if p.returncode != expected_exit:
            return (f"exit {p.returncode} (expected {expected_exit}): delayspec {' '.join(args)}\n"
                    f"    stderr: {p.stderr.strip()[-600:]}"), output
    return None, output


def split_and(words):
    steps, current = [], []
    for w in words:
        if w == "&&":
            steps.append(current)
            current = []
        else:
            current.append(w)
    steps.append(current)
    return steps


def help_keys(program, command):
    """The key list of `delayspec COMMAND --help` (the lines after "Keys read by")."""
    out = subprocess.run([program, command, "--help"], capture_output=True, text=True, timeout=60).stdout
    lines = out.split("\n")
    first = next(i for i, l in enumerate(lines) if l.startswith("Keys read by"))
    return [l for l in lines[first:] if l.strip()]


def check_help(doc_path, helps, program, update):
    """Compares (or with update rewrites) the help blocks of one document; returns failures."""
    lines = open(doc_path, encoding="utf-8").read().split("\n")
    failures = []
    for command, start, end in reversed(helps):  # from the end: rewriting keeps earlier indices
        want = help_keys(program, command)
        if lines[start:end] != want:
            if update:
                lines[start:end] = want
            else:
                failures.append(f"{doc_path}:{start}: the key list of `{command}` differs from "
                                f"`delayspec {command} --help` (run scripts/doc_test.py --update)")
    if update:
        open(doc_path, "w", encoding="utf-8").write("\n".join(lines))
    return failures


def lookup(data, path):
    for part in path.split("."):
        if isinstance(data, list):
            data = data[int(part)]
        else:
            data = data[part]
    return data


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--delayspec", required=True, help="the built program")
    parser.add_argument("--source", required=True, help="the source tree (docs, data)")
    parser.add_argument("--update", action="store_true",
                        help="rewrite the help blocks (docs/cli.md) from the program, run nothing")
    parser.add_argument("--keep", metavar="DIR",
                        help="copy the scratch directory (the files the documents' commands wrote) to DIR")
    parser.add_argument("--mpirun", help="the MPI launcher of an MPI build: the pages' mpirun lines run with it")
    parser.add_argument("docs", nargs="*", default=DOCS_IN_ORDER)
    a = parser.parse_args()
    program = os.path.abspath(a.delayspec)
    have_gnuplot = shutil.which("gnuplot") is not None
    failures, log = [], []
    # Every page is in the reading order (a new page must say where a reader meets it).
    pages = sorted(os.path.join("docs", f) for f in os.listdir(os.path.join(a.source, "docs")) if f.endswith(".md"))
    failures += [f"{page}: not in doc_test.py's DOCS_IN_ORDER (add it where a reader meets it)"
                 for page in pages if page not in DOCS_IN_ORDER]
    for doc in a.docs:
        where = os.path.join(a.source, doc)
        helps = [item for kind, _, item in parse(where) if kind == "help"]
        failures += check_help(where, helps, program, a.update)
        if helps:
            log.append(f"{doc}: {len(helps)} key lists compared with --help")
    if a.update:
        return 0
    # One scratch directory for every document, in the order given (a reader at the repository
    # root, one clone): a page that reuses another page's output folder fails here.
    with tempfile.TemporaryDirectory(prefix="delayspec_doc_test_") as scratch:
        for sub in ("data", "docs"):
            os.symlink(os.path.join(os.path.abspath(a.source), sub), os.path.join(scratch, sub))
        for doc in a.docs:
            where = os.path.join(a.source, doc)
            log.append(f"{doc}:")
            for kind, line, item in parse(where):
                if kind == "help":
                    continue
                if kind == "expect":
                    try:
                        with open(os.path.join(scratch, item["file"]), encoding="utf-8") as f:
                            got = float(lookup(json.load(f), item["path"]))
                        want, tol = float(item["value"]), float(item["tol"])
                        ok = abs(got - want) <= tol
                        log.append(f"  expect {item['file']} {item['path']} = {want} +- {tol}: got {got!r}"
                                   f"{'' if ok else '  MISMATCH'}")
                        if not ok:
                            failures.append(f"{doc}:{line}: {item['path']} in {item['file']} is {got!r}, "
                                            f"the doc says {item['value']} +- {item['tol']}")
                    except (OSError, KeyError, IndexError, ValueError, TypeError) as e:
                        failures.append(f"{doc}:{line}: cannot read {item['path']} from {item['file']}: {e!r}")
                    continue
                block = item
                if block.skip:
                    log.append(f"  block at line {line} skipped: {block.skip}")
                    continue
                for words, expected in block.commands:
                    error, output = run_command(words, block.extra, program, scratch, block.exit, have_gnuplot, log,
                                                a.mpirun)
                    if error:
                        failures.append(f"{doc}:{line}: {error}")
                        continue
                    for want in expected:
                        if want not in output:
                            failures.append(f"{doc}:{line}: output lacks the documented line `{want}`;"
                                            f" got: {output.strip()[-600:]}")
        if a.keep:  # what the commands wrote, not the source tree's data/ and docs/ linked in
            shutil.copytree(scratch, a.keep, symlinks=True,
                            ignore=lambda d, names: [n for n in names if os.path.islink(os.path.join(d, n))])
    print("\n".join(log))
    if failures:
        print(f"\n{len(failures)} doc-test failure(s):\n" + "\n".join(failures))
        return 1
    print("\ndoc-test: every documented command ran and every quoted number matched")
    return 0


if __name__ == "__main__":
    sys.exit(main())
