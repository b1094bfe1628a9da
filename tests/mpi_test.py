#!/usr/bin/python3
"""MPI test: `mpirun -n R delayspec sweep|chart|basin|run` writes the files a run of one process
with threads = 1 writes, value for value; a run killed on one rank is completed by --resume;
bad input stops every rank with exit 2 and one message; so does a missing MPI module, which a
run without mpirun does not need.

    mpi_test.py --delayspec BUILD/delayspec --mpirun /usr/bin/mpirun

(ctest runs it as `mpi_test`, with OpenMPI's OMPI_ALLOW_RUN_AS_ROOT variables set for CI, which
runs as root.) The reference is always a plain run of the same binary without mpirun: the
distributed runs are checked against the code path that has no MPI in it.

Compared: every file of the output directory, and the point logs (POINTS/rank_R.jsonl, one per
rank: which rank logged which point differs from run to run) record by record. Timings are the only thing left out: the JSON keys
"seconds", "*_seconds" and "finished_utc", the CSV comment lines of the same names, and the last
column (`seconds`) of sweep's exponents.csv. Everything else, including every number
printed with 17 significant digits, must be identical byte for byte. Without --out, the JSON
printed on stdout is compared the same way.

The killed run uses the test hook DELAYSPEC_TEST_KILL_RANK=R:K (src/scene/points/distributed_points.hpp):
rank R raises SIGKILL after its K-th point, as a node failure or `scancel` would end it.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

def is_timing(key):
    return key in ("seconds", "finished_utc") or key.endswith("_seconds")
FAILURES = []

# Small problems (each run about a second of computing or less) that still give every rank points;
# a sweep point takes some 50 ms, so that a killed rank stops the run before all points are done.
SWEEP = ["sweep", "--set", "model=impact", "--set", "sweep_key=k", "--set", "sweep_from=0", "--set", "sweep_to=1.4",
         "--set", "sweep_points=12", "--set", "N=40", "--set", "transient=500", "--set", "periods=2000",
         "--set", "exponents=2", "--set", "section_points=20", "--set", "threads=1"]
CHART = ["chart", "--set", "model=mathieu", "--set", "N=20", "--set", "solver=dense", "--set", "chart_x_points=6",
         "--set", "chart_y_points=5", "--set", "threads=1"]
BASIN = ["basin", "--set", "model=impact", "--set", "N=30", "--set", "k=0", "--set", "basin_x_points=5",
         "--set", "basin_y_points=4", "--set", "basin_transient=60", "--set", "basin_max_period=4",
         "--set", "threads=1"]
# Every point fails (an orbit by simulation allowed 2 periods cannot settle): exit 3.
FAILING_CHART = ["chart", "--set", "model=impact", "--set", "N=8", "--set", "chart_x=k", "--set", "chart_y=zeta",
                 "--set", "chart_x_range=0,0.2", "--set", "chart_y_range=0,0.1", "--set", "chart_x_points=3",
                 "--set", "chart_y_points=2", "--set", "orbit=simulate", "--set", "orbit_max_periods=2",
                 "--set", "threads=1"]
# Runs the program given as $0 and writes this rank's own exit status to the file rank_<rank> in
# the directory $STATUS_DIR; exits 0, so that mpirun does not end the other ranks before they
# write theirs. A file, not stderr: mpirun's forwarding of a rank's last stderr line raced with
# its own exit under load (a status line went missing once in ctest next to a sanitizer build).
EACH_RANK_STATUS = '"$0" "$@"; s=$?; echo "rank $OMPI_COMM_WORLD_RANK exit $s" > "$STATUS_DIR/rank_$OMPI_COMM_WORLD_RANK"'
# `run`: analyses with and without point loops; the workers must skip floquet and follow the
# lead through the two grids.
RUN_SCENE = """analyses = ["floquet", "chart", "basin"]
model = "mathieu"
N = 20
solver = "dense"
threads = 1
chart_x_points = 5
chart_y_points = 4
basin_x = "delta"
basin_y = "b"
basin_x_points = 4
basin_y_points = 3
basin_transient = 20
basin_max_period = 3
"""


def check(condition, message):
    if not condition:
        FAILURES.append(message)
        print("FAIL:", message, flush=True)
    return condition


def strip_timing(value):
    if isinstance(value, dict):
        return {k: strip_timing(v) for k, v in value.items() if not is_timing(k)}
    if isinstance(value, list):
        return [strip_timing(v) for v in value]
    return value


def normalised(path):
    """The file's content without timings (see the module docstring)."""
    text = path.read_text()
    if path.suffix == ".json":
        # Numbers compare as the doubles they denote (Python's float parsing is correctly rounded).
        return json.dumps(strip_timing(json.loads(text)), sort_keys=True)
    lines = [line for line in text.splitlines() if not is_timing(line.split(":")[0].lstrip("# "))]
    if path.name == "exponents.csv":
        lines = [line if line.startswith("#") else line.rsplit(",", 1)[0] for line in lines]
    return "\n".join(lines)


def files_of(directory):
    """The files but the hidden ones and the point logs (point_records)."""
    return sorted(p.relative_to(directory) for p in directory.rglob("*")
                  if p.is_file() and not p.name.startswith(".") and p.suffix != ".jsonl")


def point_records(directory):
    """The logged points: (points directory, index) -> the record without timings. A line that does
    not parse (cut by a kill) is left out, as --resume leaves it; a point logged twice must be
    the same record."""
    records = {}
    for log in sorted(directory.rglob("*.jsonl")):
        for line in log.read_text().splitlines():
            try:
                record = json.loads(line)
            except json.JSONDecodeError:
                continue
            key = (log.parent.name, record["index"])
            text = json.dumps(strip_timing(record), sort_keys=True)
            check(records.setdefault(key, text) == text, f"{log}: point {key} logged twice, differently")
    return records


def same_files(reference, other, what, leave_out=()):
    names = [name for name in files_of(reference) if str(name) not in leave_out]
    other_names = [name for name in files_of(other) if str(name) not in leave_out]
    if not check(names == other_names, f"{what}: files {other_names} != reference {names}"):
        return
    for name in names:
        check(normalised(reference / name) == normalised(other / name), f"{what}: {name} differs from the reference")
    check(point_records(reference) == point_records(other), f"{what}: the logged points differ from the reference")


def run(command, env=None, cwd=None):
    return subprocess.run(command, capture_output=True, text=True, env=env, cwd=cwd, timeout=300)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--delayspec", required=True)
    parser.add_argument("--mpirun", required=True)
    args = parser.parse_args()
    program = str(Path(args.delayspec).resolve())

    def mpirun(ranks, *rest):
        return [args.mpirun, "--oversubscribe", "-n", str(ranks), *rest]

    status_runs = 0

    def run_each_rank(ranks, *command):
        """The command on `ranks` ranks under EACH_RANK_STATUS: (the run, the sorted status lines)."""
        nonlocal status_runs
        status_runs += 1
        directory = Path(scratch) / f"statuses_{status_runs}"
        directory.mkdir()
        env = dict(os.environ, STATUS_DIR=str(directory))
        r = run(mpirun(ranks, "-x", "STATUS_DIR", "sh", "-c", EACH_RANK_STATUS, *command), env=env)
        return r, sorted(f.read_text().strip() for f in directory.glob("rank_*"))

    with tempfile.TemporaryDirectory(prefix="delayspec_mpi_test_") as scratch:
        scratch = Path(scratch)
        scene = scratch / "run_scene.toml"
        scene.write_text(RUN_SCENE)
        cases = {"sweep": SWEEP, "chart": CHART, "basin": BASIN, "run": ["run", str(scene)],
                 "failing_chart": FAILING_CHART}

        # 1. Same files as a single process with threads = 1, for R = 2 and 3, and the same exit
        # status (3 for failed points, recorded in the files), the summary printed once.
        for name, command in cases.items():
            status = 3 if name == "failing_chart" else 0
            reference = scratch / f"{name}_ref"
            r = run([program, *command, "--quiet", "--out", str(reference)])
            check(r.returncode == status, f"{name} without mpirun: exit {r.returncode}: {r.stderr}")
            for ranks in (2, 3):
                out = scratch / f"{name}_{ranks}"
                r, statuses = run_each_rank(ranks, program, *command, "--out", str(out))
                if check(statuses == [f"rank {i} exit {status}" for i in range(ranks)],
                         f"{name} on {ranks} ranks: rank statuses {statuses}\n{r.stderr}"):
                    same_files(reference, out, f"{name} on {ranks} ranks")
                    summary = "run: " if name == "run" else "delayspec " + command[0]
                    check(r.stdout.count(summary) == 1,
                          f"{name} on {ranks} ranks: the summary is not printed exactly once:\n{r.stdout}")
                    if status == 3:
                        check(r.stderr.count("numerical failure at") == 1,
                              f"{name} on {ranks} ranks: the failure is not reported once:\n{r.stderr}")

        # Without --out the points reach rank 0 only as messages: the JSON on stdout is the same.
        for name in ("sweep", "basin"):
            alone = run([program, *cases[name], "--quiet", "--json"])
            r = run(mpirun(3, program, *cases[name], "--quiet", "--json"))
            if check(alone.returncode == 0 and r.returncode == 0, f"{name} --json: exit {r.returncode}: {r.stderr}"):
                check(strip_timing(json.loads(r.stdout)) == strip_timing(json.loads(alone.stdout)),
                      f"{name} --json on 3 ranks differs from one process")

        # 2. A rank killed mid-run: the finished points are on disk, --resume completes the sweep
        # with the reference's values (killed worker -> resume without MPI; killed lead -> R = 2).
        reference = scratch / "sweep_ref"
        for killed, resume_ranks in ((1, 1), (0, 2)):
            out = scratch / f"sweep_killed_{killed}"
            env = dict(os.environ, DELAYSPEC_TEST_KILL_RANK=f"{killed}:1")
            r = run(mpirun(3, program, *SWEEP, "--quiet", "--out", str(out)), env=env)
            check(r.returncode != 0, f"sweep with rank {killed} killed: exit 0 (the test hook did not fire)")
            points = point_records(out)
            check(len(points) >= 1, f"sweep with rank {killed} killed: no point logged")
            # The killed rank's last point never reached the lead, so the tables were not written.
            # A killed worker: the other ranks go on until mpirun ends them (about 0.3 s here),
            # possibly computing every point. A killed lead: the workers stop at their next
            # request, so points are missing and --resume computes them.
            if killed == 0:
                check(len(points) < 12, f"sweep with the lead killed: all {len(points)} points logged")
            for name in ("complete.json", "exponents.csv", "sweep.json"):
                check(not (out / name).exists(), f"sweep with rank {killed} killed: {name} exists")
            resume = [program, *SWEEP, "--quiet", "--resume", "--out", str(out)]
            r = run(resume if resume_ranks == 1 else mpirun(resume_ranks, *resume))
            if check(r.returncode == 0, f"resume after rank {killed} killed: exit {r.returncode}: {r.stderr}"):
                # complete.json lists the files this run wrote; sweep.json counts the points it computed
                same_files(reference, out, f"sweep resumed after rank {killed} was killed",
                           leave_out=("complete.json", "sweep.json"))

        # The grids keep point logs too: the lead killed after its first point, the workers stop
        # at their next request; --resume without MPI computes the rest.
        for name in ("chart", "basin"):
            out = scratch / f"{name}_killed"
            env = dict(os.environ, DELAYSPEC_TEST_KILL_RANK="0:1")
            r = run(mpirun(3, program, *cases[name], "--quiet", "--out", str(out)), env=env)
            check(r.returncode != 0, f"{name} with the lead killed: exit 0 (the test hook did not fire)")
            check(not (out / f"{name}.csv").exists(), f"{name} with the lead killed: {name}.csv exists")
            r = run([program, *cases[name], "--quiet", "--resume", "--out", str(out)])
            if check(r.returncode == 0, f"{name} resumed: exit {r.returncode}: {r.stderr}"):
                same_files(scratch / f"{name}_ref", out, f"{name} resumed after the lead was killed",
                           leave_out=("complete.json",))

        # 3. Bad input: every rank exits 2, one message. Two kinds: found by every rank (a bad key
        # value), and found only by the lead (an --out directory that already holds a sweep: the
        # workers never look at it).
        for what, command in (("bad key", [*SWEEP, "--set", "sweep_points=0"]),
                              ("bad --out", [*SWEEP, "--out", str(reference)]),
                              ("bad chart", [*CHART, "--set", "chart_x_points=1"])):
            r, statuses = run_each_rank(3, program, *command)
            check(statuses == [f"rank {i} exit 2" for i in range(3)], f"{what}: rank statuses {statuses}\n{r.stderr}")
            check(r.stderr.count("bad input") == 1, f"{what}: the message is not printed once:\n{r.stderr}")

        # 4. The MPI module (libdelayspec_mpi.so beside libdelayspec) is loaded only under a
        # launcher: the program and its library (with the built-in models' module, which the
        # Mathieu chart needs) copied without it run alone, and under mpirun every rank exits 2
        # with one message naming the file.
        copy = scratch / "without_mpi_module"
        copy.mkdir()
        libraries = list(Path(program).parent.glob("libdelayspec.so*"))
        check(len(libraries) >= 1, f"no libdelayspec.so* beside {program}")
        libraries += list(Path(program).parent.glob("libdelayspec_models.so*"))
        for library in libraries:
            shutil.copyfile(library.resolve(), copy / library.name)
        shutil.copy(program, copy / "delayspec")
        alone = ["env", f"LD_LIBRARY_PATH={copy}", str(copy / "delayspec"), *CHART, "--quiet", "--json"]
        r = run(alone)
        check(r.returncode == 0, f"the copy without the MPI module, alone: exit {r.returncode}: {r.stderr}")
        r, statuses = run_each_rank(2, *alone)
        check(statuses == [f"rank {i} exit 2" for i in range(2)], f"no MPI module: rank statuses {statuses}\n{r.stderr}")
        missing = f"the module {copy / 'libdelayspec_mpi.so'} (delayspec's MPI transport): it is missing"
        check(r.stderr.count(missing) == 1, f"no MPI module: the message is not printed once:\n{r.stderr}")

    if FAILURES:
        print(f"mpi_test: {len(FAILURES)} failure(s)")
        return 1
    print("mpi_test: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
