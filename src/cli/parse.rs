//! The value parsers of flags shared by several commands: the noise presets
//! (`paper`, `authors`, `both`), the data sources of the experiments (`log`,
//! `model`, `both`) and comma-separated pose counts.

pub(super) fn parse_sources(text: &str) -> Result<Vec<sagcal::experiments::table2::Source>, String> {
    match text {
        "both" => Ok(vec![
            sagcal::experiments::table2::Source::Log,
            sagcal::experiments::table2::Source::Model,
        ]),
        other => parse_source(other).map(|s| vec![s]),
    }
}

/// `paper`, `authors` or `both`.
pub(super) fn parse_noises(text: &str) -> Result<Vec<sagcal::model::sensors::NoisePreset>, String> {
    use sagcal::model::sensors::NoisePreset;
    match text {
        "both" => Ok(vec![NoisePreset::Paper, NoisePreset::Authors]),
        other => NoisePreset::parse(other)
            .map(|n| vec![n])
            .map_err(|e| format!("{e}, or `both` (paper and authors)")),
    }
}

pub(super) fn parse_pose_counts(text: &str) -> Result<Vec<usize>, String> {
    text.split(',')
        .map(|p| {
            p.trim()
                .parse::<usize>()
                .map_err(|_| format!("`{p}` is not a pose count"))
        })
        .collect()
}

pub(super) fn parse_source(text: &str) -> Result<sagcal::experiments::table2::Source, String> {
    match text {
        "log" => Ok(sagcal::experiments::table2::Source::Log),
        "model" => Ok(sagcal::experiments::table2::Source::Model),
        other => Err(format!("unknown source `{other}` (log, model)")),
    }
}
