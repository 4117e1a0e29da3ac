"""The ``progress`` keyword of the long jobs (``plan``, ``calibrate``,
``localize``; ``diagnose`` in test_diagnose.py): called with ``(done, total,
what)`` as the library reports, counts increasing within a stage and the
last call ``(total, total, "done")``; an exception raised in the callback is
re-raised after the run; and the results are those of a run without it."""

import numpy as np
import pytest

import sagcal
from conftest import ROOT

SMALL = ROOT / "robots" / "small.toml"


def recorder():
    """A callback and the calls it received."""
    calls = []
    return calls, lambda done, total, what: calls.append((done, total, what))


def check_calls(calls):
    """Each call is (int, int, str) with 0 <= done <= total, done never
    falls while the stage stays, and the last call says done."""
    assert calls, "the callback was never called"
    for done, total, what in calls:
        assert isinstance(done, int) and isinstance(total, int) and isinstance(what, str)
        assert 0 <= done <= total, (done, total, what)
    for (done, _, what), (next_done, _, next_what) in zip(calls, calls[1:]):
        if next_what == what:
            assert next_done >= done, (what, done, next_done)
    done, total, what = calls[-1]
    assert done == total and what == "done", calls[-1]


class Raised(Exception):
    """What the callback raises."""


def raising(done, total, what):
    raise Raised(f"stop at {done} of {total}: {what}")


def test_plan_reports_drawing_and_choosing():
    robot = sagcal.Robot.from_toml(SMALL)
    calls, progress = recorder()
    planned = sagcal.plan(robot, 6, candidates=60, seed=3, progress=progress)
    check_calls(calls)
    drawing = [c for c in calls if c[2].startswith("drawing 60 candidate poses")]
    assert drawing[0][:2] == (0, 60) and drawing[-1][:2] == (60, 60)
    greedy = [c[:2] for c in calls if c[2] == "choosing the poses one by one"]
    assert greedy == [(k, 6) for k in range(7)]
    assert any(c[2].startswith("exchanging poses, pass 1 of at most") for c in calls)
    # The same plan as without the callback, to the last digit.
    assert planned.report == sagcal.plan(robot, 6, candidates=60, seed=3).report


def test_calibrate_reports_each_stage_of_each_fit(problem):
    data = problem["measurements"].copy()
    data[4, 7] += 2.0  # the drum of cable 2 slipped 2 m before row 5 was read
    calls, progress = recorder()
    result = sagcal.calibrate(problem["guess"], data, noise=problem["noise"], progress=progress)
    check_calls(calls)
    assert calls[0] == (0, 1, "calibration: rigid")
    stages = {what for _, _, what in calls}
    assert {"calibration: rigid", "calibration: catenary (relaxed statics)", "calibration: catenary"} <= stages
    # The blunder is searched for: more fits than one, each counted.
    assert any(what.startswith("gross-error search") for what in stages)
    fits = calls[-1][0]
    assert fits >= 2 and [c[0] for c in calls] == sorted(c[0] for c in calls)
    assert result.report == sagcal.calibrate(problem["guess"], data, noise=problem["noise"]).report


def test_localize_reports_the_rows(problem):
    data = problem["measurements"]
    calls, progress = recorder()
    found = sagcal.localize(problem["truth"], data[:, 6:10], load_cell=data[:, 10], progress=progress)
    check_calls(calls)
    rows = len(data)
    assert calls[0] == (0, rows, "localising rows") and calls[-1] == (rows, rows, "done")
    assert [c[0] for c in calls] == sorted(c[0] for c in calls)
    alone = sagcal.localize(problem["truth"], data[:, 6:10], load_cell=data[:, 10])
    np.testing.assert_array_equal(found.positions_m, alone.positions_m)
    np.testing.assert_array_equal(found.tensions_n, alone.tensions_n)
    np.testing.assert_array_equal(found.covariance, alone.covariance)


def test_a_long_input_calls_about_a_hundred_times(problem):
    data = problem["measurements"]
    lengths = data[:, 6:10].repeat(20, axis=0)  # 600 rows
    calls, progress = recorder()
    sagcal.localize(problem["truth"], lengths, progress=progress)
    check_calls(calls)
    assert 100 <= len(calls) <= 110, len(calls)


@pytest.mark.parametrize("job", ["plan", "calibrate", "localize"])
def test_an_exception_in_the_callback_is_raised_after_the_run(job, problem):
    data = problem["measurements"]
    with pytest.raises(Raised, match=r"stop at 0 of "):
        if job == "plan":
            sagcal.plan(sagcal.Robot.from_toml(SMALL), 6, candidates=30, seed=3, progress=raising)
        elif job == "calibrate":
            sagcal.calibrate(problem["guess"], data, noise=problem["noise"], progress=raising)
        else:
            sagcal.localize(problem["truth"], data[:, 6:10], progress=raising)


def test_an_error_of_the_job_comes_before_the_callbacks(problem):
    # Paper-noise data calibrated under the authors' 10 times smaller sigmas:
    # the fit fails its tests and is refused, whatever the callback raised.
    with pytest.raises(sagcal.CalibrationRefused):
        sagcal.calibrate(problem["guess"], problem["measurements"], noise="authors", progress=raising)
