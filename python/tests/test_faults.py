"""Faults at the Python boundary: a pose outside the robot's frame is flagged,
a massless cable localises, no Rust panic crosses as anything but a
SagcalError, Ctrl-C interrupts a long call, and every argument that cannot be
converted raises a SagcalError naming it."""

import os
import re
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import sagcal
from sagcal import _boundary


def message(call):
    with pytest.raises(sagcal.SagcalError) as caught:
        call()
    return str(caught.value)


@pytest.fixture(scope="module")
def demo(cli, tmp_path_factory):
    """The folder `sagcal demo` writes."""
    folder = tmp_path_factory.mktemp("demo")
    done = subprocess.run([str(cli_binary(cli)), "demo"], cwd=folder, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return folder / "sagcal-demo"


def cli_binary(cli):
    # The fixture's closure holds the binary; run `--version` through it to find it.
    from conftest import _find_binary

    return _find_binary()


def test_a_pose_below_the_floor_is_flagged(demo):
    robot = sagcal.Robot.from_toml(demo / "calibrated.toml")
    found = sagcal.localize(robot, np.array([[1000.0, 1000.0, 1000.0, 1000.0]]))
    assert found.positions_m[0, 2] < -900.0
    assert found.flags[0] is not None and "below the floor" in found.flags[0]
    # The same from a file, as the command reads it.
    path = demo.parent / "r.csv"
    path.write_text("l1_m,l2_m,l3_m,l4_m\n1000,1000,1000,1000\n")
    assert "below the floor" in sagcal.localize(robot, path).flags[0]


@pytest.mark.parametrize("weight", [0.0, 1e-9, 1e-3])
def test_a_massless_cable_localises(weight):
    robot = sagcal.Robot.builtin("large")
    robot.cable_weight_n_per_m = weight
    simulation = sagcal.simulate(robot, 20, seed=3)
    # Encoders and load cell, as the command reads the simulated file.
    readings, load_cell = simulation.measurements[:, 6:10], simulation.measurements[:, 10]
    found = sagcal.localize(robot, readings, load_cell)
    assert all(f is None for f in found.flags), found.flags
    assert all(found.stable)
    error = np.linalg.norm(found.positions_m - simulation.measurements[:, 0:3], axis=1)
    assert np.sqrt(np.mean(error**2)) < 0.1


def test_a_panic_becomes_a_sagcal_error_naming_the_call(demo, tmp_path):
    text = (demo / "truth.toml").read_text()
    below = re.sub(r"(?m)^(anchor_m = \[[^,]*,[^,]*,).*$", r"\1 -48.0]", text)
    path = tmp_path / "b.toml"
    path.write_text(below)
    try:
        robot = sagcal.Robot.from_toml(path)
    except sagcal.SagcalError:
        return  # refused when read: no panic to catch
    try:
        sagcal.simulate(robot, 5)
    except sagcal.SagcalError:
        pass  # an error, or a panic turned into one; any other exception fails the test
    try:
        sagcal.plan(robot, 4, candidates=20)
    except sagcal.SagcalError:
        pass


def test_the_boundary_turns_a_panic_into_a_sagcal_error():
    class PanicException(BaseException):
        """Stands for pyo3's exception of a Rust panic."""

    def explode(poses, seed=1):
        raise PanicException("cannot sample empty range")

    wrapped = _boundary.entry(explode, name="plan", ints={"poses": (0, 2**64)})
    text = message(lambda: wrapped(3))
    assert text.startswith("internal error in sagcal.plan: cannot sample empty range") and "please report" in text
    # Other errors pass through unchanged.
    with pytest.raises(ZeroDivisionError):
        _boundary.entry(lambda: 1 / 0, name="x")()


@pytest.mark.parametrize(
    "call, argument",
    [
        (lambda r: sagcal.simulate(r, -5), "poses"),
        (lambda r: sagcal.simulate(r, 3, seed=-1), "seed"),
        (lambda r: sagcal.simulate(r, 3, seed=2**64), "seed"),
        (lambda r: sagcal.simulate(r, "3"), "poses"),
        (lambda r: sagcal.simulate(r, 3, effects="elastic:ea_n=3e6"), "effects"),
        (lambda r: sagcal.plan(r, 4, seed=-1), "seed"),
        (lambda r: sagcal.diagnose(r, np.zeros((10, 11)), folds=-1), "folds"),
        (lambda r: sagcal.diagnose(r, np.zeros((10, 11)), candidates="elastic"), "candidates"),
        (lambda r: sagcal.read_measurements("x.csv", reference_cable=-1), "reference_cable"),
        (lambda r: sagcal.localize(r, [[1.0, 2.0, 3.0, 4.0]], false_alarm="x"), "false_alarm"),
        (lambda r: sagcal.write_measurements("x.csv", np.zeros((1, 11)), comments="a comment"), "comments"),
    ],
)
def test_an_argument_that_cannot_be_converted_is_named(call, argument, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    robot = sagcal.Robot.builtin("large")
    text = message(lambda: call(robot))
    assert argument in text, text
    assert not (tmp_path / "x.csv").exists()


def test_a_reference_cable_that_is_not_a_cable_number_is_named():
    robot = sagcal.Robot.builtin("large")
    for value in (-1, 2**64, "2"):
        with pytest.raises(sagcal.SagcalError, match="reference_cable"):
            robot.reference_cable = value


def test_ctrl_c_interrupts_a_long_call():
    # 20 000 poses run for minutes: a call that ends within the minute after
    # Ctrl-C was stopped by it (no clock of the shared machine is asserted:
    # a 10 s wait once ran out with two other long jobs on both cores).
    script = textwrap.dedent(
        """
        import faulthandler, signal, sys, threading, time, sagcal
        faulthandler.register(signal.SIGUSR1, all_threads=True)
        # A shell starts a background job (`make test &`, a CI runner) with
        # SIGINT ignored, and a child inherits that: Ctrl-C as a terminal sends it.
        signal.signal(signal.SIGINT, signal.default_int_handler)
        print("ready", flush=True)
        start = time.monotonic()
        try:
            sagcal.simulate(sagcal.Robot.builtin("large"), 20000)
        except KeyboardInterrupt:
            # The job itself stopped (the library's cancellation), not only the wait for it.
            working = [t.name for t in threading.enumerate() if t.name.startswith("sagcal.")]
            print(f"working {working} interrupted after {time.monotonic() - start:.2f}", flush=True)
            sys.exit(0)
        print("ran to the end", flush=True)
        sys.exit(1)
        """
    )
    process = subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    assert process.stdout.readline().strip() == "ready"
    import time

    time.sleep(1.5)
    process.send_signal(signal.SIGINT)
    try:
        out, _ = process.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        # Where every thread of the child is, for the report.
        process.send_signal(signal.SIGUSR1)
        time.sleep(2)
        process.kill()
        out, err = process.communicate()
        raise AssertionError(f"no end within 60 s of Ctrl-C; stdout {out!r}; the child's threads:\n{err}")
    finally:
        process.kill()
    assert process.returncode == 0, out
    assert "working []" in out, out
