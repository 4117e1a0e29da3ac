"""Robots of 3 to 8 cables from Python: the same numbers as ``sagcal simulate``."""

import json

import numpy as np
import pytest

import sagcal
from conftest import ROOT


@pytest.mark.parametrize("name, cables, load_cells", [("three", 3, [1]), ("six", 6, [1]), ("eight", 8, [1, 5])])
def test_simulate_suspended_draws_the_commands_numbers(cli, tmp_path, name, cables, load_cells):
    robot = sagcal.SuspendedRobot.builtin(name)
    assert (robot.cable_count, robot.load_cells) == (cables, load_cells)
    simulation = sagcal.simulate_suspended(robot, 6, seed=5)
    data = simulation.measurements
    assert data.shape == (6, 6 + cables + len(load_cells))
    assert robot.columns[6 + cables :] == [f"f{k}_n" for k in load_cells]
    out = tmp_path / "cli.csv"
    cli("simulate", "--robot", ROOT / "robots" / f"{name}.toml", "--poses", 6, "--seed", 5, "--out", out)
    rows = [line for line in out.read_text().splitlines() if not line.startswith("#")]
    assert rows[0] == ",".join(robot.columns)
    command = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    assert np.array_equal(command, data), "the same seed gives the command's numbers, bit for bit"
    written = tmp_path / "py.csv"
    simulation.write(written, comments=["from Python"])
    assert written.read_text().splitlines()[2:] == rows[1:]


def test_simulate_suspended_with_effects_is_the_commands_discretised_data(cli, tmp_path):
    robot = sagcal.SuspendedRobot.builtin("six")
    effects = ["elastic:ea_n=3e6", "pulley:radius_m=0.15"]
    simulation = sagcal.simulate_suspended(robot, 5, seed=4, effects=effects, segments=30)
    out = tmp_path / "cli.csv"
    cli("simulate", "--robot", ROOT / "robots" / "six.toml", "--poses", 5, "--seed", 4,
        "--effect", effects[0], "--effect", effects[1], "--segments", 30, "--out", out)
    rows = [line for line in out.read_text().splitlines() if not line.startswith("#")]
    command = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    assert np.array_equal(command, simulation.measurements), "the same seed and effects give the command's numbers"
    # The pulley's wrap and the stretch move the platform: not the closed-form data of the same seed.
    plain = sagcal.simulate_suspended(robot, 5, seed=4).measurements
    assert np.abs(plain[:, :3] - simulation.measurements[:, :3]).max() > 1e-3
    with pytest.raises(sagcal.SagcalError, match="the effect encoder-backlash.*not simulated on robots of 3 to 8 cables"):
        sagcal.simulate_suspended(robot, 2, effects=["elastic:ea_n=3e6", "encoder-backlash:b_m=0.002"])
    with pytest.raises(sagcal.SagcalError, match="effects `bogus:x=1`"):
        sagcal.simulate_suspended(robot, 2, effects=["bogus:x=1"])


def test_suspended_robot_errors_name_what_is_wrong(tmp_path):
    with pytest.raises(sagcal.SagcalError, match="unknown built-in robot `nine`"):
        sagcal.SuspendedRobot.builtin("nine")
    text = (ROOT / "robots" / "six.toml").read_text().replace("load_cells = [1]", "load_cells = [9]")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(sagcal.SagcalError, match="bad.toml.*cable 9 does not exist"):
        sagcal.SuspendedRobot.from_file(path)
    with pytest.raises(sagcal.SagcalError, match="three cables fix the platform's orientation"):
        sagcal.simulate_suspended(sagcal.SuspendedRobot.builtin("three"), 2, closure="yaw")


@pytest.mark.parametrize("name", ["three", "eight"])
def test_calibrate_suspended_gives_the_commands_report(cli, tmp_path, name):
    robot = sagcal.SuspendedRobot.builtin(name)
    simulation = sagcal.simulate_suspended(robot, 24, seed=3)
    data = tmp_path / "d.csv"
    simulation.write(data)
    stages = []
    result = sagcal.calibrate_suspended(robot, simulation.measurements, progress=lambda d, t, w: stages.append(w))
    assert stages[:3] == ["straight cables", "catenary (anchors held)", "catenary"] and stages[-1] == "done"
    assert result.anchors_m.shape == (robot.cable_count, 3)
    assert result.forces_n.shape == (24, robot.cable_count, 2)
    assert result.consistent and result.inconsistency is None
    # Within 4 sigma of the truth the data were simulated from, per coordinate.
    assert np.all(np.abs(result.anchors_m - robot.anchors_m) < 4 * result.anchor_sigma_m)
    report = cli("calibrate", "--robot", ROOT / "robots" / f"{name}.toml", "--data", data, "--json")
    command = json.loads(report.stdout)
    assert command["anchors_m"] == result.report["anchors_m"], "an array and its file give the command's numbers"
    assert command["chi_square"] == result.chi_square
    assert result.robot.toml().count("[[cables]]") == robot.cable_count


def test_undetermined_forces_are_reported(tmp_path):
    # Weightless cables on the eight-cable robot with one load cell: one force direction per pose
    # that no reading sees; a load cell on a second cable fixes it.
    text = (ROOT / "robots" / "eight.toml").read_text().replace("cable_weight_n_per_m = 2.5506", "cable_weight_n_per_m = 0.0")
    for load_cells, expected in [("[1]", [{"pose": k, "directions": 1} for k in range(1, 13)]), ("[1, 5]", [])]:
        path = tmp_path / "light.toml"
        path.write_text(text.replace("load_cells = [1, 5]", f"load_cells = {load_cells}"))
        robot = sagcal.SuspendedRobot.from_file(path)
        result = sagcal.calibrate_suspended(robot, sagcal.simulate_suspended(robot, 12, seed=2).measurements)
        assert result.undetermined_forces == expected == result.report["undetermined_forces"]
        assert result.anchor_sigma_m is not None and result.consistent
    # Elastic cables (EA 2 MN) with the one load cell: each encoder reads its tension, nothing is left open.
    path.write_text(text.replace("load_cells = [1, 5]", "load_cells = [1]\naxial_stiffness_n = 2.0e6"))
    robot = sagcal.SuspendedRobot.from_file(path)
    assert robot.axial_stiffness_n == [2.0e6] * 8
    result = sagcal.calibrate_suspended(robot, sagcal.simulate_suspended(robot, 12, seed=2, segments=20).measurements)
    assert result.undetermined_forces == [] and result.consistent
    assert result.report["axial_stiffness_n"] == [2.0e6] * 8


def test_calibrate_suspended_leaves_a_blunder_out_and_refuses_a_wrong_model(tmp_path):
    robot = sagcal.SuspendedRobot.builtin("six")
    data = np.array(sagcal.simulate_suspended(robot, 30, seed=7).measurements)
    data[4, 7] += 0.5  # cable 2 of row 5 reads 0.5 m long
    result = sagcal.calibrate_suspended(robot, data)
    assert result.consistent
    assert [(r["row"], r["reading"]) for r in result.readings_left_out] == [(5, {"encoder": 1})]
    # A platform 30 % heavier than the one the data were simulated with: a model error.
    heavy = tmp_path / "heavy.toml"
    text = (ROOT / "robots" / "six.toml").read_text()
    heavy.write_text(text.replace("platform_weight_n = 2943.0", "platform_weight_n = 3825.9"))
    wrong = sagcal.SuspendedRobot.from_file(heavy)
    with pytest.raises(sagcal.CalibrationRefused, match=r"accept_inconsistent=True returns it anyway"):
        sagcal.calibrate_suspended(wrong, data)
    accepted = sagcal.calibrate_suspended(wrong, data, accept_inconsistent=True)
    assert not accepted.consistent and accepted.inconsistency
    with pytest.raises(sagcal.SagcalError, match=r"measurements must be an \(N, 13\) array"):
        sagcal.calibrate_suspended(robot, data[:, :12])
    data[2, 12] = -1.0
    with pytest.raises(sagcal.SagcalError, match="row 3.*f1_n.*must be positive"):
        sagcal.calibrate_suspended(robot, data)


def test_localize_suspended_gives_the_commands_report(cli, tmp_path):
    robot = sagcal.SuspendedRobot.builtin("six")
    simulation = sagcal.simulate_suspended(robot, 12, seed=9)
    calibrated = sagcal.calibrate_suspended(robot, simulation.measurements)
    robot_file = tmp_path / "six.toml"
    robot_file.write_text(calibrated.robot.toml())
    data = tmp_path / "d.csv"
    simulation.write(data)
    found = sagcal.localize_suspended(calibrated.robot, simulation.measurements)
    assert found.rows_flagged == 0 and all(found.ok)
    assert found.positions_m.shape == (12, 3)
    # Each position near the localiser's (5 mm noise) within 5 of its combined 1-sigma.
    error = np.linalg.norm(found.positions_m - simulation.measurements[:, :3], axis=1)
    combined = np.sqrt(np.sum(found.position_sigma_m**2, axis=1) + 0.005**2)
    assert np.all(error < 5 * combined)
    command = json.loads(cli("localize", "--robot", robot_file, "--data", data, "--json").stdout)
    assert [r["position_m"] for r in command["rows"]] == [r["position_m"] for r in found.report["rows"]]
    with pytest.raises(sagcal.SagcalError, match="false_alarm must be between 0 and 1"):
        sagcal.localize_suspended(calibrated.robot, simulation.measurements, false_alarm=2.0)


def test_plan_suspended_is_the_commands_plan(cli, tmp_path):
    robot = sagcal.SuspendedRobot.builtin("eight")
    steps = []
    plan = sagcal.plan_suspended(robot, 12, candidates=60, seed=3, progress=lambda d, t, w: steps.append(w))
    assert steps[0].startswith("drawing 60 candidate poses") and steps[-1] == "done"
    out = tmp_path / "plan.csv"
    command = json.loads(cli("plan", "--robot", ROOT / "robots" / "eight.toml", "--poses", 12, "--candidates", 60,
                             "--seed", 3, "--out", out, "--json").stdout)
    assert command == plan.report
    assert plan.anchor_bound_m == command["anchor_bound_m"] < plan.random_anchor_bound_m
    assert plan.cable_lengths_m.shape == (12, 8) and plan.anchor_covariance_m2.shape == (8, 3, 3)
    rows = [line for line in out.read_text().splitlines() if not line.startswith("#")]
    written = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    np.testing.assert_array_equal(written, plan.measurements)



def test_plan_suspended_chooses_among_logged_poses_as_the_command_does(cli, tmp_path):
    robot = sagcal.SuspendedRobot.builtin("six")
    logged = sagcal.simulate_suspended(robot, 30, seed=8)
    path = tmp_path / "logged.csv"
    logged.write(path)
    plan = sagcal.plan_suspended(robot, 6, candidates=path)
    command = json.loads(cli("plan", "--robot", ROOT / "robots" / "six.toml", "--poses", 6, "--from", path,
                             "--json").stdout)
    assert command == plan.report
    assert plan.report["candidates_from"].startswith("30 logged poses of")
    from_array = sagcal.plan_suspended(robot, 6, candidates=logged.measurements)
    assert from_array.anchor_bound_m == plan.anchor_bound_m
    positions = logged.measurements[:, :3]
    for p in plan.measurements[:, :3]:
        assert np.min(np.max(np.abs(positions - p), axis=1)) < 1e-12, "each planned pose is a logged one"
    with pytest.raises(sagcal.InvalidInputError, match="candidates: -1"):
        sagcal.plan_suspended(robot, 6, candidates=-1)

def test_diagnose_suspended_is_the_commands_diagnosis(cli, tmp_path):
    robot = sagcal.SuspendedRobot.builtin("three")
    simulation = sagcal.simulate_suspended(robot, 16, seed=4)
    data = tmp_path / "d.csv"
    simulation.write(data)
    seen = []
    names = ["elastic", "encoder-scale"]
    report = sagcal.diagnose_suspended(robot, simulation.measurements, candidates=names, folds=4,
                                       progress=lambda d, t, w: seen.append((d, t)), truth=robot)
    assert seen[-1][0] == seen[-1][1] == 6, "the baseline's and each extension's fit and cross-validation"
    assert [e["extension"] for e in report["extensions"]] == names
    command = json.loads(cli("diagnose", "--robot", ROOT / "robots" / "three.toml", "--data", data,
                             "--candidates", ",".join(names), "--folds", 4, "--truth",
                             ROOT / "robots" / "three.toml", "--json").stdout)
    assert command == report, "an array and its file give the command's numbers"
    assert [m["model"] for m in report["against_truth"]] == ["baseline"] + names
    assert report["verdict"]["kind"] == "consistent"
    with pytest.raises(sagcal.InvalidInputError, match="`pulley` is not an extension"):
        sagcal.diagnose_suspended(robot, simulation.measurements, candidates=["pulley"])


def test_verify_suspended_is_the_commands_verification(cli, tmp_path):
    robot = sagcal.SuspendedRobot.builtin("six")
    simulation = sagcal.simulate_suspended(robot, 10, seed=6)
    data = tmp_path / "d.csv"
    simulation.write(data)
    report = sagcal.verify_suspended(robot, data)
    command = json.loads(cli("verify", "--robot", ROOT / "robots" / "six.toml", "--data", data, "--json").stdout)
    assert command == report, "the library call and the command give the same report"
    assert report["passes"] and report["degrees_of_freedom"] == 10 * 4, "3 positions and 1 load cell a row"
    from_array = sagcal.verify_suspended(robot, simulation.measurements)
    assert from_array["chi_square"] == report["chi_square"]
    with pytest.raises(sagcal.InvalidInputError, match="false_alarm: false-alarm rate 2"):
        sagcal.verify_suspended(robot, data, false_alarm=2.0)
