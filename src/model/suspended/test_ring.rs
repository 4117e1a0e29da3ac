//! The robots the tests of this folder hang: `n` cables on an irregular
//! ring ([`ring`]).

use nalgebra::Vector3;

use super::robot::SuspendedRobot;

/// `n` anchors around a 20 m circle at about 15 m height, each at its own
/// radius and height (a fixed pattern, so no two cables are alike),
/// attachments at `attachment_z_m` on a 0.5 m circle facing their anchors,
/// 0.5 N/m cables, a 500 N platform with its centre of mass at `com_m`.
pub(super) fn ring(n: usize, attachment_z_m: f64, com_m: Vector3<f64>) -> SuspendedRobot {
    let angle = |k: usize| std::f64::consts::TAU * k as f64 / n as f64;
    let anchor = |k: usize| {
        let r = 20.0 + 2.0 * (3.0 * k as f64).cos();
        Vector3::new(r * angle(k).cos(), r * angle(k).sin(), 15.0 + (2.0 * k as f64).sin())
    };
    SuspendedRobot::new(
        (0..n).map(anchor).collect(),
        (0..n)
            .map(|k| Vector3::new(0.5 * angle(k).cos(), 0.5 * angle(k).sin(), attachment_z_m))
            .collect(),
        vec![0.5; n],
        com_m,
        500.0,
    )
    .expect("a ring of three cables or more is a robot")
}

/// `n` anchors evenly on a 20 m circle at 15 m, attachments on a 0.5 m
/// circle facing them (so the yaw is held only by the cables' small lever
/// arms), 0.5 N/m cables, a 500 N platform with its centre of mass 1 m
/// below the attachments: the symmetric robot on which an equilibrium
/// search meets its flattest directions.
pub(super) fn regular_ring(n: usize) -> SuspendedRobot {
    let angle = |k: usize| std::f64::consts::TAU * k as f64 / n as f64;
    SuspendedRobot::new(
        (0..n)
            .map(|k| Vector3::new(20.0 * angle(k).cos(), 20.0 * angle(k).sin(), 15.0))
            .collect(),
        (0..n)
            .map(|k| Vector3::new(0.5 * angle(k).cos(), 0.5 * angle(k).sin(), 0.0))
            .collect(),
        vec![0.5; n],
        Vector3::new(0.0, 0.0, -1.0),
        500.0,
    )
    .expect("a ring of three cables or more is a robot")
}
