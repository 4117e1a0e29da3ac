"""`sagcal.diagnose` against the `sagcal diagnose` command."""

import numpy as np

import sagcal
from conftest import cli_json


def test_diagnose_equals_the_command(cli, problem):
    folder = problem["folder"]
    command = cli_json(
        cli(
            "diagnose", "--robot", folder / "guess.toml", "--data", folder / "data.csv",
            "--truth", folder / "truth.toml", "--folds", 2, "--candidates", "elastic,loadcell", "--json",
        )
    )
    calls = []
    found = sagcal.diagnose(
        problem["guess"], folder / "data.csv", truth=problem["truth"], folds=2,
        candidates=["elastic", "loadcell"], progress=lambda done, total, what: calls.append((done, total, what)),
    )
    assert found.report == command
    # Data from the closed-form model: no effect is declared.
    assert found.verdict == "none" == command["verdict"] and found.effects == []
    assert found.explained and command["explained"] and found.stand_ins == [] == command["stand_ins"]
    assert found.baseline_consistent
    # Progress: every fit announced, the last call says done.
    assert calls[-1][0] == calls[-1][1] and calls[-1][2] == "done" and len(calls) > 3
    series = found.series
    assert series["before"].ndim == 2 and series["before"].shape[1] == 2 and series["after"] is None
    np.testing.assert_array_equal(found.robot.anchors_m.shape, (4, 3))
