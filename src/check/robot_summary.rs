//! The robot as `sagcal check` reports it.

use std::path::Path;

use super::report::{RobotSummary, Span, WorkspaceSummary};
use crate::model::geometry::{platform_reach_m, Footprint};
use crate::model::plausibility::STANDARD_GRAVITY_M_S2;
use crate::model::robot::{Robot, CABLE_COUNT};
use crate::sim::closed_form::Workspace;

impl RobotSummary {
    /// What `robot`, read from `path`, holds.
    pub fn of(robot: &Robot, path: &Path) -> Self {
        let footprint = Footprint::of(robot);
        let workspace = Workspace::default_for(robot);
        let axis = |k: usize| Span::of(robot.anchors_m.iter().map(|a| a[k]));
        RobotSummary {
            path: path.display().to_string(),
            name: robot.name.clone(),
            cables: CABLE_COUNT,
            anchors_m: robot.anchors_m.iter().map(|a| [a.x, a.y, a.z]).collect(),
            attachments_m: robot.attachments_m.iter().map(|b| [b.x, b.y, b.z]).collect(),
            anchor_span_m: [axis(0), axis(1), axis(2)],
            footprint_width_m: footprint.width_m,
            footprint_diameter_m: footprint.diameter_m,
            platform_reach_m: platform_reach_m(robot),
            reference_cable: robot.reference_cable + 1,
            platform_weight_n: robot.platform_weight_n,
            platform_mass_kg: robot.platform_weight_n / STANDARD_GRAVITY_M_S2,
            cable_weight_n_per_m: robot.cable_weight_n_per_m,
            cable_mass_g_per_m: 1e3 * robot.cable_weight_n_per_m / STANDARD_GRAVITY_M_S2,
            com_offset_m: robot.com_offset_m.into(),
            length_offsets_m: robot.length_offsets_m,
            workspace: WorkspaceSummary {
                min_m: workspace.min_m,
                max_m: workspace.max_m,
                source: if robot.workspace.is_some() {
                    "robot file".into()
                } else {
                    "derived from the anchors".into()
                },
            },
            effects: robot.effects.specs(),
            calibration_covariance: robot.calibration_covariance_m2.is_some(),
            paper_robot: robot.paper_robot.map(|p| p.name().to_string()),
        }
    }
}
