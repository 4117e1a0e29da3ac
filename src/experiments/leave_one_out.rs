//! The hidden-effect experiment's open world: each hidden effect is also
//! left out of the diagnosis' catalogue, so that the data hold a cause the
//! diagnosis has no hypothesis for. The verdict must then be honest: it
//! says that something is left unexplained, and every cause it names is a
//! hidden effect still in the catalogue (a stand-in is named as one, never as
//! a cause). `none` on data with a detectable hidden effect is not honest.
//! Two exceptions name an equivalent of the effect left out ([`honest`]): a
//! platform weight, cable weight or load-cell gain left out is still in the
//! catalogue as the other two together (each possibly as one of an
//! ambiguous pair, `X|Y`), which predict every reading alike
//! ([`crate::diagnose::WEIGHT_SCALING`]; the report gives the equivalent
//! fit); and an effect that the full catalogue could not tell from another
//! (`X|Y`) is honestly named by the other.

use serde::{Deserialize, Serialize};

use crate::error::ParseError;

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
    pub fn parse(text: &str) -> std::result::Result<Self, ParseError> {
        match text.trim() {
            "full" => Ok(Catalogue::Full),
            "leave-one-out" => Ok(Catalogue::LeaveOneOut),
            other => Err(ParseError::UnknownChoice {
                what: "catalogue",
                given: other.to_string(),
                choices: " (full or leave-one-out)".to_string(),
            }),
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
    /// Whether the verdict is honest (`honest`).
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
/// diagnosis' catalogue lacked `left_out` (module docs), given the verdict
/// `full` of the same data with the whole catalogue: every hidden effect
/// left out is said to be `unexplained` or named by an equivalent, and each
/// cause named (or one of each ambiguous pair) is a hidden effect still in
/// the catalogue or an equivalent of one left out. The equivalents of a
/// hidden effect `h` left out:
///
/// - exact: the two other members of [`WEIGHT_SCALING`] named together
///   (either may be one of an ambiguous `X|Y`) where `h` is one of them
///   (they predict every reading alike);
/// - by the diagnosis' own test: `Y` where the full catalogue named `h|Y`
///   or `Y|h` (the data do not tell the two apart: their BICs are within
///   [`crate::diagnose::AMBIGUOUS_BIC`]).
pub fn honest(verdict: &str, hidden: &[EffectKind], left_out: &[EffectKind], full: &str) -> bool {
    let terms: Vec<&str> = verdict.split('+').collect();
    let says_unexplained = terms.contains(&"unexplained");
    let mut named: Vec<&str> = terms.into_iter().filter(|t| *t != "unexplained").collect();
    let still_in: Vec<&str> = hidden
        .iter()
        .filter(|k| !left_out.contains(k))
        .map(|k| k.name())
        .collect();
    let mut accounted = 0;
    let blind: Vec<EffectKind> = hidden.iter().copied().filter(|k| left_out.contains(k)).collect();
    for h in &blind {
        let pair: Vec<&str> = WEIGHT_SCALING.iter().filter(|k| *k != h).map(|k| k.name()).collect();
        // A term `X|Y` names either of the two.
        let names = |t: &&str, p: &str| t.split('|').any(|name| name == p);
        if WEIGHT_SCALING.contains(h) && pair.iter().all(|p| named.iter().any(|t| names(t, p))) {
            named.retain(|t| !pair.iter().any(|p| names(t, p)));
            accounted += 1;
            continue;
        }
        let rivals: Vec<&str> = full
            .split('+')
            .filter_map(|t| t.split_once('|'))
            .filter_map(|(a, b)| match (a == h.name(), b == h.name()) {
                (true, _) => Some(b),
                (_, true) => Some(a),
                _ => None,
            })
            .collect();
        let before = named.len();
        named.retain(|t| !t.split('|').any(|name| rivals.contains(&name)));
        if named.len() < before {
            accounted += 1;
        }
    }
    let causes_right = named.iter().all(|t| t.split('|').any(|name| still_in.contains(&name)));
    causes_right && (says_unexplained || (!blind.is_empty() && accounted == blind.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn honest_verdicts_say_unexplained_and_name_no_wrong_cause() {
        let (loadcell, elastic, com) = (EffectKind::LoadCell, EffectKind::Elastic, EffectKind::Com);
        assert!(honest("unexplained", &[loadcell], &[loadcell], "loadcell"));
        assert!(!honest("none", &[loadcell], &[loadcell], ""));
        assert!(!honest("encoder-scale+unexplained", &[elastic], &[elastic], ""));
        assert!(!honest("encoder-scale", &[elastic], &[elastic], ""));
        // A pair with one left out: the other may be named.
        assert!(honest("com+unexplained", &[com, elastic], &[elastic], ""));
        assert!(honest(
            "com|localiser-mount+unexplained",
            &[com, elastic],
            &[elastic],
            ""
        ));
        assert!(!honest("elastic+unexplained", &[com, elastic], &[elastic], ""));
        // A weight left out: its exact equivalent, the other weight with a load-cell gain.
        let (platform, cable) = (EffectKind::PlatformWeight, EffectKind::CableWeight);
        assert!(honest("loadcell+cable-weight", &[platform], &[platform], ""));
        assert!(honest("platform-weight+loadcell", &[cable], &[cable], ""));
        assert!(!honest("loadcell", &[platform], &[platform], ""));
        // ... also where the verdict cannot tell one of the two from a rival.
        assert!(honest("loadcell+cable-weight|segments", &[platform], &[platform], ""));
        assert!(!honest("loadcell+segments", &[platform], &[platform], ""));
        // The pair names the platform weight left out; the shift still in
        // is missed (not detected), not replaced by a wrong cause.
        assert!(honest("loadcell+cable-weight", &[platform, com], &[platform], ""));
        assert!(!honest(
            "loadcell+cable-weight+elastic",
            &[platform, com],
            &[platform],
            ""
        ));
        // The gain of a load cell left out: the two weights together are its exact equivalent.
        let loadcell_gain = [EffectKind::LoadCell];
        assert!(honest(
            "platform-weight+cable-weight",
            &loadcell_gain,
            &loadcell_gain,
            ""
        ));
        assert!(!honest("platform-weight", &loadcell_gain, &loadcell_gain, ""));
        // The full catalogue could not tell the load cell from the platform weight.
        assert!(honest(
            "platform-weight",
            &loadcell_gain,
            &loadcell_gain,
            "platform-weight|loadcell"
        ));
        assert!(!honest(
            "com",
            &loadcell_gain,
            &loadcell_gain,
            "platform-weight|loadcell"
        ));
        assert!(!honest("platform-weight", &loadcell_gain, &loadcell_gain, "loadcell"));
        assert_eq!(
            left_out_with(EffectKind::CommonGain),
            vec![EffectKind::EncoderScale, EffectKind::CommonGain]
        );
        assert_eq!(left_out_with(EffectKind::Pulley), vec![EffectKind::Pulley]);
    }
}
