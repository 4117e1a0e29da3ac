"""Type stubs of sagcal (the extension module `sagcal._sagcal`, re-exported)."""

import os
from typing import Any, Callable, Dict, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

#: The columns of a measurement array, in order (sagcal's CSV header).
MEASUREMENT_COLUMNS: Tuple[str, ...]

#: Anything numpy turns into a float64 array.
ArrayLike = npt.ArrayLike
#: A file path.
PathLike = Union[str, "os.PathLike[str]"]
#: A float64 array.
FloatArray = npt.NDArray[np.float64]

class SagcalError(ValueError):
    """A sagcal error; the message is what the ``sagcal`` command prints after ``error: ``."""

class FileError(SagcalError):
    """A file cannot be read or written, or one of its rows or fields is wrong."""

class RobotError(SagcalError):
    """A robot description is invalid."""

class InvalidInputError(SagcalError):
    """An argument is out of range or not understood (the message names the keyword)."""

class EquilibriumError(SagcalError):
    """The kineto-statics have no solution with positive cable tensions."""

class SolverError(SagcalError):
    """The solver failed."""

class CalibrationError(SagcalError):
    """A calibration gave no result; a failed step's error is the ``__cause__``."""

class CalibrationRefused(CalibrationError):
    """The fit fails its own consistency tests (``accept_inconsistent=True`` returns it anyway)."""

class FigureError(SagcalError):
    """A figure could not be rendered."""

class CancelledError(SagcalError):
    """The job was stopped on request."""

class Robot:
    """A suspended four-cable robot (a robot TOML file). Array attributes
    return new read-only float64 arrays: copy, edit, assign back."""

    @staticmethod
    def from_toml(path: PathLike) -> "Robot":
        """Read and validate a robot TOML file."""
    @staticmethod
    def builtin(name: str) -> "Robot":
        """A built-in robot: ``"large"`` or ``"small"``."""
    def to_toml(self, path: PathLike) -> None:
        """Write the robot as a TOML file (atomically)."""
    def toml(self) -> str:
        """The robot file's text (TOML)."""
    def copy(self) -> "Robot":
        """An independent copy."""
    def __copy__(self) -> "Robot": ...
    def __deepcopy__(self, memo: Any) -> "Robot": ...
    def __eq__(self, other: object) -> bool: ...
    name: str
    """Human-readable name."""
    @property
    def anchors_m(self) -> FloatArray:
        """Anchors of cables 1..4, world frame, metres: (4, 3)."""
    @anchors_m.setter
    def anchors_m(self, value: ArrayLike) -> None: ...
    @property
    def attachments_m(self) -> FloatArray:
        """Attachment points of cables 1..4, platform frame, metres: (4, 3)."""
    @attachments_m.setter
    def attachments_m(self, value: ArrayLike) -> None: ...
    @property
    def com_offset_m(self) -> FloatArray:
        """Centre of mass, platform frame, metres: (3,)."""
    @com_offset_m.setter
    def com_offset_m(self, value: ArrayLike) -> None: ...
    platform_weight_n: float
    """Platform weight, newtons."""
    cable_weight_n_per_m: float
    """Cable weight per metre, newtons per metre."""
    reference_cable: int
    """The cable with the load cell, 1..4 (as in the robot file)."""
    @property
    def length_offsets_m(self) -> FloatArray:
        """Encoder length offsets of cables 1..4, metres: (4,)."""
    @length_offsets_m.setter
    def length_offsets_m(self, value: ArrayLike) -> None: ...
    @property
    def workspace(self) -> Optional[Tuple[FloatArray, FloatArray]]:
        """``(min_m, max_m)`` of the pose box, or ``None``."""
    @workspace.setter
    def workspace(self, value: Optional[Tuple[ArrayLike, ArrayLike]]) -> None: ...
    @property
    def paper_robot(self) -> Optional[str]:
        """``"large"``, ``"small"`` or ``None``."""
    @property
    def effects(self) -> dict[str, Any]:
        """The effects beyond the closed-form model (every key)."""
    @effects.setter
    def effects(self, value: dict[str, Any]) -> None: ...

class Calibration:
    """The result of :func:`calibrate`."""

    @property
    def robot(self) -> Robot:
        """The calibrated robot."""
    @property
    def anchors_m(self) -> FloatArray:
        """Calibrated anchors, metres: (4, 3)."""
    @property
    def length_offsets_m(self) -> FloatArray:
        """Calibrated length offsets, metres: (4,)."""
    @property
    def anchor_covariance_m2(self) -> Optional[FloatArray]:
        """Per anchor its 3x3 covariance, m^2: (4, 3, 3); ``None`` if not observable."""
    @property
    def anchor_sigma_m(self) -> Optional[FloatArray]:
        """1-sigma per anchor coordinate, metres: (4, 3); ``None`` if not observable."""
    @property
    def offset_sigma_m(self) -> Optional[FloatArray]:
        """1-sigma per offset, metres: (4,); ``None`` if not observable."""
    @property
    def factor_statistics(self) -> list[dict[str, Any]]:
        """Normalised residual statistics per factor type."""
    @property
    def stages(self) -> list[dict[str, Any]]:
        """The solver stages in order."""
    @property
    def termination(self) -> str:
        """Why the final stage stopped, in words."""
    @property
    def converged(self) -> bool:
        """Whether the final stage stopped at a minimum."""
    @property
    def iterations(self) -> int:
        """Solver iterations over all stages."""
    @property
    def final_cost(self) -> float:
        """Cost of the final stage."""
    @property
    def poses_used(self) -> int:
        """Poses in the final solve."""
    @property
    def excluded_poses(self) -> list[dict[str, Any]]:
        """Poses without an equilibrium near them: ``row`` (1-based) and ``line`` (``None`` for an array)."""
    @property
    def excluded_readings(self) -> list[dict[str, Any]]:
        """Readings left out as gross errors."""
    @property
    def mistakes(self) -> list[dict[str, Any]]:
        """Common mistakes recognised in the data."""
    @property
    def consistent(self) -> bool:
        """Whether the fit passes its consistency tests."""
    @property
    def inconsistency(self) -> Optional[str]:
        """Why the fit fails its consistency tests, or ``None``."""
    @property
    def rows(self) -> list[int]:
        """1-based row of each pose the fit used."""
    @property
    def lines(self) -> list[Optional[int]]:
        """File line of each pose the fit used (``None`` for an array)."""
    @property
    def positions_m(self) -> FloatArray:
        """Estimated platform positions, metres: (M, 3)."""
    @property
    def roll_pitch_yaw_deg(self) -> FloatArray:
        """Estimated orientations, degrees: (M, 3)."""
    @property
    def reference_tensions_n(self) -> FloatArray:
        """Estimated reference tension ``(f_h, f_v)``, newtons: (M, 2)."""
    @property
    def report(self) -> dict[str, Any]:
        """The report as ``sagcal calibrate --json`` prints it."""

class Diagnosis:
    """The result of :func:`diagnose`."""

    @property
    def verdict(self) -> str:
        """The causes named, joined by ``+``; ``"none"``, ``"unexplained"``, or ``"X+unexplained"``; ``"X|Y"`` for one of two."""
    @property
    def explained(self) -> bool:
        """Whether the final model passes every sensor's test and holds no stand-in."""
    @property
    def stand_ins(self) -> list[str]:
        """The final model's hypotheses that fit only as proxies, each with what it stands in for."""
    @property
    def reason(self) -> str:
        """Why, in one sentence."""
    @property
    def effects(self) -> list[dict[str, Any]]:
        """The final model's effects with their parameters and 1-sigma."""
    @property
    def robot(self) -> Robot:
        """The final model's calibrated robot."""
    @property
    def baseline_consistent(self) -> bool:
        """Whether the baseline model passes its chi-square test."""
    @property
    def series(self) -> dict[str, Any]:
        """Residual against its strongest driver, before and after."""
    @property
    def report(self) -> dict[str, Any]:
        """The diagnosis as ``sagcal diagnose --json`` prints it."""

class Localization:
    """The result of :func:`localize` (one row per input row)."""

    @property
    def rows(self) -> list[int]:
        """1-based row of each row of readings."""
    @property
    def lines(self) -> list[Optional[int]]:
        """File line of each row (``None`` for an array)."""
    @property
    def positions_m(self) -> FloatArray:
        """Platform positions, metres: (N, 3)."""
    @property
    def roll_pitch_yaw_deg(self) -> FloatArray:
        """Orientations, degrees: (N, 3)."""
    @property
    def tensions_n(self) -> FloatArray:
        """Cable tensions, newtons: (N, 4)."""
    @property
    def position_sigma_m(self) -> FloatArray:
        """1-sigma of the position from the reading noise, metres: (N, 3)."""
    @property
    def covariance(self) -> FloatArray:
        """Covariance of the pose tangent ``[dtheta, dp]``: (N, 6, 6)."""
    @property
    def chi_square(self) -> FloatArray:
        """Chi-square of each row: (N,)."""
    @property
    def degrees_of_freedom(self) -> list[int]:
        """Degrees of freedom of each row's test (-1: no solution)."""
    @property
    def consistent(self) -> list[bool]:
        """Whether each row passes its chi-square test."""
    @property
    def stable(self) -> list[bool]:
        """Whether each row's equilibrium is stable."""
    @property
    def flags(self) -> list[Optional[str]]:
        """Why a row is not trusted (outside the robot's frame, a cable on the floor, unstable, inconsistent, no equilibrium), or ``None``."""
    @property
    def position_error_m(self) -> Optional[FloatArray]:
        """Distance from the input's localiser positions, metres: (N,), or ``None``."""

class SuspendedPlan:
    """The result of :func:`plan_suspended` (one row per chosen pose, in visiting order)."""

    @property
    def positions_m(self) -> FloatArray:
        """Commanded platform positions, metres: (poses, 3)."""
    @property
    def cable_lengths_m(self) -> FloatArray:
        """The lengths the drums pay out, metres: (poses, N)."""
    @property
    def min_horizontal_tension_n(self) -> FloatArray:
        """Each pose's smallest horizontal cable tension, newtons: (poses,)."""
    @property
    def measurements(self) -> FloatArray:
        """The nominal model's noise-free readings, in :attr:`SuspendedRobot.columns`."""
    @property
    def order(self) -> list[int]:
        """The candidates' indices in visiting order."""
    @property
    def anchor_covariance_m2(self) -> FloatArray:
        """Each anchor's 3x3 covariance of the bound, m^2: (N, 3, 3)."""
    @property
    def anchor_bound_m(self) -> float:
        """The plan's bound, RMS per anchor, metres."""
    @property
    def offset_bound_m(self) -> float:
        """The plan's bound, RMS per offset, metres."""
    @property
    def random_anchor_bound_m(self) -> float:
        """The mean bound of random sets of as many poses, RMS per anchor, metres."""
    @property
    def path_length_m(self) -> float:
        """The visiting path's length, metres."""
    @property
    def report(self) -> dict[str, Any]:
        """The report as ``sagcal plan --json`` prints it."""

class PosePlan:
    """The result of :func:`plan` (one row per chosen pose, in visiting order)."""

    @property
    def positions_m(self) -> FloatArray:
        """Commanded platform positions, metres: (N, 3)."""
    @property
    def roll_pitch_yaw_deg(self) -> FloatArray:
        """The nominal model's orientations, degrees: (N, 3)."""
    @property
    def cable_lengths_m(self) -> FloatArray:
        """The nominal model's cable lengths, metres: (N, 4)."""
    @property
    def min_horizontal_tension_n(self) -> FloatArray:
        """The smallest horizontal cable tension at each pose, newtons: (N,)."""
    @property
    def measurements(self) -> FloatArray:
        """The plan as noise-free measurements (what ``--out`` writes): (N, 11)."""
    @property
    def candidates_m(self) -> FloatArray:
        """The kept candidates' positions, metres: (M, 3)."""
    @property
    def order(self) -> list[int]:
        """The chosen candidates in visiting order (0-based rows of ``candidates_m``)."""
    @property
    def anchor_covariance_m2(self) -> FloatArray:
        """The plan's bound on each anchor's covariance, m^2: (4, 3, 3)."""
    @property
    def anchor_bound_m(self) -> float:
        """The plan's bound, RMS per anchor, metres."""
    @property
    def offset_bound_m(self) -> float:
        """The plan's bound, RMS per encoder offset, metres."""
    @property
    def random_anchor_bound_m(self) -> float:
        """Mean bound of random sets of as many candidates, RMS per anchor, metres."""
    @property
    def random_offset_bound_m(self) -> float:
        """Mean bound of random sets of as many candidates, RMS per offset, metres."""
    @property
    def random35_anchor_bound_m(self) -> Optional[float]:
        """Mean bound of random sets of 35 candidates, RMS per anchor, metres, or ``None``."""
    @property
    def path_length_m(self) -> float:
        """Length of the visiting path, metres."""
    @property
    def seed(self) -> int:
        """The random seed."""
    @property
    def report(self) -> dict[str, Any]:
        """The plan as ``sagcal plan --json`` prints it."""

class Simulation:
    """The result of :func:`simulate`."""

    @property
    def measurements(self) -> FloatArray:
        """The simulated measurements: (N, 11)."""
    @property
    def truth(self) -> Robot:
        """The true robot."""
    @property
    def seed(self) -> int:
        """The random seed."""

class SuspendedRobot:
    """A robot of 3 to 8 sagging cables (a robot TOML file with any number
    of ``[[cables]]``, per-cable weights and ``load_cells``)."""

    @staticmethod
    def builtin(name: str) -> "SuspendedRobot":
        """A built-in robot: ``"three"``, ``"six"``, ``"eight"``, ``"large"`` or ``"small"``."""
    @staticmethod
    def from_file(path: PathLike) -> "SuspendedRobot":
        """Read and validate a robot TOML file of 3 to 8 cables."""
    @property
    def name(self) -> str:
        """The robot's name."""
    @property
    def cable_count(self) -> int:
        """The number of cables."""
    @property
    def load_cells(self) -> list[int]:
        """The cables with a load cell, 1-based."""
    @property
    def columns(self) -> list[str]:
        """The columns of the robot's measurements."""
    @property
    def anchors_m(self) -> FloatArray:
        """The anchors of cables 1..N, metres: (N, 3)."""
    @property
    def length_offsets_m(self) -> FloatArray:
        """The encoder length offsets, metres: (N,)."""
    @property
    def axial_stiffness_n(self) -> list[float | None]:
        """Each cable's axial stiffness EA, newtons; ``None`` for an inextensible cable."""
    def toml(self) -> str:
        """The robot file's text (TOML)."""

class SuspendedSimulation:
    """The result of :func:`simulate_suspended`."""

    @property
    def measurements(self) -> FloatArray:
        """The simulated measurements: (N, 6 + cables + load cells)."""
    @property
    def seed(self) -> int:
        """The random seed."""
    def write(self, path: PathLike, comments: Optional[Sequence[str]] = None) -> None:
        """Write the measurements as ``sagcal simulate`` writes them (atomically)."""

class SuspendedCalibration:
    """The result of :func:`calibrate_suspended`."""

    @property
    def robot(self) -> SuspendedRobot:
        """The calibrated robot."""
    @property
    def anchors_m(self) -> FloatArray:
        """Calibrated anchors, metres: (N, 3)."""
    @property
    def length_offsets_m(self) -> FloatArray:
        """Calibrated length offsets, metres: (N,)."""
    @property
    def anchor_covariance_m2(self) -> Optional[FloatArray]:
        """Per anchor its 3x3 covariance, m^2: (N, 3, 3); ``None`` if not observable."""
    @property
    def anchor_sigma_m(self) -> Optional[FloatArray]:
        """1-sigma per anchor coordinate, metres: (N, 3); ``None`` if not observable."""
    @property
    def offset_sigma_m(self) -> Optional[FloatArray]:
        """1-sigma per offset, metres: (N,); ``None`` if not observable."""
    @property
    def positions_m(self) -> FloatArray:
        """Estimated platform positions, metres: (M, 3)."""
    @property
    def forces_n(self) -> FloatArray:
        """Estimated ``(f_h, f_v)`` of every cable, newtons: (M, N, 2)."""
    @property
    def chi_square(self) -> float:
        """The fit's chi-square."""
    @property
    def degrees_of_freedom(self) -> int:
        """Residual rows minus the unknowns the readings determine."""
    @property
    def undetermined_forces(self) -> list[dict[str, int]]:
        """The poses whose cable forces the readings do not determine (``pose``, ``directions``)."""
    @property
    def consistent(self) -> bool:
        """Whether the fit passes its chi-square test and the solver converged."""
    @property
    def inconsistency(self) -> Optional[str]:
        """Why the fit fails its test; ``None`` when it passes."""
    @property
    def readings_left_out(self) -> list[dict[str, Any]]:
        """The readings left out as gross errors, in the order found."""
    @property
    def report(self) -> dict[str, Any]:
        """The report as ``sagcal calibrate --json`` prints it."""

class SuspendedLocalization:
    """The result of :func:`localize_suspended`."""

    @property
    def positions_m(self) -> FloatArray:
        """Platform positions, metres: (M, 3); ``nan`` where a row has none."""
    @property
    def roll_pitch_yaw_deg(self) -> FloatArray:
        """``(roll, pitch, yaw)`` degrees: (M, 3)."""
    @property
    def position_sigma_m(self) -> FloatArray:
        """1-sigma of each position from the reading noise, metres: (M, 3)."""
    @property
    def ok(self) -> list[bool]:
        """Whether each row passes its chi-square test and is stable."""
    @property
    def rows_flagged(self) -> int:
        """The rows flagged."""
    @property
    def report(self) -> dict[str, Any]:
        """The report as ``sagcal localize --json`` prints it."""

def localize_suspended(
    robot: SuspendedRobot,
    measurements: Union[ArrayLike, PathLike],
    noise: str = "paper",
    *,
    false_alarm: float = 1e-3,
    progress: Optional[Callable[[int, int, str], Any]] = None,
) -> SuspendedLocalization:
    """Pose and forces of every row of a calibrated robot of 3 to 8 cables, as ``sagcal localize`` does."""

def calibrate_suspended(
    robot: SuspendedRobot,
    measurements: Union[ArrayLike, PathLike],
    noise: str = "paper",
    *,
    encoder_sigma_m: Optional[float] = None,
    load_cell_sigma_n: Optional[float] = None,
    position_sigma_m: Optional[float] = None,
    orientation_prior: str = "auto",
    robust_encoder: str = "none",
    robust_load_cell: str = "none",
    robust_pose: str = "none",
    false_alarm: float = 1e-3,
    accept_inconsistent: bool = False,
    progress: Optional[Callable[[int, int, str], Any]] = None,
) -> SuspendedCalibration:
    """Calibrate anchors and encoder offsets of a robot of 3 to 8 cables, as ``sagcal calibrate`` does."""

def calibrate(
    robot: Robot,
    measurements: Union[ArrayLike, PathLike],
    noise: str = "paper",
    *,
    model: str = "catenary",
    encoder_sigma_m: Optional[float] = None,
    load_cell_sigma_n: Optional[float] = None,
    position_sigma_m: Optional[float] = None,
    orientation_prior: str = "auto",
    robust_encoder: str = "none",
    robust_load_cell: str = "none",
    robust_pose: str = "none",
    false_alarm: float = 1e-3,
    accept_inconsistent: bool = False,
    progress: Optional[Callable[[int, int, str], Any]] = None,
) -> Calibration:
    """Calibrate anchors and encoder offsets, as ``sagcal calibrate`` does."""

def diagnose(
    robot: Robot,
    measurements: Union[ArrayLike, PathLike],
    noise: str = "paper",
    *,
    truth: Optional[Robot] = None,
    candidates: Optional[Sequence[str]] = None,
    orientation_hypothesis: bool = True,
    folds: int = 5,
    false_alarm: float = 1e-3,
    progress: Optional[Callable[[int, int, str], Any]] = None,
    model: str = "catenary",
    encoder_sigma_m: Optional[float] = None,
    load_cell_sigma_n: Optional[float] = None,
    position_sigma_m: Optional[float] = None,
    orientation_prior: str = "auto",
    robust_encoder: str = "none",
    robust_load_cell: str = "none",
    robust_pose: str = "none",
) -> Diagnosis:
    """Find what the calibration model gets wrong, as ``sagcal diagnose`` does."""

def diagnose_suspended(
    robot: SuspendedRobot,
    measurements: Union[ArrayLike, PathLike],
    noise: str = "paper",
    *,
    candidates: Optional[Sequence[str]] = None,
    folds: int = 5,
    false_alarm: float = 1e-3,
    orientation_prior: str = "auto",
    progress: Optional[Callable[[int, int, str], Any]] = None,
    truth: Optional[SuspendedRobot] = None,
) -> Dict[str, Any]:
    """What the model of a robot of 3 to 8 cables gets wrong, as ``sagcal diagnose --json`` reports it."""

def verify_suspended(
    robot: SuspendedRobot,
    measurements: Union[ArrayLike, PathLike],
    noise: str = "paper",
    *,
    false_alarm: float = 1e-3,
) -> Dict[str, Any]:
    """A robot file of 3 to 8 cables, held, against measurements, as ``sagcal verify --json`` reports it."""

def localize(
    robot: Robot,
    readings: Union[ArrayLike, PathLike],
    load_cell: Optional[ArrayLike] = None,
    localiser_poses: Optional[ArrayLike] = None,
    *,
    pose_prior: bool = False,
    noise: str = "paper",
    false_alarm: float = 1e-3,
    progress: Optional[Callable[[int, int, str], Any]] = None,
) -> Localization:
    """Pose and tensions from the cable readings, as ``sagcal localize`` does."""

def plan_suspended(
    robot: SuspendedRobot,
    poses: int,
    *,
    candidates: Union[int, ArrayLike, PathLike, None] = 1000,
    workspace: Union[Sequence[float], str, None] = None,
    noise: str = "paper",
    criterion: str = "a",
    seed: int = 1,
    orientation_prior: str = "off",
    progress: Optional[Callable[[int, int, str], Any]] = None,
) -> SuspendedPlan:
    """The calibration poses of a robot of 3 to 8 cables, as ``sagcal plan`` chooses them."""

def plan(
    robot: Robot,
    poses: int,
    *,
    candidates: Union[int, ArrayLike, PathLike, None] = 1000,
    workspace: Union[Sequence[float], str, None] = None,
    noise: str = "paper",
    criterion: str = "a",
    seed: int = 1,
    orientation_prior: str = "off",
    progress: Optional[Callable[[int, int, str], Any]] = None,
) -> PosePlan:
    """The calibration poses that best determine the anchors, as ``sagcal plan`` chooses them."""

def simulate(
    robot: Robot,
    poses: int,
    seed: int = 1,
    noise: str = "paper",
    *,
    effects: Optional[Sequence[str]] = None,
    segments: int = 100,
    closure: str = "level",
) -> Simulation:
    """Simulated measurements, as ``sagcal simulate`` draws them."""

def simulate_suspended(
    robot: SuspendedRobot,
    poses: int,
    seed: int = 1,
    noise: str = "paper",
    *,
    closure: str = "level",
    effects: Optional[Sequence[str]] = None,
    segments: int = 100,
) -> SuspendedSimulation:
    """Simulated measurements of a robot of 3 to 8 cables, as ``sagcal simulate`` draws them
    (with ``effects``, from the discretised simulator with ``segments`` segments per cable)."""

def init_robot(
    anchors_m: Optional[ArrayLike] = None,
    attachments_m: Optional[ArrayLike] = None,
    *,
    platform_mass_kg: Optional[float] = None,
    platform_weight_n: Optional[float] = None,
    cable_mass_per_m_kg: Optional[float] = None,
    cable_weight_n_per_m: Optional[float] = None,
    axial_stiffness_n: Optional[float] = None,
    com_offset_m: Optional[ArrayLike] = None,
    reference_cable: Optional[int] = None,
    workspace: Optional[Sequence[float]] = None,
    name: Optional[str] = None,
    from_template: Optional[str] = None,
    out: Optional[PathLike] = None,
    force: bool = False,
) -> str:
    """A new robot file's text (TOML, every key commented), as ``sagcal init`` writes it; with ``out``, written there."""

def check(robot: Union[Robot, SuspendedRobot, PathLike], data: Optional[PathLike] = None) -> dict[str, Any]:
    """What sagcal understood from a robot file and a data file, as ``sagcal check --json`` prints it."""

def read_measurements(path: PathLike, reference_cable: int = 1) -> FloatArray:
    """A measurement file (sagcal CSV or RecurDyn log) as an (N, 11) array."""

def write_measurements(path: PathLike, measurements: ArrayLike, comments: Optional[Sequence[str]] = None) -> None:
    """Write an (N, 11) array as a sagcal measurement file (atomically)."""
