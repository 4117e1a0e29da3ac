//! The paper's Table I (model verification): per robot, the mean
//! percentage errors of the predicted cable lengths and forces over 5
//! random poses, which `sagcal verify` prints beside its own
//! ([`super::verify`]).
//!
//! ```
//! use sagcal::diagnose::verify::paper_table1;
//! use sagcal::model::robot::PaperRobot;
//! let large = paper_table1(PaperRobot::Large);
//! assert_eq!((large.poses, large.mpe_force_pct), (5, 0.9154));
//! ```

use serde::Serialize;

use crate::model::robot::PaperRobot;

/// One robot's column of the paper's Table I (model verification).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PaperTable1 {
    /// The paper's robot the column is for.
    pub robot: PaperRobot,
    /// Static poses the paper verified on.
    pub poses: usize,
    /// Mean percentage error of the predicted cable lengths (MPE-L), %.
    pub mpe_length_pct: f64,
    /// Mean percentage error of the predicted cable forces (MPE-F), %.
    pub mpe_force_pct: f64,
}

/// The paper's Table I column for `robot` (both columns over 5 random poses).
pub fn paper_table1(robot: PaperRobot) -> PaperTable1 {
    let (mpe_length_pct, mpe_force_pct) = match robot {
        PaperRobot::Large => (8.8947e-3, 0.9154),
        PaperRobot::Small => (7.3595e-3, 0.9046),
    };
    PaperTable1 {
        robot,
        poses: 5,
        mpe_length_pct,
        mpe_force_pct,
    }
}
