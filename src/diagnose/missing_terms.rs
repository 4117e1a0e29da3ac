//! Step 5b: the structure a fitted model leaves, as terms it lacks, and the
//! term that would explain it (discovery).
//!
//! Each candidate term is one reading's residual linear in one physical
//! driver (`reading - model = c (driver - its mean)`):
//!
//! - the encoders against each per-cable driver (tension, tension x length,
//!   length, sag, elevation, wrap angle, platform height) and each pose
//!   driver (platform x and y and, where the rows are in the order taken,
//!   the row: a drift, and each cable's direction of last motion: friction,
//!   backlash, hysteresis), all four with one coefficient and each alone
//!   with its own (a drum's gain is one encoder against its cable length);
//! - the load cell against the same drivers, a per-cable driver taken at the
//!   cable it reads (a gain error is then `c` newtons per newton of its
//!   tension);
//! - the localiser's position and, where the model has the orientation as a
//!   prior, its orientation (the rotation error about world x, y, z, rad)
//!   against them, a per-cable driver taken as its mean over the cables;
//! - each reading against a constant, `reading - model = c`: a bias (an
//!   encoder's is its offset, so it is testable only where a pose is left
//!   out of the encoder terms, and is then an offset step of the others).
//!
//! A pose with a reading of the term's sensor left out as a gross error
//! takes no part in the term. The measured tension, a driver of step 2, is
//! not one here: it holds the load cell's own noise, so it correlates with
//! the residuals under any model.
//!
//! Each term gets Rao's score test at the fitted model
//! ([`crate::solver::score_tests`]): its coefficient with 1-sigma as if it
//! were added to the model and every parameter re-fitted, and `z`, standard
//! normal when the model holds. Unlike the correlations of step 2, the test
//! counts what the fit does to the residuals (the readings of one pose share
//! its pose and tension; the offsets absorb a constant per cable), so its
//! false-alarm rate is what it states: a term is structure the model misses
//! when `|z|` exceeds the two-sided limit at `false_alarm / m` over the `m`
//! testable terms (Bonferroni), and a model that holds shows one with
//! probability at most `false_alarm`.
//!
//! The proposed missing terms are a sparse regression of the whitened
//! residuals on these terms (in the spirit of SINDy, Brunton, Proctor and
//! Kutz 2016): forward selection, each step adding the term of largest
//! `|z|` given those chosen (its information and score with their
//! coefficients re-fitted, [`crate::solver::ScoreSystem::test`]) while it
//! exceeds the Bonferroni limit over the terms left, at most
//! [`MOST_PROPOSED`] of them; the terms chosen are reported in words and as
//! formulas with their coefficients fitted together. They are what the data ask for, not physical causes: the
//! report names them as terms, never as effects.

use serde::Serialize;

use super::drivers::{driver_value, drivers_tested, PoseSample, DIRECTION_DRIVER, MEASURED_TENSION, ROW_DRIVER};
use crate::calib::CalibrationGraph;
use crate::error::{Error, Result};
use crate::model::measurement::{PoseMeasurement, Sensor};
use crate::model::robot::CABLE_COUNT;
use crate::solver::{score_system, Direction};
use crate::stats::{chi_square_critical, chi_square_survival};

/// A term the fitted model lacks: one reading's residual linear in one driver.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MissingTerm {
    /// The reading (`encoder`, `load_cell`, `position_x|y|z`, `orientation_x|y|z`).
    pub residual: String,
    /// The driver, with its unit.
    pub driver: String,
    /// Readings in the test.
    pub points: usize,
    /// `c` of `reading - model = c (driver - its mean)`, in the reading's
    /// unit (metres or newtons) per unit of the driver.
    pub coefficient: f64,
    /// Its 1-sigma.
    pub sigma: f64,
    /// The score statistic `c / sigma`, standard normal when the model holds.
    pub z: f64,
    /// For a proposed term: the other terms missing alike, which these data
    /// do not tell from it (`residual vs driver`, [`ALIKE_SHARE`]).
    pub alike: Vec<String>,
}

/// The most terms proposed. Where the model is far from the data, the
/// residuals are no sum of a few terms and the regression would go on
/// finding more; a description a person can act on holds a few, the
/// strongest, and the report says how many more are missing.
pub const MOST_PROPOSED: usize = 3;

/// The most terms that describe what is wrong when the causes of a model
/// that does not explain the data are checked against them
/// (`CausesGivenTerms`): the same forward selection run on past
/// the 3 terms proposed while a term is beyond the limit given those chosen.
/// A proxy absorbs the part of a missing fault that the first few terms
/// leave (a centre-of-mass shift's tilt is three orientation terms, its
/// pull on the sags more); a cause is named only when it is needed beyond
/// everything the terms describe at the stated rate.
pub const MOST_DESCRIBING: usize = 30;

/// A missing term is named alike a proposed one when the proposed terms
/// explain it away (it is within the limit given them) and this one
/// carries at least this share of its information (the square of their
/// correlation with the model's parameters re-fitted, `M_jk^2 / (M_jj
/// M_kk)`, here a correlation of at least 0.5), more than any other
/// proposed term.
pub const ALIKE_SHARE: f64 = 0.25;

impl MissingTerm {
    /// The term as a formula with its coefficient and 1-sigma, and what
    /// such a term is in the robot, where a driver of time or motion says it.
    pub fn formula(&self) -> String {
        let unit = match self.residual.as_str() {
            "load_cell" => "N",
            r if r.starts_with("orientation") => "rad",
            _ => "m",
        };
        let per = match self.driver.as_str() {
            ROW_DRIVER => "row".to_string(),
            DIRECTION_DRIVER => "unit of the direction of last motion (+1 out, -1 in)".to_string(),
            driver => match (driver.find('('), driver.rfind(')')) {
                (Some(open), Some(close)) => format!("{} of {}", &driver[open + 1..close], driver[..open].trim()),
                _ => driver.to_string(),
            },
        };
        let cable = self.residual.strip_prefix("encoder_");
        let one_encoder = cable.map(|i| format!("encoder {i} reading"));
        let reading = match self.residual.as_str() {
            "encoder" => "encoder reading",
            _ if cable.is_some() => one_encoder.as_deref().unwrap_or("encoder reading"),
            "load_cell" => "load-cell reading",
            "position_x" => "localiser x",
            "position_y" => "localiser y",
            "position_z" => "localiser z",
            "orientation_x" => "localiser orientation about x",
            "orientation_y" => "localiser orientation about y",
            _ => "localiser orientation about z",
        };
        let encoder = if cable.is_some() {
            "encoder"
        } else {
            self.residual.as_str()
        };
        let what = match (encoder, self.driver.as_str()) {
            ("encoder", ROW_DRIVER) if cable.is_some() => ": the encoder drifts over time",
            ("encoder", ROW_DRIVER) => ": the encoders drift over time",
            ("load_cell", ROW_DRIVER) => ": the load cell drifts over time",
            ("encoder", DIRECTION_DRIVER) => ": the lengths depend on the direction of motion (backlash, hysteresis)",
            ("load_cell", DIRECTION_DRIVER) => ": the tension depends on the direction of motion (friction)",
            (_, ROW_DRIVER) => ": the localiser and the other readings part ways over time (a drift of either)",
            _ => "",
        };
        let alike = match self.alike.is_empty() {
            true => String::new(),
            false => format!(" (or, alike in these data: {})", self.alike.join(", ")),
        };
        if self.driver == CONSTANT_DRIVER {
            return format!(
                "{reading} - model = ({:+.3e} +- {:.1e}) {unit}, a constant bias (z = {:+.1}){alike}",
                self.coefficient, self.sigma, self.z
            );
        }
        format!(
            "{reading} - model = ({:+.3e} +- {:.1e}) {unit} per {per} (about its mean; z = {:+.1}){what}{alike}",
            self.coefficient, self.sigma, self.z
        )
    }
}

/// The readings whose residuals the terms describe: step 2's, the
/// localiser's orientation (its rotation error about world x, y, z, rad),
/// and each encoder alone (`encoder_1`..`encoder_4`: each drum has its own
/// hardware, and a fault of one drum, or one cable's share of a fault of the
/// platform, is no common term).
const TERM_RESIDUALS: [&str; 12] = [
    "encoder",
    "encoder_1",
    "encoder_2",
    "encoder_3",
    "encoder_4",
    "load_cell",
    "position_x",
    "position_y",
    "position_z",
    "orientation_x",
    "orientation_y",
    "orientation_z",
];

/// The driver of a constant bias: `reading - model = c` (not centred).
pub const CONSTANT_DRIVER: &str = "constant (a bias)";

/// What [`missing_terms`] finds.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TermsFound {
    /// Each term beyond the limit on its own, strongest first.
    pub missing: Vec<MissingTerm>,
    /// The forward selection of terms (each beyond the limit given those
    /// chosen before it), with their coefficients fitted jointly.
    pub proposed: Vec<MissingTerm>,
    /// The limit of `|z|` on the first step (`m` testable terms).
    pub limit: f64,
    /// The proposed terms' `(residual, driver)`.
    pub proposed_keys: Vec<(&'static str, &'static str)>,
    /// The forward selection run on to [`MOST_DESCRIBING`] terms (the
    /// proposed ones first), with their coefficients fitted jointly.
    pub describing: Vec<MissingTerm>,
    /// Their `(residual, driver)`.
    pub describing_keys: Vec<(&'static str, &'static str)>,
}

/// Are a model's causes still needed once the terms that describe what the
/// baseline misses ([`crate::diagnose::MOST_DESCRIBING`]) are added to
/// both? The likelihood ratio of the causes given the terms `T` is theirs
/// alone less what `T` gains in the baseline plus what
/// `T` gains in the model: `LR(C | T) = LR(C) - D_T(baseline) + D_T(model)`,
/// each gain `D_T = b_T^T M_TT^-1 b_T` the chi-square drop of adding `T`
/// by the score system (to first order); where the baseline and the model
/// can each be refitted with the terms as corrections of the readings
/// (`term_refit`), `LR(C | T)` is the difference of those refits'
/// chi-squares instead (`refitted`). Causes whose evidence the terms
/// explain as well are not needed: the data hold a fault that the terms
/// describe, and the causes fitted part of it as proxies.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CausesGivenTerms {
    /// The terms given, in words.
    pub terms: Vec<String>,
    /// `LR(C)`: the causes' likelihood ratio against the baseline.
    pub likelihood_ratio_alone: f64,
    /// `LR(C | T)`.
    pub likelihood_ratio: f64,
    /// Its degrees of freedom: the causes' parameters.
    pub dof: usize,
    /// Its p-value (chi-square with `dof` degrees of freedom).
    pub p_value: f64,
    /// Whether `p_value` is below the false-alarm rate: the causes are needed.
    pub needed: bool,
    /// Whether `likelihood_ratio` comes from the baseline and the model each
    /// refitted with the terms as corrections of the readings (`term_refit`);
    /// otherwise it is the first-order value above.
    pub refitted: bool,
}

impl CausesGivenTerms {
    /// This check with the likelihood ratio given the terms from refits
    /// (`likelihood_ratio`), tested at `false_alarm`.
    pub(super) fn refitted(self, likelihood_ratio: f64, false_alarm: f64) -> Self {
        let p_value = chi_square_survival(self.dof, likelihood_ratio.max(0.0));
        Self {
            likelihood_ratio,
            p_value,
            needed: p_value < false_alarm,
            refitted: true,
            ..self
        }
    }
}

/// The fitted models that [`causes_given_terms`] compares: the graph at the
/// solution and the samples of its poses.
pub(super) type FittedModel<'a> = (&'a CalibrationGraph, &'a [PoseSample]);

/// [`CausesGivenTerms`] of a model against the baseline, given the terms
/// proposed for the baseline; `likelihood_ratio_alone` is the causes' (the
/// chi-square drop over the variance factor), `dof` their parameters.
pub(super) fn causes_given_terms(
    (base, model): (FittedModel<'_>, FittedModel<'_>),
    used: &[PoseMeasurement],
    terms: &TermsFound,
    (likelihood_ratio_alone, variance_factor, dof): (f64, f64, usize),
    false_alarm: f64,
) -> Result<CausesGivenTerms> {
    let gain = |(graph, samples): FittedModel<'_>| -> Result<f64> {
        let directions: Vec<Direction> = terms
            .describing_keys
            .iter()
            .map(|(residual, driver)| direction_of(graph, used, samples, residual, driver).0)
            .collect();
        let system = score_system(&graph.graph, &directions)?;
        let (_, drop) = system
            .joint_fit()
            .ok_or_else(|| Error::InvalidInput("the proposed terms' information is singular".into()))?;
        Ok(drop)
    };
    let likelihood_ratio = likelihood_ratio_alone - (gain(base)? - gain(model)?) / variance_factor;
    let p_value = chi_square_survival(dof, likelihood_ratio.max(0.0));
    Ok(CausesGivenTerms {
        terms: terms.describing.iter().map(MissingTerm::formula).collect(),
        likelihood_ratio_alone,
        likelihood_ratio,
        dof,
        p_value,
        needed: p_value < false_alarm,
        refitted: false,
    })
}

/// The terms the fitted model (its graph at the solution, with the samples
/// of its poses) lacks (module docs).
pub(super) fn missing_terms(
    graph: &CalibrationGraph,
    used: &[PoseMeasurement],
    samples: &[PoseSample],
    time_order: bool,
    false_alarm: f64,
) -> Result<TermsFound> {
    let mut terms = Vec::new();
    let mut directions = Vec::new();
    // The measured tension holds the load cell's own noise: as a driver it
    // would correlate with the residuals under any model.
    let mut drivers: Vec<&str> = drivers_tested(time_order)
        .into_iter()
        .filter(|d| *d != MEASURED_TENSION)
        .collect();
    drivers.push(CONSTANT_DRIVER);
    for residual in TERM_RESIDUALS {
        for &driver in &drivers {
            // One encoder's constant is its length offset, always fitted.
            if residual.starts_with("encoder_") && driver == CONSTANT_DRIVER {
                continue;
            }
            let (direction, points) = direction_of(graph, used, samples, residual, driver);
            if points > 2 {
                directions.push(direction);
                terms.push((residual, driver, points));
            }
        }
    }
    let system = score_system(&graph.graph, &directions)?;
    let limit_of = |testable: usize| chi_square_critical(1, false_alarm / testable.max(1) as f64).sqrt();
    let term = |j: usize, given: &[usize]| {
        let (residual, driver, points) = terms[j];
        let t = system.test(j, given);
        MissingTerm {
            residual: residual.to_string(),
            driver: driver.to_string(),
            points,
            coefficient: t.coefficient,
            sigma: t.sigma,
            z: t.z,
            alike: Vec::new(),
        }
    };
    let alone: Vec<MissingTerm> = (0..terms.len()).map(|j| term(j, &[])).collect();
    let limit = limit_of(alone.iter().filter(|t| t.z.is_finite()).count());
    let beyond: Vec<usize> = (0..terms.len()).filter(|&j| alone[j].z.abs() > limit).collect();
    let mut missing: Vec<MissingTerm> = beyond.iter().map(|&j| alone[j].clone()).collect();
    missing.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    let describing_chosen = system.forward_selection(limit_of, MOST_DESCRIBING);
    let chosen = describing_chosen[..describing_chosen.len().min(MOST_PROPOSED)].to_vec();
    let proposed_keys = chosen.iter().map(|&j| (terms[j].0, terms[j].1)).collect();
    let describing_keys = describing_chosen.iter().map(|&j| (terms[j].0, terms[j].1)).collect();
    let describing = describing_chosen
        .iter()
        .map(|&j| {
            let others: Vec<usize> = describing_chosen.iter().copied().filter(|&k| k != j).collect();
            term(j, &others)
        })
        .collect();
    let m = &system.information;
    let share = |j: usize, k: usize| m[(j, k)] * m[(j, k)] / (m[(j, j)] * m[(k, k)]);
    let proposed = chosen
        .iter()
        .map(|&j| {
            let others: Vec<usize> = chosen.iter().copied().filter(|&k| k != j).collect();
            let mut proposed = term(j, &others);
            proposed.alike = beyond
                .iter()
                .filter(|&&k| !chosen.contains(&k) && system.test(k, &chosen).z.abs() <= limit)
                .filter(|&&k| {
                    let nearest = chosen
                        .iter()
                        .copied()
                        .max_by(|&a, &b| share(a, k).total_cmp(&share(b, k)));
                    nearest == Some(j) && share(j, k) >= ALIKE_SHARE
                })
                .map(|&k| format!("{} vs {}", terms[k].0, terms[k].1))
                .collect();
            proposed
        })
        .collect();
    Ok(TermsFound {
        missing,
        proposed,
        limit,
        proposed_keys,
        describing,
        describing_keys,
    })
}

/// The direction of the term `residual ~ driver` over the graph's factors
/// (whitened: the centred driver over each row's sigma), and its readings.
/// A factor with a reading left out takes no part.
pub(super) fn direction_of(
    graph: &CalibrationGraph,
    used: &[PoseMeasurement],
    samples: &[PoseSample],
    residual: &str,
    driver: &str,
) -> (Direction, usize) {
    let (kind, sensors) = factor_of(residual);
    let whole = |k: usize| !sensors.iter().any(|s| used[k].excluded.contains(*s));
    let constant = (driver == CONSTANT_DRIVER).then_some(1.0);
    // `encoder_i`: cable i's encoder alone (0-based here).
    let one_cable = residual
        .strip_prefix("encoder_")
        .and_then(|i| i.parse::<usize>().ok())
        .map(|i| i - 1);
    // Per pose: (row in the factor, driver value) of each reading in the test.
    let readings = |k: usize, rows: usize| -> Vec<(usize, f64)> {
        let s = &samples[k];
        let all: Vec<(usize, f64)> = match residual {
            r if r.starts_with("encoder") => (0..CABLE_COUNT)
                .filter(|i| one_cable.is_none_or(|c| c == *i))
                .filter_map(|i| Some((i, constant.or_else(|| driver_value(s, driver, Some(i)))?)))
                .collect(),
            "load_cell" => constant
                .or_else(|| driver_value(s, driver, Some(s.reference_cable)))
                .map(|x| (0, x))
                .into_iter()
                .collect(),
            _ => {
                // Position rows are the factor's last three; orientation rows
                // its first three, where it has them.
                let (axis, first) = match residual.strip_prefix("orientation_") {
                    Some(axis) => (axis, if rows == 6 { Some(0) } else { None }),
                    None => (residual.strip_prefix("position_").unwrap_or("z"), Some(rows - 3)),
                };
                let axis = ["x", "y", "z"].iter().position(|a| *a == axis).unwrap_or(2);
                let value = if driver == CONSTANT_DRIVER {
                    Some(1.0)
                } else {
                    driver_value(s, driver, None)
                };
                first
                    .zip(value)
                    .map(|(first, x)| (first + axis, x))
                    .into_iter()
                    .collect()
            }
        };
        all.into_iter().filter(|(_, x)| x.is_finite()).collect()
    };
    let per_factor: Vec<Option<Vec<(usize, f64)>>> = factor_poses(graph, used, kind, &sensors)
        .into_iter()
        .zip(&graph.graph.factors)
        .map(|(k, factor)| {
            let rows = factor.residual_dim();
            k.filter(|&k| whole(k) && (kind != "pose_prior" || rows >= 3))
                .map(|k| readings(k, rows))
        })
        .collect();
    let values: Vec<f64> = per_factor.iter().flatten().flatten().map(|(_, x)| *x).collect();
    let points = values.len();
    // A bias is the constant itself; every other driver is centred.
    let mean = match constant {
        Some(_) => 0.0,
        None => values.iter().sum::<f64>() / points.max(1) as f64,
    };
    let direction = per_factor
        .iter()
        .zip(&graph.graph.factors)
        .map(|(readings, factor)| {
            readings.as_ref().map(|readings| {
                let mut weights = vec![0.0; factor.residual_dim()];
                for (row, x) in readings {
                    weights[*row] = (x - mean) / factor.sigmas()[*row];
                }
                weights
            })
        })
        .collect();
    (direction, points)
}

/// Per factor of the graph (graph order), the pose (index into `used`) of
/// each factor of `kind` whose readings are `sensors`, `None` for the others.
/// A pose whose every reading of such a factor was left out has no factor
/// (`push_masked`): the factors of this kind are the other poses', in order.
pub(super) fn factor_poses(
    graph: &CalibrationGraph,
    used: &[PoseMeasurement],
    kind: &str,
    sensors: &[Sensor],
) -> Vec<Option<usize>> {
    let mut poses_with_factor = (0..used.len()).filter(|&k| !sensors.iter().all(|s| used[k].excluded.contains(*s)));
    graph
        .graph
        .factors
        .iter()
        .map(|factor| match factor.kind() == kind {
            true => poses_with_factor.next(),
            false => None,
        })
        .collect()
}

/// The kind of the factor that holds `residual`'s readings, and the sensors
/// of its rows.
pub(super) fn factor_of(residual: &str) -> (&'static str, Vec<Sensor>) {
    match residual {
        r if r.starts_with("encoder") => ("catenary_length", (0..CABLE_COUNT).map(Sensor::Encoder).collect()),
        "load_cell" => ("reference_tension", vec![Sensor::LoadCell]),
        _ => (
            "pose_prior",
            (0..3)
                .flat_map(|i| [Sensor::Position(i), Sensor::Orientation(i)])
                .collect(),
        ),
    }
}
