//! The hidden-effect experiment's open world: each hidden effect is also
//! left out of the diagnosis' catalogue, so that the data hold a cause the
//! diagnosis has no hypothesis for. The verdict must then be honest: it
//! says that something is left unexplained, and every cause it names is a
//! hidden effect still in the catalogue (a stand-in is named as one, never as
//! a cause). `none` on data with a detectable hidden effect is not honest.
//! One exception is exact: a wrong platform or cable weight left out is
//! still in the catalogue as the other weight with a load-cell gain, which
//! predicts every reading alike ([`crate::diagnose::WEIGHT_SCALING`]); the
//! diagnosis naming that pair (its report gives the equivalent fit) is honest.

use serde::{Deserialize, Serialize};

use crate::diagnose::WEIGHT_SCALING;
use crate::model::effect_kind::EffectKind;

/// The catalogue the diagnosis of each case has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Catalogue {
    /// Every effect of the catalogue.
    #[default]
    Full,
    /// Every effect, and each hidden effect in turn left out (as well).
    LeaveOneOut,
}

impl Catalogue {
    /// Parse `full` or `leave-one-out`.
    pub fn parse(text: &str) -> Result<Self, String> {
        match text.trim() {
            "full" => Ok(Catalogue::Full),
            "leave-one-out" => Ok(Catalogue::LeaveOneOut),
            other => Err(format!("unknown catalogue `{other}` (full or leave-one-out)")),
        }
    }
}

/// One diagnosis of a case with a hidden effect left out of the catalogue.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeftOut {
    /// The effects left out of the catalogue (the hidden one, and those
    /// nested in it or containing it), joined by `+`.
    pub left_out: String,
    /// The verdict.
    pub verdict: String,
    /// Whether the verdict is honest ([`honest`]).
    pub honest: bool,
}

/// The effects left out with `hidden`: it, and the effects nested in it or
/// containing it (four drum gains contain one common gain).
pub fn left_out_with(hidden: EffectKind) -> Vec<EffectKind> {
    EffectKind::ALL
        .into_iter()
        .filter(|k| *k == hidden || k.nested_in() == Some(hidden) || hidden.nested_in() == Some(*k))
        .collect()
}

/// Whether `verdict` is honest about data holding `hidden` when the
/// diagnosis' catalogue lacked `left_out` (module docs): it says
/// `unexplained`, and each cause it names (or one of each ambiguous pair)
/// is a hidden effect still in the catalogue; or it names exactly the two
/// other members of [`WEIGHT_SCALING`] for a hidden weight left out (module docs).
pub fn honest(verdict: &str, hidden: &[EffectKind], left_out: &[EffectKind]) -> bool {
    if let [weight @ (EffectKind::PlatformWeight | EffectKind::CableWeight)] = hidden {
        let mut equivalent: Vec<&str> = WEIGHT_SCALING
            .iter()
            .filter(|k| *k != weight)
            .map(|k| k.name())
            .collect();
        let mut named: Vec<&str> = verdict.split('+').collect();
        equivalent.sort_unstable();
        named.sort_unstable();
        if left_out.contains(weight) && named == equivalent {
            return true;
        }
    }
    let still_in: Vec<&str> = hidden
        .iter()
        .filter(|k| !left_out.contains(k))
        .map(|k| k.name())
        .collect();
    let terms: Vec<&str> = verdict.split('+').collect();
    terms.contains(&"unexplained")
        && terms
            .iter()
            .filter(|t| **t != "unexplained")
            .all(|t| t.split('|').any(|name| still_in.contains(&name)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn honest_verdicts_say_unexplained_and_name_no_wrong_cause() {
        let (loadcell, elastic, com) = (EffectKind::LoadCell, EffectKind::Elastic, EffectKind::Com);
        assert!(honest("unexplained", &[loadcell], &[loadcell]));
        assert!(!honest("none", &[loadcell], &[loadcell]));
        assert!(!honest("encoder-scale+unexplained", &[elastic], &[elastic]));
        assert!(!honest("encoder-scale", &[elastic], &[elastic]));
        // A pair with one left out: the other may be named.
        assert!(honest("com+unexplained", &[com, elastic], &[elastic]));
        assert!(honest("com|localiser-mount+unexplained", &[com, elastic], &[elastic]));
        assert!(!honest("elastic+unexplained", &[com, elastic], &[elastic]));
        // A weight left out: its exact equivalent, the other weight with a load-cell gain.
        let (platform, cable) = (EffectKind::PlatformWeight, EffectKind::CableWeight);
        assert!(honest("loadcell+cable-weight", &[platform], &[platform]));
        assert!(honest("platform-weight+loadcell", &[cable], &[cable]));
        assert!(!honest("loadcell", &[platform], &[platform]));
        assert!(!honest("loadcell+cable-weight", &[platform, com], &[platform]));
        assert_eq!(
            left_out_with(EffectKind::CommonGain),
            vec![EffectKind::EncoderScale, EffectKind::CommonGain]
        );
        assert_eq!(left_out_with(EffectKind::Pulley), vec![EffectKind::Pulley]);
    }
}
