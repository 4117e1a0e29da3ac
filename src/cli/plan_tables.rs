//! What `sagcal plan` prints and captions for a plan of any number of
//! cables: the bounds of the plan and of random sets, the visiting order,
//! and the figure's caption.

use sagcal::plan::Plan;

use super::output::Table;

/// One visit as the order table lists it: its number, position (m) and
/// smallest horizontal tension (N).
pub(super) struct Visit {
    pub(super) visit: usize,
    pub(super) position_m: [f64; 3],
    pub(super) min_horizontal_tension_n: f64,
}

/// The bound table (plan, random sets of its size, random sets of 35), the
/// visits in order and the path length.
pub(super) fn print_plan_tables(plan: &Plan, visits: &[Visit]) {
    let mut table = Table::new(["poses", "anchor bound m (RMS)", "offset bound m (RMS)"]);
    table.row([
        format!("plan, {}", plan.order.len()),
        format!("{:.3}", plan.bound.anchor_rms_m),
        format!("{:.3}", plan.bound.offset_rms_m),
    ]);
    table.row([
        format!("random, {} (mean of {})", plan.random.poses, plan.random.draws),
        format!("{:.3}", plan.random.anchor_rms_m),
        format!("{:.3}", plan.random.offset_rms_m),
    ]);
    if let Some(r) = &plan.random35 {
        table.row([
            format!("random, 35 (mean of {})", r.draws),
            format!("{:.3}", r.anchor_rms_m),
            format!("{:.3}", r.offset_rms_m),
        ]);
    }
    println!("{table}");
    let mut path = Table::new(["visit", "x m", "y m", "z m", "min f_h N"]);
    for p in visits {
        path.row([
            p.visit.to_string(),
            format!("{:.2}", p.position_m[0]),
            format!("{:.2}", p.position_m[1]),
            format!("{:.2}", p.position_m[2]),
            format!("{:.1}", p.min_horizontal_tension_n),
        ]);
    }
    println!("{path}");
    println!("path length {:.1} m (nearest neighbour + 2-opt)", plan.path_length_m);
}

/// The figure's caption: the seed, the candidates, the bounds, the path.
pub(super) fn plan_caption(plan: &Plan, seed: u64, candidates: usize) -> String {
    format!(
        "seed {seed}; {candidates} candidates; bound (RMS per anchor) {:.3} m planned vs {:.3} m random {} (mean of {}){}; path {:.1} m",
        plan.bound.anchor_rms_m,
        plan.random.anchor_rms_m,
        plan.random.poses,
        plan.random.draws,
        plan.random35
            .as_ref()
            .map_or(String::new(), |r| format!(", {:.3} m random 35", r.anchor_rms_m)),
        plan.path_length_m
    )
}
