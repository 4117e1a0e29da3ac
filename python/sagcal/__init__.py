"""sagcal: self-calibration of suspended cable-driven parallel robots with
sagging (catenary) cables, after Dindarloo et al., *A Graph-Based
Self-Calibration Technique for Cable-Driven Robots with Sagging Cable*.

The Python face of the Rust library and the ``sagcal`` command: numpy arrays
in and out, the same jobs with the same options, results and error messages.

- :class:`Robot`: a robot description (TOML), its anchors, attachments,
  weights, encoder offsets and effects as numpy arrays and floats.
- :func:`simulate`: measurements of a robot (``sagcal simulate``);
  :class:`SuspendedRobot` and :func:`simulate_suspended`: a robot of 3 to 8
  cables and its measurements; :func:`calibrate_suspended` calibrates it,
  :func:`localize_suspended` localises it, :func:`plan_suspended` plans
  its calibration poses, :func:`diagnose_suspended` says what its model
  gets wrong and :func:`verify_suspended` tests a robot file against
  measurements.
- :func:`calibrate`: anchors and encoder offsets from measurements
  (``sagcal calibrate``), with their covariance and the gross-error tests.
- :func:`diagnose`: what the calibration model gets wrong (``sagcal diagnose``).
- :func:`localize`: pose and tensions from the cable readings (``sagcal localize``).
- :func:`plan`: the calibration poses that best determine the anchors, in a
  short visiting order (``sagcal plan``).
- :func:`init_robot`: a new, commented robot file from your robot's
  anchors, attachments and weights (``sagcal init``).
- :func:`check`: what sagcal understood from a robot file and a data file,
  before any fit, and their likely mistakes (``sagcal check``).
- :func:`read_measurements`, :func:`write_measurements`: sagcal's CSV (and
  RecurDyn logs) as (N, 11) arrays in the columns of :data:`MEASUREMENT_COLUMNS`.

Every error is a :class:`SagcalError` (a ``ValueError``) whose message is what
the command prints after ``error: ``; its subclass names the kind:
:class:`FileError` (a file, row or field), :class:`RobotError`,
:class:`InvalidInputError` (an argument), :class:`EquilibriumError`,
:class:`SolverError`, :class:`CalibrationError` with
:class:`CalibrationRefused` (a fit that fails its own consistency tests),
:class:`FigureError` and :class:`CancelledError`.

Example::

    import sagcal
    truth = sagcal.Robot.builtin("large")
    data = sagcal.simulate(truth, poses=35, seed=7).measurements
    guess = truth.copy()
    guess.anchors_m = truth.anchors_m + 5.0
    result = sagcal.calibrate(guess, data, noise="paper")
    print(result.anchors_m - truth.anchors_m)
"""

from . import _sagcal
from ._boundary import SEED_LIMIT as _SEED_LIMIT
from ._boundary import entry as _entry
from ._sagcal import (
    MEASUREMENT_COLUMNS,
    Calibration,
    CalibrationError,
    CalibrationRefused,
    CancelledError,
    Diagnosis,
    EquilibriumError,
    FigureError,
    FileError,
    InvalidInputError,
    Localization,
    PosePlan,
    Robot,
    RobotError,
    SagcalError,
    Simulation,
    SolverError,
    SuspendedCalibration,
    SuspendedLocalization,
    SuspendedPlan,
    SuspendedRobot,
    SuspendedSimulation,
    __version__,
)

# Every function through the boundary (sagcal/_boundary.py): arguments
# checked with errors naming them, no Rust panic crossing into Python as
# anything but a SagcalError, and Ctrl-C raising KeyboardInterrupt.
_COUNT = (0, _SEED_LIMIT)
calibrate = _entry(_sagcal.calibrate)
calibrate_suspended = _entry(_sagcal.calibrate_suspended)
check = _entry(_sagcal.check)
diagnose = _entry(_sagcal.diagnose, ints={"folds": _COUNT}, lists=("candidates",))
diagnose_suspended = _entry(_sagcal.diagnose_suspended, ints={"folds": _COUNT}, lists=("candidates",))
init_robot = _entry(_sagcal.init_robot)
localize = _entry(_sagcal.localize)
localize_suspended = _entry(_sagcal.localize_suspended)
plan = _entry(_sagcal.plan, ints={"poses": _COUNT, "seed": _COUNT})
plan_suspended = _entry(_sagcal.plan_suspended, ints={"poses": _COUNT, "seed": _COUNT})
read_measurements = _entry(_sagcal.read_measurements, ints={"reference_cable": (1, 5)})
simulate = _entry(_sagcal.simulate, ints={"poses": _COUNT, "seed": _COUNT, "segments": _COUNT}, lists=("effects",))
simulate_suspended = _entry(_sagcal.simulate_suspended, ints={"poses": _COUNT, "seed": _COUNT})
write_measurements = _entry(_sagcal.write_measurements, lists=("comments",))
verify_suspended = _entry(_sagcal.verify_suspended)

__all__ = [
    "MEASUREMENT_COLUMNS",
    "Calibration",
    "CalibrationError",
    "CalibrationRefused",
    "CancelledError",
    "Diagnosis",
    "EquilibriumError",
    "FigureError",
    "FileError",
    "InvalidInputError",
    "Localization",
    "PosePlan",
    "Robot",
    "RobotError",
    "SagcalError",
    "Simulation",
    "SolverError",
    "SuspendedCalibration",
    "SuspendedLocalization",
    "SuspendedPlan",
    "SuspendedRobot",
    "SuspendedSimulation",
    "__version__",
    "calibrate",
    "calibrate_suspended",
    "check",
    "diagnose",
    "diagnose_suspended",
    "init_robot",
    "localize",
    "localize_suspended",
    "plan",
    "plan_suspended",
    "read_measurements",
    "simulate",
    "simulate_suspended",
    "verify_suspended",
    "write_measurements",
]
