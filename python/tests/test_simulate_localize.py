"""`sagcal.simulate`, the measurement files and `sagcal.localize` against the
command and against the simulation's truth."""

import numpy as np
import pytest

import sagcal
from conftest import ROOT, cli_json


def test_simulate_draws_the_commands_numbers(cli, problem, tmp_path):
    truth = problem["folder"] / "truth.toml"
    out = tmp_path / "cli.csv"
    cli("simulate", "--robot", truth, "--poses", 12, "--seed", 5, "--noise", "authors", "--out", out)
    simulation = sagcal.simulate(sagcal.Robot.from_toml(truth), 12, seed=5, noise="authors")
    # The command's file, read independently of sagcal, equals the array bit for bit.
    from_file = np.loadtxt(out, delimiter=",", comments="#", skiprows=4)
    assert simulation.measurements.shape == (12, 11) and simulation.measurements.dtype == np.float64
    np.testing.assert_array_equal(simulation.measurements, from_file)
    np.testing.assert_array_equal(sagcal.read_measurements(out), from_file)
    assert simulation.truth == sagcal.Robot.from_toml(truth) and simulation.seed == 5


def test_simulate_with_an_effect_draws_the_commands_numbers(cli, tmp_path):
    robot = ROOT / "robots" / "small.toml"
    out = tmp_path / "cli.csv"
    cli("simulate", "--robot", robot, "--poses", 4, "--seed", 2, "--effect", "elastic:ea_n=2e5", "--segments", 20, "--out", out)
    simulation = sagcal.simulate(sagcal.Robot.from_toml(robot), 4, seed=2, effects=["elastic:ea_n=2e5"], segments=20)
    np.testing.assert_array_equal(simulation.measurements, sagcal.read_measurements(out))
    assert simulation.truth.effects["axial_stiffness_n"] == 2e5


def test_measurement_files_round_trip_bit_for_bit(problem, tmp_path):
    path = tmp_path / "round.csv"
    data = problem["measurements"]
    sagcal.write_measurements(path, data, ["two", "comments"])
    assert path.read_text().startswith("# two\n# comments\nx_m,y_m,z_m,")
    np.testing.assert_array_equal(sagcal.read_measurements(path), data)
    with pytest.raises(sagcal.SagcalError, match=r"^measurements: row 2, field `y_m`: not a finite number: `inf`$"):
        bad = data.copy()
        bad[1, 1] = np.inf
        sagcal.write_measurements(tmp_path / "bad.csv", bad)
    assert not (tmp_path / "bad.csv").exists()


def test_localize_without_noise_finds_the_simulated_poses(problem):
    truth = problem["truth"]
    data = sagcal.simulate(truth, 8, seed=3, noise="none").measurements
    found = sagcal.localize(truth, data[:, 6:10], load_cell=data[:, 10], localiser_poses=data[:, :6])
    # Noise-free readings of the closed-form equilibria: the localiser poses are the true poses.
    np.testing.assert_allclose(found.positions_m, data[:, :3], rtol=0, atol=1e-6)
    np.testing.assert_allclose(found.roll_pitch_yaw_deg, data[:, 3:6], rtol=0, atol=1e-5)
    assert found.positions_m.shape == (8, 3) and found.tensions_n.shape == (8, 4)
    assert found.covariance.shape == (8, 6, 6) and found.position_sigma_m.shape == (8, 3)
    assert found.chi_square.shape == (8,) and np.all(found.chi_square < 1e-6)
    assert found.degrees_of_freedom == [1] * 8 and all(found.consistent) and all(found.stable)
    assert found.flags == [None] * 8 and found.rows == list(range(1, 9)) and found.lines == [None] * 8
    assert np.max(found.position_error_m) < 1e-6
    # The reference cable's tension is the load cell's reading.
    np.testing.assert_allclose(found.tensions_n[:, truth.reference_cable - 1], data[:, 10], rtol=1e-9)
    # Sigmas are the square roots of the covariance's position block.
    np.testing.assert_allclose(found.position_sigma_m, np.sqrt(np.diagonal(found.covariance[:, 3:, 3:], axis1=1, axis2=2)))
    # Encoders only: 0 degrees of freedom, the same equilibria.
    alone = sagcal.localize(truth, data[:, 6:10])
    assert alone.degrees_of_freedom == [0] * 8 and alone.position_error_m is None
    np.testing.assert_allclose(alone.positions_m, data[:, :3], rtol=0, atol=1e-6)


def test_localize_equals_the_command(cli, problem):
    folder = problem["folder"]
    command = cli_json(cli("localize", "--robot", folder / "truth.toml", "--data", folder / "data.csv", "--json"))
    found = sagcal.localize(problem["truth"], folder / "data.csv")
    rows = command["rows"]
    assert found.rows == [r["row"] for r in rows] and found.lines == [r["line"] for r in rows]
    np.testing.assert_array_equal(found.positions_m, [r["position_m"] for r in rows])
    np.testing.assert_array_equal(found.tensions_n, [r["tensions_n"] for r in rows])
    np.testing.assert_array_equal(found.chi_square, [r["chi_square"] for r in rows])
    assert found.flags == [r["flag"] for r in rows]
    np.testing.assert_array_equal(found.position_error_m, [r["position_error_m"] for r in rows])


def test_localize_input_errors(problem):
    data = problem["measurements"]
    lengths = data[:, 6:10].copy()
    lengths[2, 1] = np.nan
    with pytest.raises(sagcal.SagcalError, match=r"^readings: row 3, field `l2_m`: not a finite number: `NaN`$"):
        sagcal.localize(problem["truth"], lengths)
    with pytest.raises(sagcal.SagcalError, match=r"load_cell must be an array of shape \(30,\), got shape \(29,\)"):
        sagcal.localize(problem["truth"], data[:, 6:10], load_cell=data[:29, 10])
    with pytest.raises(sagcal.SagcalError, match=r"localiser_poses must be an array of shape \(30, 6\), got shape \(30, 3\)"):
        sagcal.localize(problem["truth"], data[:, 6:10], localiser_poses=data[:, :3])
    with pytest.raises(sagcal.SagcalError, match="needs a localiser pose on every row"):
        sagcal.localize(problem["truth"], data[:, 6:10], pose_prior=True)
