"""`sagcal.init_robot` and `sagcal.check`: the library calls of `sagcal init`
and `sagcal check`, with the same text, JSON and refusals (naming the
keyword instead of the flag). Expected numbers come from the inputs and the
files, not from sagcal."""

import numpy as np
import pytest

import sagcal
from conftest import ROOT, cli_json

ANCHORS = [[-6.25, -2.25, 28.5], [6.25, -2.25, 28.5], [6.25, 2.25, 28.5], [-6.25, 2.25, 28.5]]
ATTACHMENTS = [[-0.21, -0.21, -0.011], [0.21, -0.21, -0.011], [0.21, 0.21, -0.011], [-0.21, 0.21, -0.011]]


def lab(**changes):
    """The keyword arguments of a lab robot, with `changes`."""
    kwargs = dict(platform_mass_kg=4.4, cable_mass_per_m_kg=0.0102, com_offset_m=[0.0, 0.0, -0.3], name="lab")
    kwargs.update(changes)
    return kwargs


def test_the_text_loads_as_the_robot_given(tmp_path):
    text = sagcal.init_robot(ANCHORS, ATTACHMENTS, **lab(axial_stiffness_n=2e4, workspace=[-2, 2, -0.8, 0.8, 3, 18]))
    path = tmp_path / "lab.toml"
    path.write_text(text)
    robot = sagcal.Robot.from_toml(path)
    np.testing.assert_array_equal(robot.anchors_m, ANCHORS)
    np.testing.assert_array_equal(robot.attachments_m, ATTACHMENTS)
    np.testing.assert_array_equal(robot.com_offset_m, [0.0, 0.0, -0.3])
    assert robot.platform_weight_n == pytest.approx(4.4 * 9.81, rel=1e-14)
    assert robot.cable_weight_n_per_m == pytest.approx(0.0102 * 9.81, rel=1e-14)
    assert robot.effects["axial_stiffness_n"] == 2e4
    assert robot.reference_cable == 1 and robot.name == "lab"
    np.testing.assert_array_equal(robot.workspace[0], [-2.0, -0.8, 3.0])
    np.testing.assert_array_equal(robot.workspace[1], [2.0, 0.8, 18.0])
    # Every key has a comment line above it.
    lines = text.splitlines()
    for k, line in enumerate(lines):
        if " = " in line and not line.startswith("#"):
            assert lines[k - 1].startswith("#"), line


def test_out_writes_the_text_and_refuses_to_overwrite(tmp_path):
    path = tmp_path / "lab.toml"
    text = sagcal.init_robot(ANCHORS, ATTACHMENTS, out=path, **lab())
    assert path.read_text() == text == sagcal.init_robot(ANCHORS, ATTACHMENTS, **lab())
    with pytest.raises(sagcal.InvalidInputError, match="force=True"):
        sagcal.init_robot(ANCHORS, ATTACHMENTS, out=path, **lab(name="other"))
    assert path.read_text() == text
    sagcal.init_robot(ANCHORS, ATTACHMENTS, out=path, force=True, **lab(name="other"))
    assert sagcal.Robot.from_toml(path).name == "other"


def test_the_same_text_as_the_command(cli):
    flags = [f"--anchor={','.join(map(str, a))}" for a in ANCHORS]
    flags += [f"--attachment={','.join(map(str, b))}" for b in ATTACHMENTS]
    done = cli("init", *flags, "--platform-mass-kg", "4.4", "--cable-mass-per-m-kg", "0.0102", "--com-offset-m=0,0,-0.3", "--name", "lab")
    assert done.stdout == sagcal.init_robot(ANCHORS, ATTACHMENTS, **lab())


def test_a_template_fills_what_is_not_given():
    small = sagcal.Robot.builtin("small")
    text = sagcal.init_robot(from_template="small", platform_mass_kg=5.0)
    assert "from the built-in `small` robot" in text
    assert "platform_weight_n = 49.05\n" in text  # 5 kg x 9.81 m/s^2
    assert f"cable_weight_n_per_m = {small.cable_weight_n_per_m!r}\n" in text


@pytest.mark.parametrize(
    "anchors, attachments, changes, named",
    [
        (ANCHORS, np.array(ATTACHMENTS) * 1e3, {}, "attachments_m"),  # millimetres
        (np.array(ANCHORS) * 1e3, ATTACHMENTS, {}, "anchors_m"),
        (ANCHORS, ATTACHMENTS, {"platform_mass_kg": 1e-7}, "platform_mass_kg 1e-7"),
        (ANCHORS, ATTACHMENTS, {"cable_mass_per_m_kg": 10.2}, "cable_mass_per_m_kg 10.2"),
        (ANCHORS, ATTACHMENTS, {"axial_stiffness_n": 20.0}, "axial_stiffness_n 20"),
        (ANCHORS, ATTACHMENTS, {"reference_cable": 5}, "reference_cable"),
        (ANCHORS, ATTACHMENTS, {"platform_weight_n": 43.0}, "platform_mass_kg and platform_weight_n"),
        (ANCHORS[:3], ATTACHMENTS, {}, "anchors_m: 3 points given"),
        (ANCHORS, ATTACHMENTS, {"workspace": [-2, 2, -1, 1, 3, 30]}, "workspace"),
    ],
)
def test_refusals_name_the_keyword(anchors, attachments, changes, named):
    with pytest.raises(sagcal.InvalidInputError, match=named):
        sagcal.init_robot(anchors, attachments, **lab(**changes))


def test_what_is_missing_is_named():
    with pytest.raises(sagcal.InvalidInputError, match="cable_mass_per_m_kg: missing"):
        sagcal.init_robot(ANCHORS, ATTACHMENTS, platform_mass_kg=4.4)


def test_check_is_the_commands_json(problem, cli):
    folder = problem["folder"]
    robot, data = folder / "guess.toml", folder / "data.csv"
    report = sagcal.check(robot, data)
    assert report == cli_json(cli("check", "--robot", robot, "--data", data, "--json"))
    lines = [(k + 1, line) for k, line in enumerate(data.read_text().splitlines()) if not line.startswith("#")]
    read = report["data"]
    assert read["format"] == "sagcal-csv"
    assert read["rows"] == len(lines) - 1 == len(problem["measurements"])
    assert (read["samples"][0]["row"], read["samples"][0]["line"]) == (1, lines[1][0])
    np.testing.assert_array_equal(read["samples"][0]["values"], problem["measurements"][0])
    assert [c["unit"] for c in read["columns"]] == ["m"] * 3 + ["deg"] * 3 + ["m"] * 4 + ["N"]
    np.testing.assert_array_equal(
        [[c["range"]["min"], c["range"]["max"]] for c in read["columns"]],
        np.stack([problem["measurements"].min(axis=0), problem["measurements"].max(axis=0)], axis=1),
    )
    assert report["warnings"] == []
    # A Robot instead of its file: the same data read.
    assert sagcal.check(problem["guess"], data)["data"] == read
    assert sagcal.check(robot)["data"] is None


def test_check_flags_a_column_in_millimetres(problem, tmp_path):
    measurements = problem["measurements"].copy()
    measurements[:, 6:10] *= 1e3
    sagcal.write_measurements(tmp_path / "mm.csv", measurements)
    units = [w for w in sagcal.check(problem["guess"], tmp_path / "mm.csv")["warnings"] if w["kind"] == "unit"]
    assert len(units) == 4 and all("look like mm" in w["message"] for w in units), units


def test_unreadable_files_raise_naming_them(tmp_path):
    with pytest.raises(sagcal.FileError, match="missing.csv"):
        sagcal.check(ROOT / "robots" / "large.toml", tmp_path / "missing.csv")
    with pytest.raises(sagcal.FileError, match="missing.toml"):
        sagcal.check(tmp_path / "missing.toml")


def test_check_reads_a_robot_of_six_cables_as_the_command_does(cli, tmp_path):
    robot = sagcal.SuspendedRobot.builtin("six")
    data = tmp_path / "six.csv"
    sagcal.simulate_suspended(robot, 10, seed=2).write(data)
    path = ROOT / "robots" / "six.toml"
    report = sagcal.check(path, data)
    assert report == cli_json(cli("check", "--robot", path, "--data", data, "--json"))
    assert report["robot"]["free_force_components"] == 6 and report["warnings"] == []
    assert sagcal.check(robot, data)["data"]["rows"] == 10
