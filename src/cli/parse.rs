//! The value parsers of flags shared by several commands: the noise presets
//! (`paper`, `authors`, `both`), the data sources of the experiments (`log`,
//! `model`, `both`) and comma-separated pose counts.

use sagcal::error::ParseError;

pub(super) fn parse_sources(text: &str) -> Result<Vec<sagcal::experiments::table2::Source>, ParseError> {
    match text {
        "both" => Ok(vec![
            sagcal::experiments::table2::Source::Log,
            sagcal::experiments::table2::Source::Model,
        ]),
        other => parse_source(other).map(|s| vec![s]),
    }
}

/// `paper`, `authors` or `both`.
pub(super) fn parse_noises(text: &str) -> Result<Vec<sagcal::model::sensors::NoisePreset>, ParseError> {
    use sagcal::model::sensors::NoisePreset;
    match text {
        "both" => Ok(vec![NoisePreset::Paper, NoisePreset::Authors]),
        other => NoisePreset::parse(other)
            .map(|n| vec![n])
            .map_err(|_| ParseError::UnknownChoice {
                what: "noise setting",
                given: other.to_string(),
                choices: " (paper, authors, none), or `both` (paper and authors)".to_string(),
            }),
    }
}

pub(super) fn parse_pose_counts(text: &str) -> Result<Vec<usize>, ParseError> {
    text.split(',')
        .map(|p| {
            p.trim().parse::<usize>().map_err(|_| ParseError::NotANumber {
                what: "pose count",
                given: p.to_string(),
            })
        })
        .collect()
}

pub(super) fn parse_source(text: &str) -> Result<sagcal::experiments::table2::Source, ParseError> {
    match text {
        "log" => Ok(sagcal::experiments::table2::Source::Log),
        "model" => Ok(sagcal::experiments::table2::Source::Model),
        other => Err(ParseError::UnknownChoice {
            what: "source",
            given: other.to_string(),
            choices: " (log, model)".to_string(),
        }),
    }
}
