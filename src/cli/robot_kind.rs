//! Which model a robot file is for: the four-cable robot of the paper
//! ([`Robot`]) or a robot of 3 to 8 cables ([`SuspendedRobot`]).

use std::path::Path;

use sagcal::model::suspended::SuspendedRobot;
use sagcal::model::Robot;

/// A robot file, read by the model it is for.
pub(super) enum AnyRobot {
    /// Four cables, one load cell: the paper's model and every job.
    Four(Box<Robot>),
    /// Another number of cables, several load cells or per-cable weights.
    Suspended(Box<SuspendedRobot>),
}

/// The robot of `path`: four-cable where that model takes the file, else
/// the model of 3 to 8 cables. The error is the four-cable reader's unless
/// the file's cables are what it refused (then the other reader's).
pub(super) fn read_robot(path: &Path) -> sagcal::Result<AnyRobot> {
    let four_cable = match Robot::from_file(path) {
        Ok(robot) => return Ok(AnyRobot::Four(Box::new(robot))),
        Err(e) => e,
    };
    let about_cables =
        matches!(&four_cable, sagcal::Error::Robot { message, .. } if message.contains("field `cables`"));
    match SuspendedRobot::from_file(path) {
        Ok(robot) => Ok(AnyRobot::Suspended(Box::new(robot))),
        Err(n_cables) if about_cables => Err(n_cables),
        Err(_) => Err(four_cable),
    }
}

/// The first of the `given` flags (each `(is it given, its name)`) that a
/// robot of 3 to 8 cables does not take, refused as `{flag}: robot `name`
/// has N cables; {why}`.
pub(super) fn refuse_four_cable_flags(given: &[(bool, &str)], robot: &SuspendedRobot, why: &str) -> sagcal::Result<()> {
    match given.iter().find(|(on, _)| *on) {
        Some((_, flag)) => Err(sagcal::Error::InvalidInput(format!(
            "{flag}: robot `{}` has {} cables; {why}",
            robot.name,
            robot.cable_count()
        ))),
        None => Ok(()),
    }
}
