"""sagcal: self-calibration of suspended cable-driven parallel robots with
sagging (catenary) cables, after Dindarloo et al., *A Graph-Based
Self-Calibration Technique for Cable-Driven Robots with Sagging Cable*.

The Python face of the Rust library and the ``sagcal`` command: numpy arrays
in and out, the same jobs with the same options, results and error messages.

- :class:`Robot`: a robot description (TOML), its anchors, attachments,
  weights, encoder offsets and effects as numpy arrays and floats.
- :func:`simulate`: measurements of a robot (``sagcal simulate``).
- :func:`calibrate`: anchors and encoder offsets from measurements
  (``sagcal calibrate``), with their covariance and the gross-error tests.
- :func:`diagnose`: what the calibration model gets wrong (``sagcal diagnose``).
- :func:`localize`: pose and tensions from the cable readings (``sagcal localize``).
- :func:`read_measurements`, :func:`write_measurements`: sagcal's CSV (and
  RecurDyn logs) as (N, 11) arrays in the columns of :data:`MEASUREMENT_COLUMNS`.

Every error is a :class:`SagcalError` (a ``ValueError``) whose message is what
the command prints after ``error: ``.

Example::

    import sagcal
    truth = sagcal.Robot.builtin("large")
    data = sagcal.simulate(truth, poses=35, seed=7).measurements
    guess = truth.copy()
    guess.anchors_m = truth.anchors_m + 5.0
    result = sagcal.calibrate(guess, data, noise="paper")
    print(result.anchors_m - truth.anchors_m)
"""

from ._sagcal import (
    MEASUREMENT_COLUMNS,
    Calibration,
    Diagnosis,
    Localization,
    Robot,
    SagcalError,
    Simulation,
    __version__,
    calibrate,
    diagnose,
    localize,
    read_measurements,
    simulate,
    write_measurements,
)

# --- sagcal.plan (issue 19) --------------------------------------------------
# The pose planner (src/plan/) is being built on another branch. After the
# merge, register `plan` in python/src/lib.rs (the marked place there) and add
# `plan` (and its result class) to the import above, to __all__ below and to
# __init__.pyi (the marked place there), with a test in python/tests/.
# ------------------------------------------------------------------------------

__all__ = [
    "MEASUREMENT_COLUMNS",
    "Calibration",
    "Diagnosis",
    "Localization",
    "Robot",
    "SagcalError",
    "Simulation",
    "__version__",
    "calibrate",
    "diagnose",
    "localize",
    "read_measurements",
    "simulate",
    "write_measurements",
]
