//! `sagcal experiment hidden-effects`'s flags ([`HiddenEffectsArgs`]), for
//! the four-cable sweep (`hidden.rs`) and the sweep of 3 to 8 cables
//! (`hidden_suspended.rs`).

#[derive(Debug, clap::Args)]
pub(super) struct HiddenEffectsArgs {
    /// Cases per effect (and with none) per robot.
    #[arg(long, default_value_t = 20)]
    pub(super) seeds: usize,
    /// Base random seed (each case's seed is derived from it and printed in the JSON).
    #[arg(long, default_value_t = 1)]
    pub(super) seed: u64,
    /// Built-in robots, comma separated: four-cable (large, small) or of 3 to 8 cables (three, six, eight).
    #[arg(long, default_value = "large,small")]
    pub(super) robots: String,
    /// Static poses per case.
    #[arg(long, default_value_t = 35)]
    pub(super) poses: usize,
    /// Sensor noise of the data and the calibration: paper, authors, or both.
    #[arg(long, default_value = "both", value_parser = super::parse::parse_noises)]
    pub(super) noise: std::vec::Vec<sagcal::model::sensors::NoisePreset>,
    /// Segments per cable of the discretised simulator.
    #[arg(long, default_value_t = 50)]
    pub(super) segments: usize,
    /// How each pose closes its family of equilibria: level (the most level member),
    /// yaw (a random yaw within +-1 degree) or mixed (about half each).
    #[arg(long, default_value = "mixed", value_parser = sagcal::sim::closed_form::Closure::parse)]
    pub(super) closure: sagcal::sim::closed_form::Closure,
    /// The diagnosis' catalogue: full, or leave-one-out (each case is also
    /// diagnosed with each hidden effect left out of the catalogue, and the
    /// verdict scored for honesty: `unexplained`, and no wrong cause named).
    #[arg(long, default_value = "full", value_parser = sagcal::experiments::hidden_effects::Catalogue::parse)]
    pub(super) catalogue: sagcal::experiments::hidden_effects::Catalogue,
    /// Print JSON (with every case).
    #[arg(long)]
    pub(super) json: bool,
}
