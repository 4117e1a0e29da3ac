"""Shared fixtures: the repository, the `sagcal` command to compare with, and
a simulated calibration problem written both as files (for the command) and
held as arrays (for the package)."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import sagcal

ROOT = Path(__file__).resolve().parents[2]


def _find_binary():
    """The `sagcal` binary: $SAGCAL_BIN (must exist when set), else the one
    `cargo test` / `cargo build` left in target/."""
    given = os.environ.get("SAGCAL_BIN")
    if given:
        if not Path(given).is_file():
            raise FileNotFoundError(f"SAGCAL_BIN={given} does not exist: build it with `cargo build`")
        return Path(given)
    for profile in ("debug", "release"):
        path = ROOT / "target" / profile / "sagcal"
        if path.is_file():
            return path
    return None


@pytest.fixture(scope="session")
def cli():
    """Run the `sagcal` command: `cli(*args)` returns the completed process."""
    binary = _find_binary()
    if binary is None:
        pytest.skip("no sagcal binary to compare with: run `cargo build` (or set SAGCAL_BIN)")

    def run(*args, check=True):
        done = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True, cwd=ROOT)
        if check and done.returncode != 0:
            raise AssertionError(f"sagcal {' '.join(map(str, args))} failed: {done.stderr}")
        return done

    return run


def cli_error(done):
    """The message of a failed command: stderr without `error: ` and the newline."""
    assert done.returncode == 1, f"expected exit code 1, got {done.returncode}: {done.stderr}"
    text = done.stderr.strip()
    assert text.startswith("error: "), text
    return text[len("error: ") :]


def cli_json(done):
    """The JSON a command printed."""
    return json.loads(done.stdout)


def make_problem(folder, robot, noise, seed, moved_m):
    """A calibration problem away from the nominal robot: the built-in robot
    with encoder offsets as the truth, 30 poses with `noise`, and a guess with
    every anchor moved `moved_m` (in fixed directions) and every offset 3 m.
    Files in `folder`: truth.toml, guess.toml, data.csv (written by the package)."""
    truth = sagcal.Robot.from_toml(ROOT / "robots" / f"{robot}.toml")
    truth.length_offsets_m = [1.5, -2.0, 0.7, 3.1]
    simulation = sagcal.simulate(truth, 30, seed=seed, noise=noise)
    directions = np.array([[2.0, -1.0, 1.0], [-2.0, 1.0, 1.0], [1.0, 2.0, -1.0], [-1.0, -2.0, 1.0]]) / np.sqrt(6.0)
    guess = truth.copy()
    guess.anchors_m = truth.anchors_m + moved_m * directions
    guess.length_offsets_m = truth.length_offsets_m + np.array([3.0, -3.0, 3.0, -3.0])
    truth.to_toml(folder / "truth.toml")
    guess.to_toml(folder / "guess.toml")
    sagcal.write_measurements(folder / "data.csv", simulation.measurements, [f"{robot}, seed {seed}, {noise} noise"])
    return {
        "folder": folder,
        "noise": noise,
        "truth": truth,
        "guess": guess,
        "measurements": simulation.measurements,
    }


@pytest.fixture(scope="session")
def problem(tmp_path_factory):
    """The large robot, the paper's noise (seed 11), anchors guessed 2.4 m off."""
    return make_problem(tmp_path_factory.mktemp("large-paper"), "large", "paper", 11, 2.45)


@pytest.fixture(scope="session")
def small_problem(tmp_path_factory):
    """The small robot, the authors' noise (seed 4), anchors guessed 0.5 m off."""
    return make_problem(tmp_path_factory.mktemp("small-authors"), "small", "authors", 4, 0.5)
