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
