"""`sagcal.plan` against `sagcal plan`: the same report to the last digit,
arrays that agree with it and with independent sums, the command's defaults
and error messages, and the same plan from the same seed."""

import inspect
import re

import numpy as np
import pytest

import sagcal
from conftest import ROOT, cli_json

SMALL = ROOT / "robots" / "small.toml"
LARGE = ROOT / "robots" / "large.toml"


@pytest.fixture(scope="module")
def small_plan():
    """6 poses of 60 candidates drawn in the small robot's default box (seed 3)."""
    return sagcal.plan(sagcal.Robot.from_toml(SMALL), 6, candidates=60, seed=3)


def test_the_report_is_the_commands_json(cli, small_plan, tmp_path):
    out = tmp_path / "plan.csv"
    done = cli("plan", "--robot", SMALL, "--poses", 6, "--candidates", 60, "--seed", 3, "--out", out, "--json")
    assert small_plan.report == cli_json(done)
    # `--out` and `measurements` are the same numbers, bit for bit.
    np.testing.assert_array_equal(small_plan.measurements, sagcal.read_measurements(out))


def test_every_option_reaches_the_planner_as_the_commands_flag(cli):
    done = cli(
        "plan", "--robot", LARGE, "--poses", 8, "--candidates", 50, "--seed", 5,
        "--workspace=-2,2,-2,2,1,4", "--criterion", "d", "--noise", "authors",
        "--orientation-prior", "on", "--json",
    )  # fmt: skip
    robot = sagcal.Robot.from_toml(LARGE)
    options = dict(candidates=50, seed=5, criterion="d", noise="authors", orientation_prior="on")
    planned = sagcal.plan(robot, 8, workspace=[-2, 2, -2, 2, 1, 4], **options)
    expected = cli_json(done)
    assert planned.report == expected
    assert sagcal.plan(robot, 8, workspace="-2,2,-2,2,1,4", **options).report == expected
    assert expected["criterion"] == "d" and expected["noise"] == "authors"
    assert expected["orientation_prior"] == "on"
    assert expected["workspace"] == {"min_m": [-2.0, -2.0, 1.0], "max_m": [2.0, 2.0, 4.0]}
    # The candidates were drawn in the box.
    assert np.all(planned.candidates_m >= [-2, -2, 1]) and np.all(planned.candidates_m <= [2, 2, 4])


def test_logged_poses_as_a_file_and_as_an_array(cli, tmp_path):
    robot = sagcal.Robot.from_toml(SMALL)
    logged = sagcal.simulate(robot, 40, seed=9).measurements
    path = tmp_path / "logged.csv"
    sagcal.write_measurements(path, logged)
    expected = cli_json(cli("plan", "--robot", SMALL, "--poses", 7, "--from", path, "--json"))
    from_file = sagcal.plan(robot, 7, candidates=path)
    assert from_file.report == expected
    assert sagcal.plan(robot, 7, candidates=str(path)).report == expected
    from_array = sagcal.plan(robot, 7, candidates=logged)
    assert from_array.report["candidates_from"] == "measurements"
    assert {**from_array.report, "candidates_from": str(path)} == expected
    # The plan visits logged poses: each planned position is one of the file's rows.
    for position in from_file.positions_m:
        assert np.min(np.linalg.norm(logged[:, :3] - position, axis=1)) == 0.0


def test_arrays_have_their_shapes_and_agree_with_the_report(small_plan):
    report = small_plan.report
    n = 6
    assert small_plan.positions_m.shape == (n, 3)
    assert small_plan.roll_pitch_yaw_deg.shape == (n, 3)
    assert small_plan.cable_lengths_m.shape == (n, 4)
    assert small_plan.min_horizontal_tension_n.shape == (n,)
    assert small_plan.measurements.shape == (n, 11)
    assert small_plan.anchor_covariance_m2.shape == (4, 3, 3)
    kept = report["candidates"]["examined"] - report["candidates"]["outside_margins"] - report["candidates"]["unstable"]
    assert small_plan.candidates_m.shape == (kept, 3)
    assert len(small_plan.order) == n == report["poses"] == len(set(small_plan.order))
    np.testing.assert_array_equal(small_plan.positions_m, [p["position_m"] for p in report["plan"]])
    np.testing.assert_array_equal(small_plan.cable_lengths_m, [p["cable_lengths_m"] for p in report["plan"]])
    np.testing.assert_array_equal(small_plan.candidates_m[small_plan.order], small_plan.positions_m)
    # The measurement rows: commanded positions, the model's orientation, and
    # encoder readings = cable length + the robot's offset (zero in small.toml).
    robot = sagcal.Robot.from_toml(SMALL)
    np.testing.assert_array_equal(small_plan.measurements[:, :3], small_plan.positions_m)
    np.testing.assert_allclose(small_plan.measurements[:, 3:6], small_plan.roll_pitch_yaw_deg, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        small_plan.measurements[:, 6:10], small_plan.cable_lengths_m + robot.length_offsets_m, rtol=0, atol=1e-12
    )
    assert np.all(small_plan.min_horizontal_tension_n > 0.0)
    # Independent sums: the path through the positions, and the bound as
    # sqrt(trace of the anchors' covariance / 4).
    legs = np.linalg.norm(np.diff(small_plan.positions_m, axis=0), axis=1)
    assert abs(legs.sum() - small_plan.path_length_m) < 1e-9
    traces = np.trace(small_plan.anchor_covariance_m2, axis1=1, axis2=2)
    assert abs(np.sqrt(traces.sum() / 4) - small_plan.anchor_bound_m) < 1e-12 * small_plan.anchor_bound_m
    assert small_plan.anchor_bound_m == report["anchor_bound_m"]
    assert small_plan.anchor_bound_m < small_plan.random_anchor_bound_m
    assert small_plan.random35_anchor_bound_m == report["random35_anchor_bound_m"]
    assert small_plan.seed == 3


def test_the_defaults_are_the_commands(cli):
    help_text = " ".join(cli("plan", "--help").stdout.split())
    defaults = {
        name: parameter.default
        for name, parameter in inspect.signature(sagcal.plan).parameters.items()
        if parameter.default is not inspect.Parameter.empty
    }
    for name, value in defaults.items():
        flag = "--" + name.replace("_", "-")
        shown = re.search(re.escape(flag) + r" <[A-Z_]+> [^\[]*?\[default: ([^\]]+)\]", help_text)
        if value is None:
            assert shown is None, (name, shown)
        else:
            assert shown is not None and shown.group(1) == str(value), (name, shown)


def test_same_seed_same_plan_and_another_seed_another(small_plan):
    robot = sagcal.Robot.from_toml(SMALL)
    again = sagcal.plan(robot, 6, candidates=60, seed=3)
    assert again.report == small_plan.report
    np.testing.assert_array_equal(again.positions_m, small_plan.positions_m)
    other = sagcal.plan(robot, 6, candidates=60, seed=4)
    assert not np.array_equal(other.candidates_m, small_plan.candidates_m)


def plan_error(done):
    """The message of a failed `sagcal plan`: its last stderr line (the first
    states the seed) without `error: `."""
    assert done.returncode == 1, f"expected exit code 1, got {done.returncode}: {done.stderr}"
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("error: "), done.stderr
    return last[len("error: ") :]


def message(call):
    with pytest.raises(sagcal.SagcalError) as caught:
        call()
    return str(caught.value)


def test_bad_input_raises_the_commands_message(cli):
    robot = sagcal.Robot.from_toml(SMALL)
    # More poses than candidates: the command's own error, word for word.
    expected = plan_error(cli("plan", "--robot", SMALL, "--poses", 50, "--candidates", 10, check=False))
    assert message(lambda: sagcal.plan(robot, 50, candidates=10)) == expected
    assert expected.startswith("invalid input: 50 poses requested but only 10 candidates")
    # A bad box or criterion: clap reports the parser's message, which the package names by its keyword.
    done = cli("plan", "--robot", SMALL, "--poses", 5, "--workspace", "1,2,3", check=False)
    assert done.returncode == 2
    text = message(lambda: sagcal.plan(robot, 5, workspace="1,2,3"))
    assert text.startswith("invalid input: workspace: ") and text[len("invalid input: workspace: ") :] in done.stderr
    assert message(lambda: sagcal.plan(robot, 5, workspace=[1, 2, 3])) == text
    inverted = message(lambda: sagcal.plan(robot, 5, workspace=[2, 1, 0, 1, 0, 1]))
    assert "x0 < x1" in inverted
    done = cli("plan", "--robot", SMALL, "--poses", 5, "--criterion", "c", check=False)
    text = message(lambda: sagcal.plan(robot, 5, criterion="c"))
    assert text == "invalid input: criterion: unknown design criterion `c` (a, d)"
    assert "unknown design criterion `c` (a, d)" in done.stderr
    # A missing file of logged poses.
    missing = ROOT / "no-such-poses.csv"
    expected = plan_error(cli("plan", "--robot", SMALL, "--poses", 5, "--from", missing, check=False))
    assert message(lambda: sagcal.plan(robot, 5, candidates=missing)) == expected
    # What only Python can get wrong.
    assert "cannot be negative" in message(lambda: sagcal.plan(robot, 5, candidates=-1))
    assert "not a bool" in message(lambda: sagcal.plan(robot, 5, candidates=True))
    assert "workspace goes with drawn candidates" in message(
        lambda: sagcal.plan(robot, 5, candidates=np.zeros((3, 11)), workspace=[0, 1, 0, 1, 0, 1])
    )
