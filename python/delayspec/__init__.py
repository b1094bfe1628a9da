"""delayspec: Floquet multipliers, Lyapunov exponents and characteristic roots of delay
differential equations (periodically forced or autonomous), from Python.

Each function runs the command of the same name of the `delayspec` program, with the same keys,
defaults, validation and messages (one code path: the CLI's key-reading layer and commands):

    delayspec.floquet(scene=None, **keys)   ==  delayspec floquet [SCENE] --set KEY=VALUE... --json

`scene` is a scene file (TOML, a path) or a dict standing for one; keyword arguments override
it as `--set` does (numbers, strings, booleans, lists for list keys such as Ns; None = leave the
key out). The result holds the JSON object the CLI prints (`.to_dict()`, equal to it but for the
timings) and presents its fields as attributes, numeric lists as numpy arrays.

Errors: BadInput (a ValueError) for bad keys or values, NumericalFailure (a RuntimeError) when a
method does not converge, with the CLI's messages. The GIL is released while a command runs;
Ctrl-C stops a call made from the main thread with KeyboardInterrupt (checked between periods).
See docs/python.md.
"""

import copy
import inspect
import sys
import warnings

import numpy as np

try:
    from . import _delayspec
except ImportError as error:  # the source tree's python/, or a build without the extension
    raise ImportError(
        f"delayspec: the compiled extension _delayspec is not beside {__file__} ({error}). Build it with "
        "`cmake --build build --target delayspec_python` (pybind11-dev and python3-dev installed: "
        "scripts/setup-debian.sh) and import from build/python with the interpreter it was built for, e.g. "
        "`PYTHONPATH=build/python /usr/bin/python3` (docs/python.md)") from error
from ._delayspec import BadInput, NumericalFailure, __version__

BadInput.__module__ = NumericalFailure.__module__ = "delayspec"

__all__ = [
    "BadInput", "NumericalFailure", "Result", "floquet", "equilibrium", "lyapunov", "converge", "simulate",
    "sweep", "chart", "basin", "continue_", "keys_help",
]


def _is_number(x):
    return x is None or (isinstance(x, (int, float)) and not isinstance(x, bool))


def _numeric_array(values):
    """A list of JSON numbers as a numpy array: int64 when all are integers, else float64 (null ->
    nan, as the CLI writes a non-finite number as null)."""
    if values and all(isinstance(x, int) and not isinstance(x, bool) for x in values):
        return np.array(values, dtype=np.int64)
    return np.array([np.nan if x is None else x for x in values], dtype=np.float64)


def _is_multiplier(x):
    return isinstance(x, dict) and "re" in x and "im" in x


def multipliers_array(values):
    """[{"re": .., "im": .., "abs": ..}, ...] -> numpy complex128 (the CLI's order: by modulus,
    largest first); a multiplier that is not resolved (`re`, `im` null, its `bound` given:
    docs/cli.md, floquet) is NaN."""
    return np.array([complex(np.nan, np.nan) if m["re"] is None else complex(m["re"], m["im"]) for m in values],
                    dtype=np.complex128)


def _to_numpy(value):
    """A JSON value with its numeric lists as numpy arrays: numbers -> int64 / float64, lists of
    multipliers -> complex128, rectangular lists of number lists -> 2-d arrays; dicts converted
    field by field; anything else unchanged."""
    if isinstance(value, dict):
        return {k: _to_numpy(v) for k, v in value.items()}
    if not isinstance(value, list) or not value:
        return value
    if all(_is_number(x) for x in value):
        return _numeric_array(value)
    if all(_is_multiplier(x) for x in value):
        return multipliers_array(value)
    if all(isinstance(x, list) and x and all(_is_number(y) for y in x) for x in value) and \
            len({len(x) for x in value}) == 1:
        return np.array([[np.nan if y is None else y for y in x] for x in value], dtype=np.float64)
    return [_to_numpy(x) for x in value]


def _stack(rows, field):
    """The field of each row as one array, rows first; a row without it (a failed point) or with
    null is nan (every row null: all nan, e.g. boundary's estimates from two levels)."""
    values = [row.get(field) for row in rows]
    present = [np.asarray(_to_numpy(v)) for v in values if v is not None]
    if not present:
        if any(field in row for row in rows):
            return np.full(len(values), np.nan)
        raise AttributeError(f"no row has the field `{field}`")
    shape = present[0].shape
    dtype = np.result_type(*present) if len(present) == len(values) else np.result_type(np.float64, *present)
    out = np.full((len(values),) + shape, np.nan, dtype=dtype) if dtype.kind in "fc" else \
        np.empty((len(values),) + shape, dtype=dtype)
    for i, v in enumerate(values):
        if v is not None:
            out[i] = np.asarray(_to_numpy(v))
    return out


class Result:
    """The result of one command: the JSON object `delayspec COMMAND --json` prints.

    Every top-level field is an attribute (numeric lists as numpy arrays: `r.N`,
    `r.exponents_per_period`); `r["field"]` gives the plain JSON value; `to_dict()` the whole
    object. `status` is the CLI's exit status: 0, or 3 when failures are recorded in the (complete)
    result, as with failing points of a sweep or chart (a RuntimeWarning says so).
    """

    def __init__(self, command, data, arrays, status):
        self.command = command
        self.status = status
        self._data = data
        self._arrays = arrays

    def to_dict(self):
        """The JSON object of `delayspec COMMAND --json` (a deep copy)."""
        return copy.deepcopy(self._data)

    def __getitem__(self, field):
        return self._data[field]

    def __contains__(self, field):
        return field in self._data

    def keys(self):
        return self._data.keys()

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return _to_numpy(self._data[name])
        except KeyError:
            raise AttributeError(f"`{self.command}` result has no field `{name}` "
                                 f"(fields: {', '.join(self._data)})") from None

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self._data))

    def __repr__(self):
        scalars = ", ".join(f"{k}={v!r}" for k, v in self._data.items()
                            if isinstance(v, (int, float, str)) and k in ("model", "N", "solver", "events"))
        return f"<delayspec.{type(self).__name__} {self.command}: {scalars}>"


class EquilibriumResult(Result):
    """`equilibrium`: `equilibrium` (float64, the state), `roots` (complex128, the rightmost
    characteristic roots, largest real part first, exact to their `error_bound`), `unstable`,
    `critical`, `stable` and the other fields of the CLI's JSON (docs/cli.md, equilibrium); each
    root's own fields (`error_bound`, `residual`, `moved`) in `r["roots"]`."""


class FloquetResult(Result):
    """`floquet`: `multipliers` (complex128, by modulus, largest first), `residuals` (float64,
    |M v - mu v| / (|mu| |v|); empty for dense solvers), `operator_applications`, `seconds`,
    `orbit` (a dict, its numeric lists as arrays) and the other fields of the CLI's JSON. With
    error bars (the default): `error_estimates` (float64, each multiplier's distance to the
    N -> infinity value; NaN where none could be estimated) and `verdict` ("stable",
    "unstable", "undecided"; docs/cli.md, floquet)."""

    @property
    def multipliers(self):
        return multipliers_array(self._data["multipliers"])

    @property
    def error_estimates(self):
        if "verdict" not in self._data:
            raise ValueError("`floquet` ran with error_bars = off: no error estimates")
        return np.array([np.nan if m.get("error_estimate") is None else m["error_estimate"]
                         for m in self._data["multipliers"]], dtype=np.float64)

    @property
    def residuals(self):
        return np.array(self._data["residuals"], dtype=np.float64)


class ConvergeResult(Result):
    """`converge`: the study's rows as arrays: `Ns` (int64), `multipliers_by_N` (complex128,
    levels x nev), `errors_by_N` (float64, levels x nev); `extrapolated` (complex128),
    `error_estimates`; and the CLI's fields (`rows`, `reference`, `observed_order`, ...)."""

    @property
    def Ns(self):
        return _stack(self._data["rows"], "N")

    @property
    def multipliers_by_N(self):
        return _stack(self._data["rows"], "multipliers")

    @property
    def errors_by_N(self):
        return _stack(self._data["rows"], "errors")

    @property
    def error_estimates(self):
        return _stack(self._data["extrapolated"], "error_estimate")


class SimulateResult(Result):
    """`simulate`: `trajectory` (float64, samples x columns: t, x[, v]; what --out writes to
    trajectory.csv), `poincare` (the states at t = m T, same columns), `impact_times` (float64)
    and the CLI's fields (`impacts`, `max_H`, ...). to_dict() has no trajectory, as the CLI JSON."""

    @property
    def trajectory(self):
        return _to_numpy(self._arrays["trajectory"]) if self._arrays.get("trajectory") else \
            np.empty((0, len(self._data["columns"].split(","))))

    @property
    def poincare(self):
        rows = self._data["poincare"]
        return _to_numpy(rows) if rows else np.empty((0, len(self._data["columns"].split(","))))

    @property
    def impact_times(self):
        return np.array(self._data["impact_times"], dtype=np.float64)


class SweepResult(Result):
    """`sweep`: per-point fields stacked over the points, points first: `parameter` (float64),
    `exponents_per_period` (points x exponents), `section_x`, `section_v` (points x
    section_points), ... (any field of the points; nan rows for failed points), and the CLI's
    fields (`points` is the list of point objects, `failed` the failures)."""

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        if name in self._data:
            return super().__getattr__(name)
        rows = self._data.get("points", [])
        if any(name in row for row in rows):
            return _stack(rows, name)
        return super().__getattr__(name)


class GridResult(Result):
    """`chart`, `basin`: the grid's axes `x` (x_points) and `y` (y_points), and every field of
    the rows shaped by the grid, y first: `spectral_radius[j, i]` at (x[i], y[j]) (nan where a
    point failed; its reason in `rows`), plus the CLI's fields."""

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        rows = self._data.get("rows", [])
        shape = (self._data["y_points"], self._data["x_points"])
        if name in ("x", "y"):
            values = _stack(rows, name).reshape(shape)
            return values[0, :] if name == "x" else values[:, 0]
        if name in self._data:
            return super().__getattr__(name)
        if any(name in row for row in rows):
            values = _stack(rows, name)
            return values.reshape(shape + values.shape[1:])
        return super().__getattr__(name)


class ContinueResult(SweepResult):
    """`continue`: per-point fields stacked over the branch's points (`parameter`, `multipliers`:
    points x nev complex128, `verdict`: "stable", "unstable" or "undecided" for N -> infinity, ...),
    and the CLI's fields (`bifurcations`, `Ns`, `verdicts_note`, `state_names`, ...; see
    docs/continuation.md). `maximum(state)`, `minimum(state)` and `amplitude(state)` ((max - min)/2)
    give an orbit branch's measures of the state component named `state` (the model's name, e.g. "x").
    With `continue_switch` on a branch of equilibria, `hopf_branch(i)` is the branch of orbits born
    at its i-th Hopf point, as a ContinueResult of its own (`parameter`, `period`, ... stacked)."""

    def _measure(self, field, state):
        """The orbits' measure `field` ("max" or "min") of state component `state`, per point."""
        names = list(self._data.get("state_names") or [])
        if state not in names:
            raise ValueError(f"state `{state}`: not a state component of the model (state_names: "
                             f"{', '.join(names) or 'none in this result'})")
        i = names.index(state)
        return np.array([np.nan if p.get("measures") is None or p["measures"][field][i] is None
                         else p["measures"][field][i] for p in self._data.get("points", [])], dtype=np.float64)

    def maximum(self, state):
        """The max over each point's orbit of the state component named `state` (one of
        `state_names`: the model's names, e.g. "x", "v"), float64 per point."""
        return self._measure("max", state)

    def minimum(self, state):
        """The min over each point's orbit of the state component named `state`, per point."""
        return self._measure("min", state)

    def amplitude(self, state):
        """(max - min)/2 over each point's orbit of the state component named `state`, per point."""
        return (self._measure("max", state) - self._measure("min", state)) / 2

    def hopf_branch(self, index=0):
        """The branch of orbits born at the index-th Hopf point (`hopf_branches[index]` of the
        JSON) with its points' fields stacked as arrays, as for the branch itself; the period at the
        Hopf point (the JSON's branch-level `period`) is `from_period`."""
        branches = self._data.get("hopf_branches") or []
        if not 0 <= index < len(branches):
            raise IndexError(f"hopf_branch({index}): this result has {len(branches)} branch(es) born at Hopf "
                             "points (continue_object = equilibrium with continue_switch = true)")
        branch = dict(branches[index])
        # the branch's own `period` is the one at the Hopf point (2 pi / omega): `from_period` here,
        # beside `from_parameter`, so that `period` is the points' (stacked)
        if "period" in branch:
            branch["from_period"] = branch.pop("period")
        branch.setdefault("state_names", self._data.get("state_names"))  # for maximum(state), ...
        return ContinueResult(self.command, branch, {}, self.status)


class BoundaryResult(Result):
    """`boundary`: the points of every curve stacked, curve after curve in the order of `curves`
    (as boundary.csv): `curve` (int64, each point's curve, from 1), `x`, `y`, `angle` at the
    finest N; the extrapolated point `x_extrapolated`, `y_extrapolated` with `x_error_estimate`,
    `error_estimate`, nan where null: it lies on the curve's normal, so pair `y_extrapolated`
    with `x_extrapolated`, not with `x`; `by_N`: points x levels; and the CLI's fields
    (`curves`, `Ns`, ...; see docs/continuation.md)."""

    def _points(self):
        return [p for c in self._data.get("curves", []) for p in c["points"]]

    @property
    def curve(self):
        return np.array([i + 1 for i, c in enumerate(self._data.get("curves", [])) for _ in c["points"]],
                        dtype=np.int64)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        if name in self._data:
            return super().__getattr__(name)
        rows = self._points()
        if any(name in row for row in rows):
            return _stack(rows, name)
        return super().__getattr__(name)


def _run(command, result_type, scene, keys, out=None, resume=False, progress=False):
    data, arrays, status, stderr = _delayspec.run(command, scene, keys, None if out is None else str(out), resume,
                                                  bool(progress))
    if status != 0:
        warnings.warn(stderr.strip() or f"delayspec {command}: exit status {status}", RuntimeWarning, stacklevel=3)
    elif stderr and not progress:  # with progress it was written as it came
        sys.stderr.write(stderr)
    return result_type(command, data, arrays, status)


def floquet(scene=None, *, progress=False, **keys):
    return _run("floquet", FloquetResult, scene, keys, progress=progress)


def equilibrium(scene=None, *, progress=False, **keys):
    return _run("equilibrium", EquilibriumResult, scene, keys, progress=progress)


def lyapunov(scene=None, *, progress=False, **keys):
    return _run("lyapunov", Result, scene, keys, progress=progress)


def converge(scene=None, *, out=None, progress=False, **keys):
    return _run("converge", ConvergeResult, scene, keys, out, progress=progress)


def simulate(scene=None, *, out=None, progress=False, **keys):
    return _run("simulate", SimulateResult, scene, keys, out, progress=progress)


def sweep(scene=None, *, out=None, resume=False, progress=False, **keys):
    return _run("sweep", SweepResult, scene, keys, out, resume, progress)


def chart(scene=None, *, out=None, resume=False, progress=False, **keys):
    return _run("chart", GridResult, scene, keys, out, resume, progress)


def basin(scene=None, *, out=None, resume=False, progress=False, **keys):
    return _run("basin", GridResult, scene, keys, out, resume, progress)


def continue_(scene=None, *, out=None, progress=False, **keys):
    return _run("continue", ContinueResult, scene, keys, out, progress=progress)


def boundary(scene=None, *, out=None, progress=False, **keys):
    return _run("boundary", BoundaryResult, scene, keys, out, progress=progress)


def keys_help(command):
    """The keys `command` reads, with their defaults and meanings (as `delayspec COMMAND --help`)."""
    return _delayspec.keys_help(command)


_RESULT_TYPES = {floquet: FloquetResult, equilibrium: EquilibriumResult, lyapunov: Result, converge: ConvergeResult, simulate: SimulateResult,
                 sweep: SweepResult, chart: GridResult, basin: GridResult, continue_: ContinueResult,
                 boundary: BoundaryResult}


def _document():
    """Each function's docstring from the command table (_delayspec.commands(), the program's own)."""
    specs = {row["name"]: row for row in _delayspec.commands()}
    for function, result_type in _RESULT_TYPES.items():
        spec = specs[function.__name__.rstrip("_")]
        command = spec["name"]
        extra = (", out=None" if spec["writes_out"] else "") + (", resume=False" if spec["resume"] else "") + \
            ", progress=False"
        summary = spec["summary"].split(": ", 1)[1]  # after the usage "delayspec COMMAND [SCENE]"
        function.__doc__ = (
            f"{summary}\n\n"
            f"delayspec.{function.__name__}(scene=None{extra}, **keys) runs `delayspec {command} [SCENE] "
            f"--set KEY=VALUE... --json{' [--out OUT]' if spec['writes_out'] else ''}`; scene: a TOML file or a dict.\n\n"
            f"Returns {result_type.__name__}: {inspect.cleandoc(result_type.__doc__ or '')}\n\n"
            f"progress=True reports the progress of long work (as the program's progress lines) on sys.stderr "
            f"as it comes.\n\n"
            f"Raises BadInput (ValueError) for bad keys or values, NumericalFailure (RuntimeError) when a "
            f"method fails; KeyboardInterrupt on Ctrl-C.\n\n"
            f"Keys (KEY = default):\n{keys_help(command)}")


_document()
