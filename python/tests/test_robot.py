"""`sagcal.Robot`: the robot file's values as numpy arrays and floats."""

import copy

import numpy as np
import pytest

import sagcal
from conftest import ROOT


def test_values_are_the_files():
    path = ROOT / "robots" / "large.toml"
    tomllib = pytest.importorskip("tomllib", reason="tomllib needs Python 3.11")
    robot = sagcal.Robot.from_toml(path)
    with open(path, "rb") as f:
        file = tomllib.load(f)
    np.testing.assert_array_equal(robot.anchors_m, [c["anchor_m"] for c in file["cables"]])
    np.testing.assert_array_equal(robot.attachments_m, [c["attachment_m"] for c in file["cables"]])
    np.testing.assert_array_equal(robot.com_offset_m, file["com_offset_m"])
    assert robot.platform_weight_n == file["platform_weight_n"]
    assert robot.cable_weight_n_per_m == file["cable_weight_n_per_m"]
    assert robot.reference_cable == file["reference_cable"]
    assert robot.name == file["name"]
    np.testing.assert_array_equal(robot.length_offsets_m, np.zeros(4))
    assert robot == sagcal.Robot.builtin("large")


def test_shapes_dtypes_and_read_only_arrays():
    robot = sagcal.Robot.builtin("small")
    for name, shape in [("anchors_m", (4, 3)), ("attachments_m", (4, 3)), ("com_offset_m", (3,)), ("length_offsets_m", (4,))]:
        value = getattr(robot, name)
        assert value.shape == shape and value.dtype == np.float64, name
        with pytest.raises(ValueError, match="read-only"):
            value[0] = 1.0
    assert isinstance(robot.platform_weight_n, float) and isinstance(robot.reference_cable, int)


def test_setting_values_and_the_toml_round_trip(tmp_path):
    robot = sagcal.Robot.builtin("large")
    anchors = robot.anchors_m.copy()
    anchors[2] += [0.5, -0.25, 1.0]
    robot.anchors_m = anchors
    robot.length_offsets_m = [1, 2, 3, 4]  # lists and ints are taken as floats
    robot.platform_weight_n = 400.0
    robot.workspace = ([-10, -10, 2], [10, 10, 20])
    robot.effects = {"axial_stiffness_n": 3e6, "encoder_gain": [1.0, 1.001, 1.0, 1.0]}
    path = tmp_path / "robot.toml"
    robot.to_toml(path)
    back = sagcal.Robot.from_toml(path)
    assert back == robot
    np.testing.assert_array_equal(back.anchors_m, anchors)
    np.testing.assert_array_equal(back.length_offsets_m, [1.0, 2.0, 3.0, 4.0])
    assert back.platform_weight_n == 400.0
    np.testing.assert_array_equal(back.workspace[0], [-10.0, -10.0, 2.0])
    effects = back.effects
    assert effects["axial_stiffness_n"] == 3e6 and effects["cable_segments"] is None
    np.testing.assert_array_equal(effects["encoder_gain"], [1.0, 1.001, 1.0, 1.0])
    assert path.read_text() == robot.toml()
    # The dict the getter returns is accepted back as it is.
    again = sagcal.Robot.builtin("large")
    again.effects = robot.effects
    assert again.effects["axial_stiffness_n"] == 3e6
    np.testing.assert_array_equal(again.effects["encoder_gain"], robot.effects["encoder_gain"])
    # Every key of the robot file's [effects], the same as the file holds.
    every = {
        "axial_stiffness_n": 2e6,
        "pulley_radius_m": 0.05,
        "encoder_gain": [1.001, 1.0, 0.999, 1.0],
        "load_cell_bias_n": 1.5,
        "load_cell_gain": 1.01,
        "com_shift_m": [0.01, 0.0, -0.02],
        "cable_segments": 40.0,
        "localiser_mount_deg": [0.5, 0.0, 0.0],
        "platform_weight_scale": 1.05,
        "cable_weight_scale": 0.95,
        "encoder_drift_m_per_row": [1e-4, 0.0, 0.0, 2e-4],
        "encoder_backlash_m": [0.0, 1e-3, 0.0, 0.0],
        "load_cell_drift_n_per_row": 0.02,
        "load_cell_friction": 0.03,
        "attachment_shift_m": [[0.01, 0.0], [0.0, 0.0], [0.0, -0.01], [0.0, 0.0]],
    }
    full = sagcal.Robot.builtin("large")
    full.effects = every
    read = full.effects
    assert sorted(read) == sorted(every)
    for key, value in every.items():
        np.testing.assert_array_equal(read[key], value, err_msg=key)
    full.to_toml(tmp_path / "full.toml")
    assert sagcal.Robot.from_toml(tmp_path / "full.toml") == full
    copied = copy.deepcopy(robot)
    copied.name = "other"
    assert robot.name != "other"


def test_invalid_values_raise_the_loaders_message_and_change_nothing():
    robot = sagcal.Robot.builtin("large")
    before = robot.copy()
    anchors = robot.anchors_m.copy()
    anchors[1] = anchors[0]
    with pytest.raises(sagcal.SagcalError) as caught:
        robot.anchors_m = anchors
    assert str(caught.value).startswith("robot <Robot.anchors_m>: cables 1 and 2: coincident anchors at")
    with pytest.raises(sagcal.SagcalError, match=r"field `platform_weight_n` must be a positive weight in newtons, got -1"):
        robot.platform_weight_n = -1.0
    with pytest.raises(sagcal.SagcalError, match="cable 5 does not exist"):
        robot.reference_cable = 5
    with pytest.raises(sagcal.SagcalError, match="unknown field `spring`"):
        robot.effects = {"spring": 1.0}
    with pytest.raises(sagcal.SagcalError, match=r"^invalid input: anchors_m must be an array of shape \(4, 3\), got shape \(4, 2\)$"):
        robot.anchors_m = np.zeros((4, 2))
    with pytest.raises(sagcal.SagcalError, match="field `anchor_m` is not finite"):
        robot.anchors_m = np.full((4, 3), np.nan)
    assert robot == before
