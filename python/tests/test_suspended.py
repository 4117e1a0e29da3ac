"""Robots of 3 to 8 cables from Python: the same numbers as ``sagcal simulate``."""

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
