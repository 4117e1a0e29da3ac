"""The RecurDyn finite-element log of the large robot (../shared/data, not in
the repository): the package reads it as the command does and calibrates
and localises to the same numbers."""

import numpy as np
import pytest

import sagcal
from conftest import ROOT, cli_json

LOG = ROOT.parent / "shared" / "data" / "recurdyn-large" / "recurdyn_large.csv"
ROBOT = ROOT / "robots" / "large.toml"


@pytest.fixture(scope="module")
def log():
    if not LOG.is_file():
        pytest.skip(f"{LOG} is absent (the shared data live beside the repository, never in it)")
    return LOG


def test_calibrate_the_recurdyn_log_as_the_command_does(cli, log):
    command = cli_json(cli("calibrate", "--robot", ROBOT, "--data", log, "--json"))
    result = sagcal.calibrate(sagcal.Robot.from_toml(ROBOT), log)
    assert result.report == command
    # The log's 57 usable rows as an array give the same anchors.
    data = sagcal.read_measurements(log)
    assert data.shape == (57, 11)
    from_array = sagcal.calibrate(sagcal.Robot.from_toml(ROBOT), data)
    np.testing.assert_array_equal(from_array.anchors_m, result.anchors_m)
    # The finite-element model was built with the nominal anchors: every coordinate within 3 of its stated sigmas.
    z = (result.anchors_m - sagcal.Robot.from_toml(ROBOT).anchors_m) / result.anchor_sigma_m
    assert np.all(np.abs(z) < 3.0), z


def test_localize_the_recurdyn_log_as_the_command_does(cli, log):
    command = cli_json(cli("localize", "--robot", ROBOT, "--data", log, "--json"))
    found = sagcal.localize(sagcal.Robot.from_toml(ROBOT), log)
    rows = command["rows"]
    assert found.rows == [r["row"] for r in rows] and found.lines == [r["line"] for r in rows]
    assert found.flags == [r["flag"] for r in rows]
    solved = [i for i, r in enumerate(rows) if r["position_m"] is not None]
    np.testing.assert_array_equal(found.positions_m[solved], [rows[i]["position_m"] for i in solved])
    np.testing.assert_array_equal(found.tensions_n[solved], [rows[i]["tensions_n"] for i in solved])
