"""`sagcal.calibrate` against the `sagcal calibrate` command, to the last digit,
and against the truth of the simulation."""

import numpy as np
import pytest

import sagcal
from conftest import cli_json


@pytest.mark.parametrize("which", ["problem", "small_problem"])
def test_calibrate_equals_the_command_to_the_last_digit(cli, request, which):
    problem = request.getfixturevalue(which)
    folder, noise = problem["folder"], problem["noise"]
    command = cli_json(
        cli("calibrate", "--robot", folder / "guess.toml", "--data", folder / "data.csv", "--noise", noise, "--json")
    )
    from_file = sagcal.calibrate(problem["guess"], folder / "data.csv", noise=noise)
    # The whole report, every float bit for bit (JSON's shortest round-trip text).
    assert from_file.report == command
    # An array gives the same fit; only the names of rows differ (1-based rows, not file lines).
    from_array = sagcal.calibrate(problem["guess"], problem["measurements"], noise=noise)
    np.testing.assert_array_equal(from_array.anchors_m, np.array(command["anchors_m"]))
    np.testing.assert_array_equal(from_array.length_offsets_m, np.array(command["length_offsets_m"]))
    np.testing.assert_array_equal(from_array.anchor_sigma_m, np.array(command["anchor_sigma_m"]))
    assert from_array.termination == from_file.termination
    assert from_array.report["factor_statistics"] == command["factor_statistics"]


@pytest.mark.parametrize("which", ["problem", "small_problem"])
def test_calibration_recovers_the_truth_within_its_stated_uncertainty(request, which):
    problem = request.getfixturevalue(which)
    result = sagcal.calibrate(problem["guess"], problem["measurements"], noise=problem["noise"])
    truth = problem["truth"]
    assert result.converged and result.consistent and result.inconsistency is None
    # Normalised errors of the 12 anchor coordinates and 4 offsets: about N(0, 1).
    z_anchor = (result.anchors_m - truth.anchors_m) / result.anchor_sigma_m
    z_offset = (result.length_offsets_m - truth.length_offsets_m) / result.offset_sigma_m
    z = np.concatenate([z_anchor.ravel(), z_offset])
    assert np.all(np.abs(z) < 4.5), z
    # The guess was metres off; every anchor ends at most half as far from the truth.
    error = np.linalg.norm(result.anchors_m - truth.anchors_m, axis=1)
    guessed = np.linalg.norm(problem["guess"].anchors_m - truth.anchors_m, axis=1)
    assert np.all(error < guessed / 2), (error, guessed)
    # The covariance's diagonal is the reported sigma, and each block is symmetric positive definite.
    cov = result.anchor_covariance_m2
    np.testing.assert_allclose(np.sqrt(np.diagonal(cov, axis1=1, axis2=2)), result.anchor_sigma_m, rtol=1e-12)
    for block in cov:
        np.testing.assert_allclose(block, block.T, rtol=0, atol=1e-15)
        assert np.all(np.linalg.eigvalsh(block) > 0)


def test_result_shapes_dtypes_and_contents(problem):
    result = sagcal.calibrate(problem["guess"], problem["measurements"])
    n = result.poses_used
    for name, shape in [
        ("anchors_m", (4, 3)),
        ("length_offsets_m", (4,)),
        ("anchor_covariance_m2", (4, 3, 3)),
        ("anchor_sigma_m", (4, 3)),
        ("offset_sigma_m", (4,)),
        ("positions_m", (n, 3)),
        ("roll_pitch_yaw_deg", (n, 3)),
        ("reference_tensions_n", (n, 2)),
    ]:
        value = getattr(result, name)
        assert value.shape == shape, name
        assert value.dtype == np.float64, name
        assert not value.flags.writeable, name
    assert n == 30 and result.rows == list(range(1, 31)) and result.lines == [None] * 30
    kinds = {s["kind"] for s in result.factor_statistics}
    assert {"catenary_length", "reference_tension", "pose_prior"} <= kinds, kinds
    for s in result.factor_statistics:
        assert set(s) == {"kind", "factors", "components", "rms", "max_abs", "chi_square"}
        # rms is the root of chi-square over components.
        assert s["rms"] == pytest.approx(np.sqrt(s["chi_square"] / s["components"]), rel=1e-12)
    assert result.excluded_poses == [] and result.excluded_readings == [] and result.mistakes == []
    assert isinstance(result.termination, str) and result.iterations > 0
    assert [s["name"] for s in result.stages] == [s["name"] for s in result.report["stages"]]
    # The calibrated robot carries the estimates.
    np.testing.assert_array_equal(result.robot.anchors_m, result.anchors_m)
    np.testing.assert_array_equal(result.robot.length_offsets_m, result.length_offsets_m)
    # The estimated positions are the localiser's within a few of its 5 mm sigmas.
    assert np.max(np.abs(result.positions_m - problem["measurements"][:, :3])) < 0.03


def test_a_blunder_is_left_out_and_named(problem):
    data = problem["measurements"].copy()
    data[7, 6] += 5.0  # encoder of cable 1 at row 8 (1-based) reads 5 m long
    result = sagcal.calibrate(problem["guess"], data)
    assert len(result.excluded_readings) == 1
    test = result.excluded_readings[0]["test"]
    # Named as the text names it: row 8, cable 1; an array has no lines.
    assert (test["row"], test["line"], test["sensor"], test["cable"]) == (8, None, "encoder", 1)
    largest = result.report["gross_errors"]["tests"]["largest"]
    assert largest is not None and largest["line"] is None
    # Its estimated error is the blunder, to within the encoder noise (10 mm).
    assert test["estimated_error"] == pytest.approx(5.0, abs=0.05)


@pytest.mark.parametrize(
    "flags, keywords",
    [
        (["--model", "rigid", "--accept-inconsistent"], {"model": "rigid", "accept_inconsistent": True}),
        (["--encoder-sigma-m", "0.02", "--load-cell-sigma-n", "7"], {"encoder_sigma_m": 0.02, "load_cell_sigma_n": 7.0}),
        (["--robust-encoder", "huber:2", "--orientation-prior", "off"], {"robust_encoder": "huber:2", "orientation_prior": "off"}),
        (["--false-alarm", "0.01"], {"false_alarm": 0.01}),
    ],
)
def test_options_reach_the_solver_as_the_flags_do(cli, problem, flags, keywords):
    folder = problem["folder"]
    command = cli_json(cli("calibrate", "--robot", folder / "guess.toml", "--data", folder / "data.csv", "--json", *flags))
    result = sagcal.calibrate(problem["guess"], folder / "data.csv", **keywords)
    assert result.report == command
    default = sagcal.calibrate(problem["guess"], folder / "data.csv")
    if "false_alarm" not in keywords:  # the fit changes (the test's threshold only moves)
        assert result.report["factor_statistics"] != default.report["factor_statistics"]
    assert result.report["gross_errors"]["tests"] != default.report["gross_errors"]["tests"]
