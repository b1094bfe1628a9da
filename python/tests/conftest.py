"""Shared helpers: the built `delayspec` program (DELAYSPEC_CLI, set by ctest) and the scenes."""
import json
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("DELAYSPEC_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
SCENES = SOURCE_DIR / "data" / "scenes"
CLI = os.environ.get("DELAYSPEC_CLI", str(SOURCE_DIR / "build" / "delayspec"))


def set_args(keys):
    """Keyword arguments as the CLI's --set options, spelled as a user would type them."""
    args = []
    for key, value in keys.items():
        if isinstance(value, (list, tuple)):
            value = ",".join(str(v) for v in value)
        args += ["--set", f"{key}={value}"]
    return args


def run_cli(command, scene=None, **keys):
    """`delayspec COMMAND [SCENE] --set ... --json --quiet`: (exit status, parsed JSON or None, stderr)."""
    argv = [CLI, command] + ([str(scene)] if scene else []) + set_args(keys) + ["--json", "--quiet"]
    p = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    return p.returncode, (json.loads(p.stdout) if p.stdout.strip() else None), p.stderr


def cli_json(command, scene=None, **keys):
    status, result, err = run_cli(command, scene, **keys)
    assert status == 0, err
    return result


def without_timings(value):
    """The JSON without wall-clock fields (`seconds`, `*_seconds`): everything else is
    deterministic and must agree to the last bit."""
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if not (k == "seconds" or k.endswith("_seconds"))}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


@pytest.fixture
def cli():
    return cli_json


def bitwise(value):
    """The JSON value with each float as its exact bit pattern (float.hex: -0.0 differs from 0.0)
    and each number tagged with its type: `bitwise(a) == bitwise(b)` is equality to the last bit,
    where == alone would let 1 == 1.0 and 0.0 == -0.0 pass."""
    if isinstance(value, dict):
        return {k: bitwise(v) for k, v in value.items()}
    if isinstance(value, list):
        return [bitwise(v) for v in value]
    if isinstance(value, float):
        return ("float", value.hex())
    if isinstance(value, bool):
        return ("bool", value)
    if isinstance(value, int):
        return ("int", value)
    return value
