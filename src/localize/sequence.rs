//! Rows of readings localised in the order given, as `sagcal localize` and
//! `sagcal.localize` run them: each row warm-started from the last stable
//! pose inside the robot's frame, a row no trusted equilibrium explains
//! flagged (never an error), and, on request, the multistart search for
//! every equilibrium of the row's readings.

use super::localizer::{Localized, Localizer, Readings};
use crate::error::Result;
use crate::model::pose::PlatformPose;

/// One row of a sequence, localised.
#[derive(Debug)]
pub struct SequenceRow {
    /// The equilibrium chosen, or why there is none.
    pub found: Result<Localized>,
    /// Why the row is not a trusted localisation ([`Localizer::flag`], or
    /// the error); `None` for a good row.
    pub flag: Option<String>,
    /// What the multistart search found (`None` without the search or
    /// without an equilibrium).
    pub search: Option<EquilibriumSearch>,
}

/// Every equilibrium of a row's readings ([`Localizer::equilibria`]), against the one chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumSearch {
    /// Equilibria the multistart found.
    pub equilibria: usize,
    /// Of those, the stable ones.
    pub stable: usize,
    /// Distance (position, metres) from the chosen pose to the farthest other
    /// stable equilibrium: the readings cannot tell them apart by more than
    /// their chi-square; `None` when the chosen one is the only stable one.
    pub ambiguity_m: Option<f64>,
}

impl Localizer {
    /// Localise `rows` in order, each warm-started from the previous row's
    /// pose when that one is stable and inside the robot's frame (the first
    /// from the level start). With `search`, every equilibrium of each
    /// solved row is found too, from the same warm start or else the
    /// localiser pose when it is a prior. `stop` is asked before each row:
    /// `true` ends the sequence there (the rows so far are returned).
    ///
    /// ```
    /// use nalgebra::Vector3;
    /// use sagcal::localize::{Localizer, Readings};
    /// use sagcal::model::sensors::NoisePreset;
    /// use sagcal::model::statics::{solve_level, StaticsOptions};
    /// use sagcal::model::Robot;
    /// let robot = Robot::builtin("large")?;
    /// let rows: Vec<Readings> = [[2.0, -3.0, 15.0], [2.5, -3.0, 15.0]]
    ///     .into_iter()
    ///     .map(|p| {
    ///         let truth = solve_level(&robot, Vector3::from(p), &StaticsOptions::default())?;
    ///         Ok(Readings { encoder_lengths_m: truth.cable_lengths_m, load_cell_n: None, localiser_pose: None })
    ///     })
    ///     .collect::<sagcal::Result<_>>()?;
    /// let localizer = Localizer::new(&robot, &NoisePreset::Paper.sigmas(robot.platform_weight_n))?;
    /// let solved = localizer.localize_sequence(&rows, false, &mut || false)?;
    /// assert!(solved.iter().all(|row| row.flag.is_none() && row.found.is_ok()));
    /// # Ok::<(), sagcal::Error>(())
    /// ```
    pub fn localize_sequence(
        &self,
        rows: &[Readings],
        search: bool,
        stop: &mut dyn FnMut() -> bool,
    ) -> Result<Vec<SequenceRow>> {
        self.localize_sequence_with_progress(rows, search, stop, &mut |_, _, _| {})
    }

    /// [`Localizer::localize_sequence`], telling `progress(done, total,
    /// what)` the rows localised: `(k, n, "localising rows")` before row
    /// `k` (from 0) of `n`, and `(n, n, "done")` after the last (not when
    /// stopped). It changes nothing computed.
    ///
    /// ```
    /// use nalgebra::Vector3;
    /// use sagcal::localize::{Localizer, Readings};
    /// use sagcal::model::sensors::NoisePreset;
    /// use sagcal::model::statics::{solve_level, StaticsOptions};
    /// use sagcal::model::Robot;
    /// let robot = Robot::builtin("small")?;
    /// let truth = solve_level(&robot, Vector3::new(0.2, -0.1, 0.8), &StaticsOptions::default())?;
    /// let row = Readings { encoder_lengths_m: truth.cable_lengths_m, load_cell_n: None, localiser_pose: None };
    /// let localizer = Localizer::new(&robot, &NoisePreset::Paper.sigmas(robot.platform_weight_n))?;
    /// let mut reports = Vec::new();
    /// localizer.localize_sequence_with_progress(&[row; 3], false, &mut || false, &mut |done, total, what| {
    ///     reports.push((done, total, what.to_string()))
    /// })?;
    /// let counts: Vec<(usize, usize)> = reports.iter().map(|r| (r.0, r.1)).collect();
    /// assert_eq!(counts, [(0, 3), (1, 3), (2, 3), (3, 3)]);
    /// assert_eq!(reports[3].2, "done");
    /// # Ok::<(), sagcal::Error>(())
    /// ```
    pub fn localize_sequence_with_progress(
        &self,
        rows: &[Readings],
        search: bool,
        stop: &mut dyn FnMut() -> bool,
        progress: &mut dyn FnMut(usize, usize, &str),
    ) -> Result<Vec<SequenceRow>> {
        let mut warm: Option<PlatformPose> = None;
        let mut solved = Vec::with_capacity(rows.len());
        for (k, readings) in rows.iter().enumerate() {
            if stop() {
                return Ok(solved);
            }
            progress(k, rows.len(), "localising rows");
            let row = match self.localize(readings, warm.as_ref()) {
                Ok(found) => {
                    let flag = self.flag(&found);
                    let search = if search {
                        Some(self.search(readings, &found, warm.as_ref())?)
                    } else {
                        None
                    };
                    // A pose outside the frame is no start for the next row.
                    if found.stable && self.frame_allows(&found) {
                        warm = Some(found.pose);
                    }
                    SequenceRow {
                        found: Ok(found),
                        flag,
                        search,
                    }
                }
                Err(e) => SequenceRow {
                    flag: Some(e.to_string()),
                    found: Err(e),
                    search: None,
                },
            };
            solved.push(row);
        }
        progress(rows.len(), rows.len(), "done");
        Ok(solved)
    }

    /// Every equilibrium of `readings`, searched from `warm` or else the
    /// localiser pose when it is a prior, against the one `found`.
    fn search(&self, readings: &Readings, found: &Localized, warm: Option<&PlatformPose>) -> Result<EquilibriumSearch> {
        let prior = readings.localiser_pose.filter(|_| self.options.pose_prior);
        let all = self.equilibria(readings, warm.or(prior.as_ref()))?;
        let stable: Vec<&Localized> = all.iter().filter(|l| l.stable).collect();
        Ok(EquilibriumSearch {
            equilibria: all.len(),
            stable: stable.len(),
            ambiguity_m: stable
                .iter()
                .map(|l| (l.pose.position_m - found.pose.position_m).norm())
                .filter(|d| *d > 1e-6)
                .reduce(f64::max),
        })
    }
}
