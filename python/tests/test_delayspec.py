"""The Python module against the program it fronts: every function's to_dict() equals the JSON
`delayspec COMMAND --json` prints for the same keys, to the last bit (timings aside), since both
run the same command code; the numpy views hold the same numbers with the documented dtypes and
shapes; errors are the CLI's, with its messages; Ctrl-C stops a long run; threads are safe.
Small N throughout: a few seconds in all."""
import os
import inspect
import json
import pathlib
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import delayspec
from conftest import CLI, SCENES, bitwise, cli_json, run_cli, without_timings

DEFAULT = SCENES / "default.toml"  # impact model, k = 0.2: a stable period-1 orbit
FLOQUET_KEYS = dict(N=40, nev=4, solver="spectra")
LYAPUNOV_KEYS = dict(N=20, transient=10, periods=30, exponents=2)


def same_as_cli(result, command, scene=None, **keys):
    assert bitwise(without_timings(result.to_dict())) == bitwise(without_timings(cli_json(command, scene, **keys)))


# ---- every function against the CLI's JSON --------------------------------------------------

def test_floquet_equals_cli_json():
    r = delayspec.floquet(DEFAULT, **FLOQUET_KEYS)
    same_as_cli(r, "floquet", DEFAULT, **FLOQUET_KEYS)


def test_floquet_reports_error_estimates_and_a_verdict():
    # x' = -x + 0.5 x(t - 1): |mu_1| = 0.73 (Lambert W), far inside the circle; at N = 200 the
    # bars are ~1e-7 (docs/cli.md, floquet).
    r = delayspec.floquet(model="linear", a=-1, b=0.5, N=200, nev=3)
    assert r.verdict == "stable"
    assert r.error_estimates.shape == r.multipliers.shape
    assert np.all(np.isfinite(r.error_estimates)) and np.all(r.error_estimates > 0)
    assert np.all(r.error_estimates < 1e-4)
    off = delayspec.floquet(model="linear", a=-1, b=0.5, N=200, nev=3, error_bars="off")
    assert "verdict" not in off
    with pytest.raises(ValueError, match="error_bars = off"):
        off.error_estimates
    np.testing.assert_array_equal(off.multipliers, r.multipliers)


def test_floquet_gives_the_orbit_as_a_time_series_by_state_name():
    """Issue 61 item 8: the orbit over one map, t and each state component by its name, as arrays
    (the CLI test checks the numbers against a long simulation: tests/cli/test_cli_floquet.cpp)."""
    keys = dict(N=40, nev=2, error_bars="off", orbit_series="on")
    r = delayspec.floquet(DEFAULT, **keys)
    same_as_cli(r, "floquet", DEFAULT, **keys)
    series = r.orbit_series
    assert sorted(series) == ["t", "v", "x"] and r.state_names == ["x", "v"]
    assert series["t"].dtype == np.float64 and series["x"].shape == (r.steps_per_map,)
    # the grid's node times over one forcing period (aligned with the orbit's contacts: not uniform)
    t = series["t"]
    assert t[0] == 0 and np.all(np.diff(t) > 0) and t[-1] < 2 * np.pi / 0.802


def test_floquet_without_scene_equals_cli_json():
    r = delayspec.floquet(N=20, k=0.1, orbit="newton")
    same_as_cli(r, "floquet", N=20, k=0.1, orbit="newton")


def test_floquet_dict_scene_equals_the_file():
    """A dict stands for a scene file: default.toml's keys as a dict give the file's result."""
    scene = dict(model="impact", zeta=0.01, e=1.26, a=0.7, beta=28, omega=0.802, k=0.2, tau_over_T=1,
                 x0=-0.0566, v0=1.0101, N=200, nev=6, solver="auto", analyses=["floquet"])
    r = delayspec.floquet(scene, N=40, nev=4)
    same_as_cli(r, "floquet", DEFAULT, N=40, nev=4)


def test_dict_scene_tables_flatten_as_in_a_scene_file(tmp_path):
    """Nested dicts are TOML tables: flattened, and a key given twice is bad input, as in a file."""
    scene = {"model": "impact", "k": 0.2, "floquet": {"nev": 3, "solver": "spectra"}}
    r = delayspec.floquet(scene, N=30)
    toml = tmp_path / "scene.toml"
    toml.write_text('model = "impact"\nk = 0.2\n[floquet]\nnev = 3\nsolver = "spectra"\n')
    same_as_cli(r, "floquet", toml, N=30)
    with pytest.raises(delayspec.BadInput, match="key `nev` is given twice"):
        delayspec.floquet({"nev": 3, "floquet": {"nev": 4}})


def test_equations_scene_dict_equals_the_file_and_the_built_in_model(tmp_path):
    """model = equations from a dict: its [equations] table stays whole (as in a file), so the dict
    gives the file's result bit for bit, and both give the built-in impact model's multipliers
    (the same discrete problem, derivatives by GiNaC against by hand: a few ulp, 1e-12)."""
    equations = dict(state=["x", "v"], parameters=dict(zeta=0.01, e=1.26, a=0.7, beta=28, omega=0.802, k=0.55),
                     period="2*pi/omega", delay="2*pi/omega",
                     rhs=["v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x"], switch="x - e",
                     rhs_switched=["v", "a*omega^2*sin(omega*t) + k*(v_tau - v) - 2*zeta*v - x - beta*(x - e)"],
                     history=dict(x=-0.0566, v=1.0101))
    keys = dict(N=40, nev=4, solver="dense", model_cache=str(tmp_path))
    r = delayspec.floquet(dict(model="equations", equations=equations), **keys)
    same_as_cli(r, "floquet", SCENES / "equations_impact.toml", **keys)
    builtin = delayspec.floquet(DEFAULT, N=40, nev=4, solver="dense", k=0.55)
    assert np.allclose(r.multipliers, builtin.multipliers, rtol=1e-12, atol=0)


def test_symbolic_libraries_load_only_for_equations(tmp_path):
    """GiNaC (the symbolic front end, libdelayspec_equations beside libdelayspec) is loaded on the
    first [equations] table, not by `import delayspec` nor a built-in model: each library mapped
    costs every process start-up (docs/benchmarks.md, "Start-up"). In a fresh interpreter, since
    this one may have run an equations model already."""
    code = f"""
import delayspec

def mapped():
    return open("/proc/self/maps").read()

delayspec.floquet(N=20, nev=2)
before = mapped()
assert "libdelayspec.so" in before, "libdelayspec not in the maps: the check would see nothing"
for library in ("libginac", "libcln", "libgmp", "libdelayspec_equations"):
    assert library not in before, library + " mapped before any [equations] table"
delayspec.floquet({str(SCENES / "equations_impact.toml")!r}, N=20, nev=2, model_cache={str(tmp_path)!r})
after = mapped()
assert "libdelayspec_equations.so" in after and "libginac" in after
"""
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr


def test_equilibrium_equals_cli_json_and_roots_are_complex():
    keys = dict(model="linear", a=-1, b=-3)
    r = delayspec.equilibrium(**keys)
    same_as_cli(r, "equilibrium", **keys)
    assert r.roots.dtype == np.complex128 and r.roots.shape == (6,)
    assert r.roots[0] == complex(r["roots"][0]["re"], r["roots"][0]["im"])
    assert r.unstable == 2 and not r.stable


def test_lyapunov_equals_cli_json():
    r = delayspec.lyapunov(**LYAPUNOV_KEYS)
    same_as_cli(r, "lyapunov", **LYAPUNOV_KEYS)


def test_converge_equals_cli_json():
    keys = dict(Ns=[10, 20, 40], nev=2)
    r = delayspec.converge(**keys)
    same_as_cli(r, "converge", **keys)
    assert r.Ns.dtype == np.int64 and list(r.Ns) == [10, 20, 40]
    assert r.multipliers_by_N.shape == (3, 2) and r.multipliers_by_N.dtype == np.complex128
    assert r.errors_by_N.shape == (3, 2)
    assert r.extrapolated.dtype == np.complex128 and r.extrapolated.shape == (2,)


def test_simulate_equals_cli_json_and_files(tmp_path):
    keys = dict(N=10, t_end=40, sample_every=2)
    r = delayspec.simulate(out=tmp_path, **keys)
    cli = cli_json("simulate", **keys)
    mine = without_timings(r.to_dict())
    assert mine.pop("files") == [str(tmp_path / f) for f in ("trajectory.csv", "poincare.csv", "impacts.csv")]
    cli.pop("files")
    assert bitwise(mine) == bitwise(without_timings(cli))
    # The trajectory is the one --out writes (17 significant digits: the same doubles).
    lines = [l for l in (tmp_path / "trajectory.csv").read_text().splitlines() if not l.startswith("#")]
    assert lines[0] == "t,x,v"
    written = np.array([[float(x) for x in l.split(",")] for l in lines[1:]])
    assert r.trajectory.dtype == np.float64 and r.trajectory.shape == (r.samples, 3)
    np.testing.assert_array_equal(r.trajectory, written)
    assert r.poincare.shape == (len(cli["poincare"]), 3)
    np.testing.assert_array_equal(r.poincare, np.array(cli["poincare"]))
    assert r.impact_times.dtype == np.float64 and r.impact_times.shape == (r.impacts,)


def test_sweep_equals_cli_json():
    keys = dict(N=20, sweep_points=3, transient=10, periods=20, section_points=4)
    r = delayspec.sweep(SCENES / "fig6_2.toml", **keys)
    same_as_cli(r, "sweep", SCENES / "fig6_2.toml", **keys)
    assert r.parameter.shape == (3,) and np.array_equal(r.parameter, [0.0, 0.7, 1.4])
    assert r.exponents_per_period.shape == (3, 2) and r.exponents_per_period.dtype == np.float64
    assert r.section_x.shape == (3, 4)


def test_chart_equals_cli_json():
    keys = dict(N=10, chart_x_points=3, chart_y_points=2)
    r = delayspec.chart(SCENES / "mathieu_chart.toml", **keys)
    same_as_cli(r, "chart", SCENES / "mathieu_chart.toml", **keys)
    assert r.spectral_radius.shape == (2, 3) and r.spectral_radius.dtype == np.float64
    np.testing.assert_array_equal(r.x, [-1.0, 2.0, 5.0])
    np.testing.assert_array_equal(r.y, [-1.5, 1.5])
    rows = r["rows"]
    for row in rows:  # spectral_radius[j, i] is the row at (x[i], y[j])
        i, j = list(r.x).index(row["x"]), list(r.y).index(row["y"])
        assert r.spectral_radius[j, i] == row["spectral_radius"]
        assert r.angle[j, i] == row["angle"]  # abs(arg mu_1): the lobe's type
    assert np.all((r.angle >= 0) & (r.angle <= np.pi))


def test_basin_equals_cli_json():
    keys = dict(N=10, basin_x_points=3, basin_y_points=2, basin_transient=20)
    r = delayspec.basin(**keys)
    same_as_cli(r, "basin", **keys)
    assert r.period.shape == (2, 3) and r.period.dtype == np.int64
    np.testing.assert_array_equal(r.x, [-3.0, 0.0, 3.0])
    assert r["x"] == "x0"  # the axis' key; r.x its values


def test_continue_equals_cli_json():
    keys = dict(continue_Ns=[10, 20], N=20)
    scene = SCENES / "continue_mathieu_delta2.toml"
    r = delayspec.continue_(scene, **keys)
    same_as_cli(r, "continue", scene, **keys)
    assert r.multipliers.dtype == np.complex128 and r.multipliers.shape == (len(r["points"]), 6)
    # each point's verdict for N -> infinity (branch_verdicts.hpp): two levels give no bars, so none is decided
    assert r.verdict.shape == (len(r["points"]),) and set(r.verdict) == {"undecided"}
    assert "three levels" in r["verdicts_note"]


def test_continue_from_a_hopf_point_equals_cli_json():
    # the equilibria of Mackey-Glass in tau and the orbits born at their Hopf point (continue_switch)
    keys = dict(continue_to=6, continue_Ns=[50, 100])
    scene = SCENES / "mackey_glass_hopf.toml"
    r = delayspec.continue_(scene, **keys)
    same_as_cli(r, "continue", scene, **keys)
    orbits = r["hopf_branches"][0]
    assert orbits["Ns"] == [50, 100] and orbits["end"] == "to"
    assert abs(orbits["points"][0]["period"] - r["bifurcations"][0]["period"]) < 1e-12 * orbits["points"][0]["period"]


def test_boundary_equals_cli_json():
    # the linear DDE's Neimark-Sacker curve in (a, b) (the exact Hopf curve, test_cli_boundary.cpp)
    keys = dict(model="linear", tau=1, period=1, boundary_x="a", boundary_y="b", boundary_x_from=-1,
                boundary_x_to=0.5, boundary_y_from=-0.5, boundary_y_to=-4, boundary_type="neimark-sacker", N=100,
                boundary_Ns=[50, 100])
    r = delayspec.boundary(**keys)
    same_as_cli(r, "boundary", **keys)
    assert r.x.shape == r.y.shape == (len(r["curves"][0]["points"]),)
    assert r.x[0] == -1 and r.x[-1] == 0.5 and r.by_N.shape == (len(r.x), 2)


def test_boundary_stacks_the_points_of_every_curve():
    # milling, a/D = 0.05, a start at 4 speeds: three lobes; every curve's points, in the order of
    # `curves` (before 2026-11-28 the arrays held the first curve's points alone)
    r = delayspec.boundary(SCENES / "milling_lobes_curves.toml", boundary_scan_points=4, boundary_Ns=[25, 50, 100],
                           N=100)
    curves = r["curves"]
    assert len(curves) >= 2
    assert r.curve.dtype == np.int64 and r.x.shape == r.curve.shape == (sum(len(c["points"]) for c in curves),)
    for i, c in enumerate(curves):
        assert list(r.x[r.curve == i + 1]) == [p["x"] for p in c["points"]]
        ye = [np.nan if p["y_extrapolated"] is None else p["y_extrapolated"] for p in c["points"]]
        assert np.array_equal(r.y_extrapolated[r.curve == i + 1], np.array(ye), equal_nan=True)
    assert np.isfinite(r.y_extrapolated).any()
    # two levels: no point has an estimate (the order cannot be checked), every one is nan
    two = delayspec.boundary(SCENES / "milling_lobes_curves.toml", boundary_scan_points=4, boundary_Ns=[50, 100], N=100)
    assert two.error_estimate.shape == two.x.shape and np.isnan(two.error_estimate).all()


def test_boundary_refined_points_keep_the_levels_shape():
    # a flip lobe's tip (milling, a/D = 0.05): where N = 100, 200, 400 do not show their order the
    # level 800 is added (boundary_refine), then 1600; every point reports all five levels, null
    # where not needed
    r = delayspec.boundary(model="milling", radial_immersion=0.05, nev=4, boundary_x="spindle_rpm",
                           boundary_y="depth", boundary_x_from=9744, boundary_x_to=13000, boundary_y_from=1e-5,
                           boundary_y_to=5e-3, N=400, boundary_Ns=[100, 200, 400], boundary_type="period-doubling")
    assert r.by_N.shape == (len(r.x), 5)
    points = r["curves"][0]["points"]
    assert any(p["extrapolated_from"] == [200, 400, 800] for p in points)
    assert all(p["by_N"][3]["N"] == 800 and p["by_N"][4]["N"] == 1600 for p in points)


# ---- numpy views -----------------------------------------------------------------------------

def test_floquet_arrays_hold_the_json_numbers():
    r = delayspec.floquet(DEFAULT, **FLOQUET_KEYS)
    d = r.to_dict()
    assert r.multipliers.dtype == np.complex128 and r.multipliers.shape == (4,)
    assert [complex(m["re"], m["im"]) for m in d["multipliers"]] == list(r.multipliers)
    assert np.all(np.diff(np.abs(r.multipliers)) <= 0)  # by modulus, largest first (CLI contract)
    assert r.residuals.dtype == np.float64 and list(r.residuals) == d["residuals"]
    assert isinstance(r.operator_applications, int) and r.operator_applications == d["operator_applications"]
    assert isinstance(r.seconds, float)
    assert r.orbit["newton_residuals"].dtype == np.float64
    assert r.N == 40 and r.model == "impact"


def test_lyapunov_arrays():
    r = delayspec.lyapunov(**LYAPUNOV_KEYS)
    for field in ("exponents_per_period", "exponents_per_time", "standard_error_per_period"):
        a = getattr(r, field)
        assert a.dtype == np.float64 and a.shape == (2,)
        assert list(a) == r[field]


def test_numpy_and_float_key_values_read_as_the_cli_reads_text():
    """k = 0.1 as a float, numpy scalar or text: the same double as `--set k=0.1`."""
    a = bitwise(without_timings(delayspec.floquet(N=20, k=0.1).to_dict()))
    b = bitwise(without_timings(delayspec.floquet(N=np.int64(20), k=np.float64(0.1)).to_dict()))
    c = bitwise(without_timings(delayspec.floquet(N="20", k="0.1").to_dict()))
    assert a == b == c
    # List keys from numpy arrays: Ns = np.array([...]) is Ns = "10,20,40".
    d = delayspec.converge(Ns=np.array([10, 20, 40]), nev=2).to_dict()
    e = delayspec.converge(Ns="10,20,40", nev=2).to_dict()
    assert bitwise(without_timings(d)) == bitwise(without_timings(e))


# ---- errors ------------------------------------------------------------------------------------

def cli_error(command, scene=None, **keys):
    status, out, err = run_cli(command, scene, **keys)
    return status, out, err


@pytest.mark.parametrize("keys", [dict(nevv=3), dict(N=0), dict(solver="lanczos"), dict(tol=-1), dict(nev="x")])
def test_bad_input_raises_with_the_cli_message(keys):
    status, out, err = cli_error("floquet", **keys)
    assert status == 2 and out is None
    prefix = "delayspec floquet: bad input: "
    assert err.startswith(prefix)
    with pytest.raises(delayspec.BadInput) as caught:
        delayspec.floquet(**keys)
    # the same message, the key's origin named as the caller gave it
    assert str(caught.value) == err[len(prefix):].rstrip("\n").replace("from --set", "from a Python keyword")
    assert isinstance(caught.value, ValueError)


def test_bad_scene_file_raises_bad_input(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text("N = = 3\n")
    status, _, err = cli_error("floquet", scene)
    with pytest.raises(delayspec.BadInput) as caught:
        delayspec.floquet(scene)
    assert status == 2 and str(caught.value) == err[len("delayspec floquet: bad input: "):].rstrip("\n")


def test_bad_value_type_raises_bad_input():
    with pytest.raises(delayspec.BadInput, match="`k`: a value of Python type object"):
        delayspec.floquet(k=object())


def test_bytes_and_strings_without_utf8_raise_bad_input_naming_the_key():
    """Issue 61 item 9: bytes were read as lists of integers (b"ab" -> 97,98) and a lone surrogate
    raised a bare RuntimeError; both are BadInput naming the key, for keywords and scene dicts."""
    with pytest.raises(delayspec.BadInput, match="`model`: a value of Python type bytes"):
        delayspec.floquet(model=b"linear")
    with pytest.raises(delayspec.BadInput, match="`Ns`: a value of Python type bytearray"):
        delayspec.converge(Ns=bytearray(b"\x19\x32"))
    with pytest.raises(delayspec.BadInput, match="`model`: a string that is not valid Unicode"):
        delayspec.floquet(model="linear\ud800")
    with pytest.raises(delayspec.BadInput, match="`model`: a string that is not valid Unicode"):
        delayspec.floquet({"model": "\udfff"})


def test_a_keyword_a_command_does_not_read_is_named_as_a_keyword():
    """Issue 61 item 9: equilibrium(out=DIR) (equilibrium writes no files) said "from --set"."""
    with pytest.raises(delayspec.BadInput, match=r"`out` \(= /tmp, from a Python keyword\)"):
        delayspec.equilibrium(model="linear", out="/tmp")


def test_the_orbits_born_at_a_hopf_point_come_as_arrays():
    """Issue 61 item 8: the Hopf branches were nested dicts only; hopf_branch(i) stacks their
    points' fields as the branch's own (the CLI test checks the numbers against the closed form:
    tests/cli/test_cli_equilibrium.cpp)."""
    r = delayspec.continue_(model="mackey-glass", continue_object="equilibrium", continue_key="tau",
                            continue_from=3, continue_to=14, equilibrium_guess=1.1, continue_switch=True)
    points = r["hopf_branches"][0]["points"]
    b = r.hopf_branch(0)
    assert b.parameter.shape == (len(points),) and b.period.shape == (len(points),)
    assert b.period[0] == points[0]["period"] and b.parameter[-1] == points[-1]["parameter"]
    assert np.all(np.diff(b.period) > 0)  # the period grows with tau (as in the CLI test)
    assert b.from_period == r["hopf_branches"][0]["period"]  # 2 pi / omega at the Hopf point
    with pytest.raises(IndexError, match="1 branch"):
        r.hopf_branch(1)
    # the orbits' size by the model's name of the state, (max - min)/2 as the table prints it
    assert r.state_names == ["x"]
    maxima = np.array([p["measures"]["max"][0] for p in points])
    minima = np.array([p["measures"]["min"][0] for p in points])
    np.testing.assert_array_equal(b.maximum("x"), maxima)
    np.testing.assert_array_equal(b.amplitude("x"), (maxima - minima) / 2)
    with pytest.raises(ValueError, match="state `y1`: not a state component of the model .state_names: x"):
        b.amplitude("y1")


def test_hopf_points_carry_their_criticality():
    """Issue 60: each Hopf point's first Lyapunov coefficient reaches Python with its bar; the
    reference -13.342516550137968 is scripts/hopf_normal_form_reference.py's (mpmath, 40 digits)."""
    r = delayspec.continue_(model="mackey-glass", continue_object="equilibrium", continue_key="tau",
                            continue_from=3, continue_to=6, equilibrium_guess=1.1)
    hopf = r["bifurcations"][0]
    assert hopf["criticality"] == "supercritical"
    assert abs(hopf["l1"] + 13.342516550137968) <= hopf["l1_bound"] <= 1.4e-7


def test_hopf_curves_of_an_equilibrium_in_two_parameters():
    """Issue 60: boundary with boundary_object = "equilibrium" from Python. Mackey-Glass in (n, tau):
    the curve from n = 10 starts at the Hopf point of the one-parameter branch (4.7081962893608,
    docs/autonomous.md) and every point has omega = sqrt(b^2 - gamma^2), b = beta (2 - n) / 4 at the
    equilibrium x* = 1 (beta / gamma = 2 for every n): the closed form along the whole curve."""
    r = delayspec.boundary(model="mackey-glass", boundary_object="equilibrium", boundary_x="n", boundary_y="tau",
                           boundary_x_from=10, boundary_x_to=6, boundary_y_from=3, boundary_y_to=30,
                           equilibrium_guess=1.1)
    points = r["curves"][0]["points"]
    assert abs(points[0]["y"] - 4.7081962893608) < 1e-9
    for p in points:
        b = 0.2 * (2 - p["x"]) / 4
        assert abs(p["omega"] - np.sqrt(b * b - 0.01)) < 1e-9
        assert p["criticality"] in ("supercritical", "subcritical", "degenerate")


def test_keys_help_of_an_unknown_command_raises_bad_input():
    """Issue 31: keys_help("nope") returned "" (an empty help, as if the command read no keys)."""
    with pytest.raises(delayspec.BadInput, match=r"unknown command `nope` \(commands: .*floquet.*sweep"):
        delayspec.keys_help("nope")
    assert "nev = " in delayspec.keys_help("floquet")  # a known command still has its help


@pytest.mark.parametrize("Ns", [[[25], [50]], [25, [50]], np.array([[25], [50]])])
def test_nested_list_for_a_list_key_raises_bad_input(Ns):
    """Issue 31: Ns=[[25], [50]] was joined to "25,50" and run; a list key takes a flat list."""
    with pytest.raises(delayspec.BadInput, match="`Ns`: a nested list"):
        delayspec.converge(Ns=Ns, nev=2)


def test_nested_array_in_a_scene_dict_raises_bad_input():
    """The same rule for a scene (a dict here, a TOML file alike: config.cpp)."""
    with pytest.raises(delayspec.BadInput, match="key `Ns` is a nested array"):
        delayspec.converge({"Ns": [[25], [50]]}, nev=2)


def test_forced_krylov_failure_raises_numerical_failure():
    """As tests/cli/test_krylov_cli.cpp: one Arnoldi iteration (max_restarts = 0) cannot converge 10
    Ritz values with ncv = 12 at N = 100."""
    keys = dict(N=100, nev=10, ncv=12, max_restarts=0, solver="spectra")
    status, out, err = cli_error("floquet", DEFAULT, **keys)
    assert status == 3 and out is None
    with pytest.raises(delayspec.NumericalFailure) as caught:
        delayspec.floquet(DEFAULT, **keys)
    assert isinstance(caught.value, RuntimeError)
    assert "did not converge" in str(caught.value)
    assert str(caught.value) == err[len("delayspec floquet: numerical failure: "):].rstrip("\n")


def test_failed_points_give_the_complete_result_status_3_and_a_warning():
    """Exit 3 with a complete result in the CLI (failures recorded per point): the same result,
    status 3, and the CLI's stderr message as a RuntimeWarning."""
    keys = dict(N=40, chart_x_points=3, chart_y_points=2, solver="spectra", nev=6, ncv=8, max_restarts=0)
    scene = SCENES / "mathieu_chart.toml"
    status, cli, err = run_cli("chart", scene, **keys)
    assert status == 3 and cli is not None
    with pytest.warns(RuntimeWarning) as warned:
        r = delayspec.chart(scene, **keys)
    assert r.status == 3
    assert str(warned[0].message) == err.strip()
    assert bitwise(without_timings(r.to_dict())) == bitwise(without_timings(cli))
    assert all("failure" in row for row in r["rows"])


def test_out_for_a_command_that_writes_no_files_is_bad_input(tmp_path):
    with pytest.raises(delayspec.BadInput, match="writes no files"):
        delayspec._run("floquet", delayspec.FloquetResult, None, {}, out=tmp_path)


# ---- interrupt, threads ------------------------------------------------------------------------

def interrupt_after(seconds):
    timer = threading.Timer(seconds, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    return timer


@pytest.mark.parametrize("command,keys", [
    ("lyapunov", dict(N=100, transient=0, periods=10_000_000)),               # periods
    ("floquet", dict(N=100, orbit="simulate", orbit_max_periods=10_000_000,   # orbit periods
                     orbit_tolerance=1e-300)),
    ("simulate", dict(N=100, t_end=1e7, sample_every=1_000_000)),              # simulation periods
    ("sweep", dict(N=100, sweep_key="k", sweep_from=0, sweep_to=1, sweep_points=4, threads=2,
                   transient=0, periods=10_000_000)),                          # points on 2 threads
])
def test_sigint_raises_keyboard_interrupt_promptly(command, keys):
    """A run of hours, interrupted after 0.3 s: KeyboardInterrupt within a second (the module
    polls the signal handlers every 50 ms between periods; a period at N = 100 takes < 1 ms)."""
    function = getattr(delayspec, command)
    timer = interrupt_after(0.3)
    start = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            function(**keys)
    finally:
        timer.cancel()  # no stray SIGINT into the next test if the call ended otherwise
        timer.join()
    elapsed = time.monotonic() - start
    assert elapsed < 1.5, elapsed
    # The module still works afterwards.
    assert delayspec.floquet(N=10).N == 10


def test_interrupted_sweep_keeps_finished_points_and_resumes(tmp_path):
    """Ctrl-C during a sweep with out=DIR leaves what the CLI leaves when killed: the finished
    points in the log (no temporary left), no complete.json; resume=True computes only the missing points and
    gives the uninterrupted CLI run's result."""
    keys = dict(N=20, sweep_key="k", sweep_from=0, sweep_to=1.4, sweep_points=12, transient=0, periods=8000,
                threads=1, section_points=2)  # ~0.05 s per point
    out = tmp_path / "sweep"

    def logged():  # the points in the log, not a line still being written
        indices = set()
        for log in (out / "points").glob("*.jsonl"):
            for line in log.read_text().splitlines():
                try:
                    indices.add(json.loads(line)["index"])
                except json.JSONDecodeError:
                    pass
        return indices

    def interrupt_after_the_first_point():  # not by time: a loaded machine is slower
        deadline = time.monotonic() + 60
        while not logged() and time.monotonic() < deadline:
            time.sleep(0.002)
        os.kill(os.getpid(), signal.SIGINT)

    watcher = threading.Thread(target=interrupt_after_the_first_point)
    watcher.start()
    with pytest.raises(KeyboardInterrupt):
        delayspec.sweep(out=out, **keys)
    watcher.join()
    done = sorted(logged())
    assert 0 < len(done) < 12, done
    assert not (out / "complete.json").exists()
    assert not [p for p in out.rglob("*") if p.name.startswith(".") and p.name != ".delayspec-lock"]
    r = delayspec.sweep(out=out, resume=True, **keys)
    assert r.points_computed_now == 12 - len(done)
    assert (out / "complete.json").exists()
    mine, cli = without_timings(r.to_dict()), without_timings(cli_json("sweep", **keys))
    mine.pop("points_computed_now"), cli.pop("points_computed_now")
    assert bitwise(mine) == bitwise(cli)


def test_threads_calling_floquet_at_once_give_the_sequential_results():
    """Three threads at once, two of them on ARPACK (whose Fortran state the library serialises)."""
    cases = [dict(N=150, k=0.2, nev=4, solver="spectra"), dict(N=150, k=0.3, nev=4, solver="arpack"),
             dict(N=120, k=0.25, nev=3, solver="arpack")]
    expected = [bitwise(without_timings(cli_json("floquet", **keys))) for keys in cases]
    results = [None] * len(cases)
    barrier = threading.Barrier(len(cases))

    def work(i):
        barrier.wait()
        for _ in range(3):
            got = bitwise(without_timings(delayspec.floquet(**cases[i]).to_dict()))
            if got != expected[i]:
                results[i] = got
                return
        results[i] = expected[i]

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(cases))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results == expected


def test_threads_writing_files_at_once_each_complete_their_own_directory(tmp_path):
    """Calls with out= run at once (each invocation carries its own output directory): each
    directory gets the files and the complete.json of its own call, as a call alone writes them."""
    keys = dict(N=40, t_end=200, sample_every=4)
    alone = tmp_path / "alone"
    delayspec.simulate(out=alone, **keys)
    barrier = threading.Barrier(3)
    errors = []

    def work(i):
        barrier.wait()
        try:
            delayspec.simulate(out=tmp_path / f"thread{i}", **keys)
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    for i in range(3):
        mine = tmp_path / f"thread{i}"
        marker = json.loads((mine / "complete.json").read_text())
        assert marker["command"] == "simulate" and marker["exit_status"] == 0
        assert sorted(marker["files"]) == sorted(json.loads((alone / "complete.json").read_text())["files"])
        for name in ("trajectory.csv", "poincare.csv", "impacts.csv"):
            body = lambda d: [l for l in (d / name).read_text().splitlines() if not l.startswith("#")]
            assert body(mine) == body(alone), name


def test_progress_is_written_to_sys_stderr_while_the_call_runs(capsys):
    """progress=True: the program's progress lines (one every 5 s) reach sys.stderr while the call
    still runs, where a notebook shows them; without it the call is silent. A sweep of ~7 s."""
    keys = dict(N=20, sweep_key="k", sweep_from=0, sweep_to=1.4, sweep_points=160, transient=0, periods=8000,
                threads=1, section_points=2)  # ~0.04-0.05 s per point: a report is due after 5 s
    seen_during = []
    real_write = sys.stderr.write

    def spy(text):  # records what arrives before the call has returned
        seen_during.append(text)
        return real_write(text)

    sys.stderr.write = spy
    try:
        r = delayspec.sweep(progress=True, **keys)
    finally:
        sys.stderr.write = real_write
    assert r.status == 0
    lines = "".join(seen_during)
    assert "sweep: " in lines and "/160 (" in lines, lines  # a report while running: "sweep: k/160 (p%), ..."
    assert "done in" in lines, lines
    capsys.readouterr()  # what the call above wrote
    delayspec.sweep(**dict(keys, sweep_points=2))
    assert "sweep" not in capsys.readouterr().err


def test_gil_is_released_during_a_run():
    """A Python thread keeps running while another computes."""
    ticks = []
    done = threading.Event()

    def ticker():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.01)

    t = threading.Thread(target=ticker)
    t.start()
    start = time.monotonic()
    delayspec.lyapunov(N=100, transient=0, periods=10000)  # ~0.2 s
    end = time.monotonic()
    done.set()
    t.join()
    assert end - start > 0.05, "the run is too short to tell"
    # With the GIL held the ticker could not run at all; a quarter of its 10 ms ticks is margin
    # for a loaded machine.
    during = [x for x in ticks if start < x < end]
    assert len(during) >= (end - start) / 0.01 / 4


def test_version_is_the_programs():
    out = subprocess.run([CLI, "--version"], capture_output=True, text=True, check=True).stdout
    assert out.strip() == f"delayspec {delayspec.__version__}"


def test_docstrings_list_the_keys():
    for function, key in [(delayspec.floquet, "nev = 6"), (delayspec.lyapunov, "exponents"),
                          (delayspec.sweep, "sweep_key"), (delayspec.chart, "chart_x")]:
        assert key in function.__doc__, function.__name__


def test_signatures_follow_the_command_table():
    # out= where the command writes files, resume=True where it resumes (chart and basin, as the
    # program's --resume): from the one table, not a list kept here.
    for row in _delayspec_commands():
        function = getattr(delayspec, row["name"] + ("_" if row["name"] == "continue" else ""), None)
        if function is None:
            continue  # run, plot, bench: the program's only
        parameters = inspect.signature(function).parameters
        assert ("out" in parameters) == row["writes_out"], row["name"]
        assert ("resume" in parameters) == row["resume"], row["name"]
        assert row["summary"].split(": ", 1)[1] in function.__doc__


def _delayspec_commands():
    from delayspec import _delayspec
    return _delayspec.commands()


def test_a_missing_extension_says_how_to_build_it(tmp_path):
    # The package without its compiled part (the source tree's python/, or a build without the
    # target): an ImportError naming the target, not "partially initialized module ... (most likely
    # due to a circular import)".
    package = tmp_path / "delayspec"
    package.mkdir()
    (package / "__init__.py").write_text(pathlib.Path(delayspec.__file__).read_text())
    p = subprocess.run([sys.executable, "-c", "import delayspec"], capture_output=True, text=True,
                       env={**os.environ, "PYTHONPATH": str(tmp_path)}, cwd=tmp_path, timeout=60)
    assert p.returncode != 0
    assert "ImportError" in p.stderr
    assert "--target delayspec_python" in p.stderr
