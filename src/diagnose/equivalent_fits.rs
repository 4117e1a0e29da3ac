//! Fits the data cannot tell apart, stated beside the verdict.
//!
//! - **Weights and the load cell are one scale**
//!   ([`super::candidates::WEIGHT_SCALING`]): with the platform's weight
//!   scale `p`, the cables' `c` and the load cell's gain `g` (1 where the
//!   model lacks the effect), every `(s p, s c, g / s)` predicts the same
//!   readings.
//! - **Attachments moved together are a centre of mass or a localiser's
//!   turn.** For nearly level poses a common move `d` of the four
//!   attachments changes each cable's end as a move of its anchor does (the
//!   anchors are free) and the platform's balance as a centre-of-mass shift
//!   of `-d`; a common turn `theta` about the platform's vertical axis is the
//!   platform turned by `theta` under a localiser mounted `-theta` about z.
//!   Measured on the large robot with the authors' noise (`sagcal simulate
//!   --seed 8`): a common move of (-8, 5) cm fits with a likelihood ratio of
//!   69 627 on 8 parameters, a centre-of-mass shift 69 585 on 2; a turn of
//!   0.68 deg as a mount of -0.689 +- 0.017 deg.

use crate::calib::EffectEstimate;
use crate::model::effect_kind::EffectKind;
use crate::model::robot::{Robot, CABLE_COUNT};

/// The fits the data cannot tell from the final model's `effects` (module
/// docs), in words; `robot` gives the attachment points.
pub(super) fn equivalent_fits(effects: &[EffectEstimate], robot: &Robot) -> Vec<String> {
    let mut fits = weight_scalings(effects);
    fits.extend(attachment_modes(effects, robot));
    fits
}

/// Where the final model holds an effect of
/// [`super::candidates::WEIGHT_SCALING`], the fits that the data cannot tell
/// from it: with the platform's weight scale `p`, the cables' `c` and the
/// load cell's gain `g` (1 where the model lacks the effect), every
/// `(s p, s c, g / s)` predicts the same readings; one line per choice of
/// `s` that makes one of the model's own effects neutral.
fn weight_scalings(effects: &[EffectEstimate]) -> Vec<String> {
    let scale = |kind: EffectKind, index: usize| effects.iter().find(|e| e.effect == kind).map(|e| e.values[index]);
    let (platform, cable, gain) = (
        scale(EffectKind::PlatformWeight, 0),
        scale(EffectKind::CableWeight, 0),
        scale(EffectKind::LoadCell, 1),
    );
    if platform.is_none() && cable.is_none() {
        return Vec::new();
    }
    let (p, c, g) = (platform.unwrap_or(1.0), cable.unwrap_or(1.0), gain.unwrap_or(1.0));
    let mut scales = Vec::new();
    if platform.is_some() {
        scales.push(1.0 / p);
    }
    if cable.is_some() {
        scales.push(1.0 / c);
    }
    if gain.is_some() {
        scales.push(g);
    }
    scales
        .into_iter()
        .map(|s| {
            format!(
                "the same fit: platform weight x {:.4}, cable weight x {:.4}, load-cell gain {:.4} \
                 (scaling both weights scales every tension alike; only the load cell sees it)",
                s * p,
                s * c,
                g / s
            )
        })
        .collect()
}

/// An attachments estimate's common move and turn, and the centre-of-mass
/// shift and mount they are the same fit as (module docs); or, for a
/// centre-of-mass shift or a mount in the final model, the attachments'
/// move or turn that is the same fit as it.
fn attachment_modes(effects: &[EffectEstimate], robot: &Robot) -> Vec<String> {
    let find = |kind: EffectKind| effects.iter().find(|e| e.effect == kind);
    let mut fits = Vec::new();
    if let Some(a) = find(EffectKind::Attachments) {
        let shift = |i: usize| (a.values[2 * i], a.values[2 * i + 1]);
        let (mut dx, mut dy) = (0.0, 0.0);
        for i in 0..CABLE_COUNT {
            dx += shift(i).0 / CABLE_COUNT as f64;
            dy += shift(i).1 / CABLE_COUNT as f64;
        }
        // The turn: the least-squares rotation of the points about the platform's centre.
        let (mut moment, mut inertia) = (0.0, 0.0);
        for (i, b) in robot.attachments_m.iter().enumerate() {
            let (sx, sy) = shift(i);
            moment += b.x * (sy - dy) - b.y * (sx - dx);
            inertia += b.x * b.x + b.y * b.y;
        }
        let turn_deg = (moment / inertia.max(f64::MIN_POSITIVE)).to_degrees();
        fits.push(format!(
            "nearly the same fit: the attachments' common move ({:.1}, {:.1}) cm as a centre-of-mass shift of \
             ({:.1}, {:.1}) cm, their common turn of {turn_deg:.2} deg as a localiser mounted {:.2} deg about z \
             (level poses see moved attachments as moved anchors; only the platform's balance and turn differ)",
            dx * 100.0,
            dy * 100.0,
            -dx * 100.0,
            -dy * 100.0,
            -turn_deg
        ));
    }
    if let Some(c) = find(EffectKind::Com) {
        fits.push(format!(
            "nearly the same fit: the four attachments moved together by ({:.1}, {:.1}) cm instead of the \
             centre of mass",
            -c.values[0] * 100.0,
            -c.values[1] * 100.0
        ));
    }
    if let Some(m) = find(EffectKind::LocaliserMount) {
        fits.push(format!(
            "nearly the same fit for the mount's turn about z: the four attachments turned together by {:.2} deg",
            -m.values[2]
        ));
    }
    fits
}
