"""A fresh clone of this repository at a revision, built cold: what the scripts timing a
newcomer's or CI's wait start from (first_number_time.py, ci_time.py)."""
import contextlib
import os
import resource
import subprocess
import tempfile


@contextlib.contextmanager
def fresh_clone(source, rev, prefix):
    """A clone of `source` checked out at `rev` in a temporary directory, removed afterwards."""
    with tempfile.TemporaryDirectory(prefix=prefix) as scratch:
        clone = os.path.join(scratch, "delayspec")
        subprocess.run(["git", "clone", "--quiet", source, clone], check=True)
        subprocess.run(["git", "-C", clone, "checkout", "--quiet", rev], check=True)
        yield clone


def cold_environment():
    """This environment with ccache disabled, as on a machine that never built delayspec."""
    return dict(os.environ, CCACHE_DISABLE="1")


def children_cpu_seconds():
    """User + system CPU seconds of the finished child processes so far."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime
