"""Errors raise `sagcal.SagcalError` (a ValueError) with the message the
`sagcal` command prints after `error: `."""

import numpy as np
import pytest

import sagcal
from conftest import ROOT, cli_error


def message(call):
    with pytest.raises(sagcal.SagcalError) as caught:
        call()
    assert isinstance(caught.value, ValueError)
    assert type(caught.value).__module__ == "sagcal"  # tracebacks say `sagcal.SagcalError`
    return str(caught.value)


def test_a_missing_measurement_file(cli, problem, tmp_path):
    missing = tmp_path / "missing.csv"
    guess = problem["folder"] / "guess.toml"
    expected = cli_error(cli("calibrate", "--robot", guess, "--data", missing, check=False))
    assert message(lambda: sagcal.calibrate(problem["guess"], missing)) == expected
    assert message(lambda: sagcal.calibrate(problem["guess"], str(missing))) == expected
    assert expected.startswith(str(missing)) and "No such file" in expected


def test_a_missing_or_invalid_robot_file(cli, tmp_path):
    missing = tmp_path / "missing.toml"
    data = ROOT / "robots" / "large.toml"  # any path: the robot is read first
    expected = cli_error(cli("calibrate", "--robot", missing, "--data", data, check=False))
    assert message(lambda: sagcal.Robot.from_toml(missing)) == expected
    bad = tmp_path / "bad.toml"
    text = (ROOT / "robots" / "large.toml").read_text().replace("reference_cable = 1", "reference_cable = 7")
    bad.write_text(text)
    expected = cli_error(cli("calibrate", "--robot", bad, "--data", data, check=False))
    assert message(lambda: sagcal.Robot.from_toml(bad)) == expected
    assert "field `reference_cable`: cable 7 does not exist" in expected


def test_nan_in_a_file_and_in_an_array(cli, problem, tmp_path):
    lines = (problem["folder"] / "data.csv").read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("x_m"))
    row = lines[header + 3].split(",")
    row[0] = "NaN"
    lines[header + 3] = ",".join(row)
    path = tmp_path / "nan.csv"
    path.write_text("\n".join(lines) + "\n")
    guess = problem["folder"] / "guess.toml"
    expected = cli_error(cli("calibrate", "--robot", guess, "--data", path, check=False))
    line = header + 4  # 1-based line of the third data row
    assert expected == f"{path}: row 3 (line {line}), field `x_m`: not a finite number: `NaN`"
    assert message(lambda: sagcal.calibrate(problem["guess"], path)) == expected
    # The same value in an array: the same check and words, the same row 3 (1-based), no line.
    data = problem["measurements"].copy()
    data[2, 0] = np.nan
    assert message(lambda: sagcal.calibrate(problem["guess"], data)) == (
        "measurements: row 3, field `x_m`: not a finite number: `NaN`"
    )


def test_a_negative_tension_in_a_file_and_in_an_array(cli, problem, tmp_path):
    data = problem["measurements"].copy()
    data[0, 10] = -5.0
    path = tmp_path / "negative.csv"
    # The file writer refuses it, so write the CSV by hand.
    header = ",".join(sagcal.MEASUREMENT_COLUMNS)
    path.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in data) + "\n")
    expected = cli_error(cli("calibrate", "--robot", problem["folder"] / "guess.toml", "--data", path, check=False))
    assert expected == f"{path}: row 1 (line 2), field `f_ref_n`: negative tension: the reference tension must be positive, got -5 N"
    # The same row 1, without a line: an array is no file.
    assert message(lambda: sagcal.calibrate(problem["guess"], data)) == expected.replace(
        f"{path}: row 1 (line 2)", "measurements: row 1"
    )


def test_bad_shapes_and_values_name_the_argument(problem):
    guess = problem["guess"]
    assert message(lambda: sagcal.calibrate(guess, np.zeros((5, 10)))) == (
        "invalid input: measurements must be an (N, 11) array with N >= 1, got shape (5, 10)"
    )
    assert message(lambda: sagcal.calibrate(guess, np.zeros(11))) == (
        "invalid input: measurements must be an (N, 11) array with N >= 1, got shape (11,)"
    )
    assert message(lambda: sagcal.calibrate(guess, [["a"] * 11])).startswith(
        "invalid input: measurements: not an array of numbers: could not convert string to float"
    )
    with pytest.raises(sagcal.SagcalError, match="must be an array of shape \\(4, 3\\), got shape \\(3, 3\\)"):
        guess.anchors_m = np.zeros((3, 3))
    assert message(lambda: sagcal.calibrate(guess, problem["measurements"], noise="loud")) == (
        "invalid input: noise: unknown noise setting `loud` (paper, authors, none)"
    )
    assert message(lambda: sagcal.calibrate(guess, problem["measurements"], false_alarm=2.0)) == (
        "invalid input: false_alarm must be between 0 and 1, got 2"
    )


def test_too_few_poses_is_the_commands_error(cli, problem, tmp_path):
    few = problem["measurements"][:3]
    path = tmp_path / "few.csv"
    sagcal.write_measurements(path, few)
    expected = cli_error(cli("calibrate", "--robot", problem["folder"] / "guess.toml", "--data", path, check=False))
    assert message(lambda: sagcal.calibrate(problem["guess"], path)) == expected
    assert message(lambda: sagcal.calibrate(problem["guess"], few)) == expected.replace(str(path), "measurements", 1)


def test_simulate_errors_are_the_commands(cli, tmp_path):
    robot = ROOT / "robots" / "large.toml"
    out = tmp_path / "x.csv"
    large = sagcal.Robot.from_toml(robot)
    # The command's words, naming the keyword where the command names its flag.
    expected = cli_error(cli("simulate", "--robot", robot, "--poses", "0", "--out", out, check=False))
    assert expected == "invalid input: --poses must be at least 1"
    assert message(lambda: sagcal.simulate(large, 0)) == "invalid input: poses must be at least 1"
    expected = cli_error(
        cli("simulate", "--robot", robot, "--poses", "3", "--out", out, "--effect", "elastic:ea_n=-1", check=False)
    )
    assert expected.startswith("invalid input: --effect `elastic:ea_n=-1`: ")
    assert message(lambda: sagcal.simulate(large, 3, effects=["elastic:ea_n=-1"])) == expected.replace(
        "--effect `", "effects `"
    )
    assert not out.exists()


def test_messages_name_keywords_not_flags(cli, problem):
    folder, guess = problem["folder"], problem["guess"]
    # A refused fit: the command's message, naming the keyword that accepts it in Python.
    flags = ("calibrate", "--robot", folder / "guess.toml", "--data", folder / "data.csv", "--model", "rigid")
    expected = cli_error(cli(*flags, check=False))
    assert "(--accept-inconsistent writes it anyway): " in expected
    python = expected.replace("(--accept-inconsistent writes it anyway)", "(accept_inconsistent=True returns it anyway)")
    assert message(lambda: sagcal.calibrate(guess, folder / "data.csv", model="rigid")) == python
    # A bad override and an unknown candidate effect, named by keyword.
    assert message(lambda: sagcal.calibrate(guess, problem["measurements"], encoder_sigma_m=-1.0)) == (
        "invalid input: encoder_sigma_m must be a positive number, got -1"
    )
    assert message(lambda: sagcal.diagnose(guess, problem["measurements"], candidates=["magic"])).startswith(
        "invalid input: candidates: unknown effect `magic`"
    )
    # A localiser pose as a prior without one.
    assert message(lambda: sagcal.localize(problem["truth"], problem["measurements"][:, 6:10], pose_prior=True)) == (
        "readings: row 1, field `x_m`: pose_prior=True needs a localiser pose on every row; this file has none"
    )


def test_a_mistyped_kernel_switch_is_refused_on_import():
    import os
    import subprocess
    import sys

    env = dict(os.environ, SAGCAL_SIMD="fast")
    run = subprocess.run([sys.executable, "-c", "import sagcal"], env=env, capture_output=True, text=True)
    assert run.returncode != 0
    assert 'ValueError: SAGCAL_SIMD="fast": expected portable, avx2 or auto' in run.stderr


def test_each_kind_of_error_has_its_class(problem, tmp_path):
    guess, data = problem["guess"], problem["measurements"]

    def caught(call):
        with pytest.raises(sagcal.SagcalError) as error:
            call()
        return error.value

    missing = caught(lambda: sagcal.calibrate(guess, tmp_path / "missing.csv"))
    assert type(missing) is sagcal.FileError
    keyword = caught(lambda: sagcal.calibrate(guess, data, encoder_sigma_m=-1.0))
    assert type(keyword) is sagcal.InvalidInputError
    # A refused fit is a CalibrationError, apart from a file error.
    refused = caught(lambda: sagcal.calibrate(guess, data, model="rigid"))
    assert type(refused) is sagcal.CalibrationRefused
    assert isinstance(refused, sagcal.CalibrationError) and not isinstance(refused, sagcal.FileError)
    # A calibration that failed on a step carries that step's error as its cause.
    few = caught(lambda: sagcal.calibrate(guess, data[:3]))
    assert type(few) is sagcal.CalibrationError
    assert type(few.__cause__) is sagcal.InvalidInputError
    # One "invalid input: " only, the cause's own.
    assert str(few) == f"measurements: no robot file is written: {few.__cause__}"
    assert str(few.__cause__).startswith("invalid input: ")
    for kind in (sagcal.FileError, sagcal.InvalidInputError, sagcal.CalibrationError, sagcal.SolverError):
        assert issubclass(kind, sagcal.SagcalError) and kind.__module__ == "sagcal"
