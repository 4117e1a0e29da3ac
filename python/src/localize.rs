//! `sagcal.localize`: the calibrated robot's pose and tensions from its cable
//! readings, row by row as `sagcal localize` does, with the library's
//! settings and checks (`sagcal::localize::LocalizeSettings`).

use std::path::PathBuf;

use nalgebra::Vector3;
use pyo3::prelude::*;
use sagcal::calib::check_false_alarm;
use sagcal::error::FrontEnd;
use sagcal::io::readings::{read_readings, ReadingRow};
use sagcal::localize::{require_pose_priors, LocalizeSettings, Localized, Localizer, Readings};
use sagcal::model::pose::PlatformPose;

use crate::arrays::{exact_rows, out1, out2, out3, rows, vector};
use crate::data::as_path;
use crate::options::noise_preset;
use crate::progress::Progress;
use crate::robot::Robot;
use crate::{invalid, to_py};

/// The result of :func:`localize`: per row of readings, the equilibrium
/// pose, the cable tensions, the pose's uncertainty from the reading noise
/// and the row's consistency test. Arrays have one row per input row; a row
/// without a trusted equilibrium has NaN values and its reason in :attr:`flags`.
#[pyclass(module = "sagcal", name = "Localization", frozen)]
pub struct Localization {
    lines: Vec<usize>,
    found: Vec<Option<Localized>>,
    flags: Vec<Option<String>>,
    position_error_m: Option<Vec<f64>>,
}

impl Localization {
    /// Per row, `value(found)` or NaNs.
    fn per_row<const C: usize>(&self, value: impl Fn(&Localized) -> [f64; C]) -> Vec<[f64; C]> {
        self.found
            .iter()
            .map(|f| f.as_ref().map_or([f64::NAN; C], &value))
            .collect()
    }
}

#[pymethods]
impl Localization {
    /// Per row, its number counted from 1 (the data rows of a file, the rows of an array).
    #[getter]
    fn rows(&self) -> Vec<usize> {
        (1..=self.lines.len()).collect()
    }

    /// Per row, its line in the file; ``None`` each for an array.
    #[getter]
    fn lines(&self) -> Vec<Option<usize>> {
        self.lines.iter().map(|&line| (line > 0).then_some(line)).collect()
    }

    /// Platform positions, world frame, metres: an (N, 3) array.
    #[getter]
    fn positions_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &self.per_row(|f| f.pose.position_m.into()))
    }

    /// Platform orientations ``(roll, pitch, yaw)``, degrees, ``R = Rz(yaw) Ry(pitch) Rx(roll)``: an (N, 3) array.
    #[getter]
    fn roll_pitch_yaw_deg<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(
            py,
            &self.per_row(|f| {
                let (r, p, y) = f.pose.roll_pitch_yaw_deg();
                [r, p, y]
            }),
        )
    }

    /// Cable tension magnitudes at the attachments, cables 1..4, newtons: an (N, 4) array.
    #[getter]
    fn tensions_n<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &self.per_row(Localized::tension_magnitudes_n))
    }

    /// 1-sigma of the position per world axis from the reading noise, metres: an (N, 3) array.
    #[getter]
    fn position_sigma_m<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        out2(py, &self.per_row(|f| f.position_sigma_m.into()))
    }

    /// Covariance of the pose tangent ``[dtheta (rad), dp (m)]`` from the
    /// reading noise: an (N, 6, 6) array.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let matrices: Vec<[[f64; 6]; 6]> = self
            .found
            .iter()
            .map(|f| {
                f.as_ref().map_or([[f64::NAN; 6]; 6], |f| {
                    std::array::from_fn(|r| std::array::from_fn(|c| f.covariance[(r, c)]))
                })
            })
            .collect();
        out3(py, &matrices)
    }

    /// Chi-square of the whitened readings at the solution: an (N,) array.
    #[getter]
    fn chi_square<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let values: Vec<f64> = self.per_row(|f| [f.chi_square]).into_iter().map(|[v]| v).collect();
        out1(py, &values)
    }

    /// Degrees of freedom of each row's test (readings minus 4; 0 with the encoders only; -1 for a row without a solution).
    #[getter]
    fn degrees_of_freedom(&self) -> Vec<i64> {
        self.found
            .iter()
            .map(|f| f.as_ref().map_or(-1, |f| f.degrees_of_freedom as i64))
            .collect()
    }

    /// Whether each row passes its chi-square test (``False`` for a row without a solution).
    #[getter]
    fn consistent(&self) -> Vec<bool> {
        self.found.iter().map(|f| f.is_some_and(|f| f.consistent)).collect()
    }

    /// Whether each row's equilibrium is stable at fixed cable lengths (``False`` for a row without a solution).
    #[getter]
    fn stable(&self) -> Vec<bool> {
        self.found.iter().map(|f| f.is_some_and(|f| f.stable)).collect()
    }

    /// Per row, why it has no trusted equilibrium (outside the robot's frame:
    /// below its floor, outside the anchors' hull or above them, or a cable
    /// lying on the floor; unstable; inconsistent; no equilibrium), in the
    /// command's words; ``None`` for a good row.
    #[getter]
    fn flags(&self) -> Vec<Option<String>> {
        self.flags.clone()
    }

    /// Distance of each position from the input's localiser position, metres
    /// (an (N,) array; ``None`` when the input has no localiser poses).
    #[getter]
    fn position_error_m<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.position_error_m.as_ref().map(|e| out1(py, e)).transpose()
    }

    fn __repr__(&self) -> String {
        format!(
            "Localization(rows={}, flagged={})",
            self.lines.len(),
            self.flags.iter().filter(|f| f.is_some()).count()
        )
    }
}

/// Localise the calibrated ``robot`` from its cable readings, as ``sagcal
/// localize`` does: per row, the static equilibrium (pose and the four cable
/// tensions) that the four encoder readings (and the load cell, if read)
/// imply through the catenary statics and the robot's ``effects``, warm-started
/// from the previous row's stable pose.
///
/// ``readings`` is an (N, 4) array of encoder readings ``l1_m .. l4_m``
/// (cable length plus the calibrated offset), or the path of a file the
/// command reads (``l1_m,l2_m,l3_m,l4_m[,f_ref_n]``, a sagcal measurement
/// file, a RecurDyn log). With an array, ``load_cell`` is an optional (N,)
/// array of the reference cable's tension (N) and ``localiser_poses`` an
/// optional (N, 6) array ``x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg``,
/// compared with (or, with ``pose_prior=True``, used as a prior). ``noise``
/// (``"paper"``, ``"authors"``) gives the reading sigmas; ``false_alarm`` the
/// rate of each row's chi-square test; ``progress`` an optional
/// ``callable(done, total, what)`` called as the rows go (``done`` rows
/// localised of ``total``; at most about a hundred calls), last with
/// ``(total, total, "done")``.
///
/// A row no stable equilibrium explains is flagged, not an error; bad input
/// raises :class:`SagcalError` with the command's message.
#[pyfunction]
#[pyo3(signature = (robot, readings, load_cell = None, localiser_poses = None, *, pose_prior = false, noise = "paper", false_alarm = 1e-3, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn localize(
    py: Python<'_>,
    robot: &Robot,
    readings: &Bound<'_, PyAny>,
    load_cell: Option<&Bound<'_, PyAny>>,
    localiser_poses: Option<&Bound<'_, PyAny>>,
    pose_prior: bool,
    noise: &str,
    false_alarm: f64,
    progress: Option<Py<PyAny>>,
) -> PyResult<Localization> {
    let robot = &robot.inner;
    let (label, input) = match as_path(readings) {
        Some(path) => {
            if load_cell.is_some() || localiser_poses.is_some() {
                return Err(invalid(
                    "load_cell and localiser_poses go with an array of readings; a file brings its own",
                ));
            }
            let file = read_readings(&path, robot.reference_cable).map_err(to_py)?;
            (file.path, file.rows)
        }
        None => (
            PathBuf::from("readings"),
            rows_from_arrays(readings, load_cell, localiser_poses)?,
        ),
    };
    if pose_prior {
        let rows = input.iter().map(|r| (r.line, r.localiser_pose));
        require_pose_priors(&label, rows, FrontEnd::Python).map_err(to_py)?;
    }
    let noise = noise_preset(noise)?;
    let false_alarm = check_false_alarm(false_alarm, "false_alarm", FrontEnd::Python).map_err(to_py)?;
    let localizer = LocalizeSettings {
        pose_prior,
        false_alarm,
        ..LocalizeSettings::new(noise)
    }
    .localizer(robot)
    .map_err(to_py)?;
    let progress = Progress::new(progress);
    let localization = py.detach(|| localize_rows(&localizer, &input, &progress))?;
    progress.finish()?;
    Ok(localization)
}

/// Every row in order, as the command localises them
/// (`sagcal::localize::Localizer::localize_sequence`, without the
/// multistart search), stopping at a stop request, telling `progress`.
fn localize_rows(localizer: &Localizer, input: &[ReadingRow], progress: &Progress) -> PyResult<Localization> {
    let readings: Vec<Readings> = input
        .iter()
        .map(|row| Readings {
            encoder_lengths_m: row.encoder_lengths_m,
            load_cell_n: row.load_cell_n,
            localiser_pose: row.localiser_pose,
        })
        .collect();
    let solved = localizer
        .localize_sequence_with_progress(
            &readings,
            false,
            &mut sagcal::cancel::requested,
            &mut |done, total, what| progress.report(done, total, what),
        )
        .map_err(to_py)?;
    let (found, flags): (Vec<Option<Localized>>, Vec<Option<String>>) =
        solved.into_iter().map(|row| (row.found.ok(), row.flag)).unzip();
    let position_error_m = input.iter().all(|r| r.localiser_pose.is_some()).then(|| {
        input
            .iter()
            .zip(&found)
            .map(|(r, f)| match (r.localiser_pose, f) {
                (Some(p), Some(f)) => (p.position_m - f.pose.position_m).norm(),
                _ => f64::NAN,
            })
            .collect()
    });
    Ok(Localization {
        lines: input.iter().map(|r| r.line).collect(),
        found,
        flags,
        position_error_m,
    })
}

/// Rows of readings from arrays, every value checked (finite; load cell positive).
fn rows_from_arrays(
    lengths: &Bound<'_, PyAny>,
    load_cell: Option<&Bound<'_, PyAny>>,
    poses: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<ReadingRow>> {
    let lengths = rows::<4>(lengths, "readings")?;
    let n = lengths.len();
    let load_cell = load_cell.map(|l| vector(l, n, "load_cell")).transpose()?;
    let poses = poses.map(|p| exact_rows::<6>(p, n, "localiser_poses")).transpose()?;
    let field = |source: &str, row: usize, field: &str, message: String| {
        to_py(sagcal::Error::Field {
            path: PathBuf::from(source),
            row,
            line: None,
            field: field.into(),
            message,
        })
    };
    let mut out = Vec::with_capacity(n);
    for (i, l) in lengths.iter().enumerate() {
        for (k, v) in l.iter().enumerate() {
            if !v.is_finite() {
                let name = format!("l{}_m", k + 1);
                return Err(field("readings", i + 1, &name, format!("not a finite number: `{v}`")));
            }
        }
        let f = load_cell.as_ref().map(|f| f[i]);
        if let Some(f) = f.filter(|f| !(f.is_finite() && *f > 0.0)) {
            let message = format!("not a positive number of newtons: `{f}`");
            return Err(field("load_cell", i + 1, "f_ref_n", message));
        }
        let pose = match &poses {
            None => None,
            Some(p) => {
                let [x, y, z, roll, pitch, yaw] = p[i];
                if let Some(v) = p[i].iter().find(|v| !v.is_finite()) {
                    return Err(field(
                        "localiser_poses",
                        i + 1,
                        "pose",
                        format!("not a finite number: `{v}`"),
                    ));
                }
                Some(PlatformPose::from_roll_pitch_yaw_deg(
                    Vector3::new(x, y, z),
                    roll,
                    pitch,
                    yaw,
                ))
            }
        };
        out.push(ReadingRow {
            line: 0,
            encoder_lengths_m: *l,
            load_cell_n: f,
            localiser_pose: pose,
        });
    }
    Ok(out)
}
