//! The extended model (issue 4): its factors reduce to the baseline ones with
//! neutral effect parameters, their chained analytic Jacobians match central
//! differences, and, the physics check, at the discretised simulator's
//! equilibria (an independent elastic chain over a swivelling pulley) they
//! predict the paid-out lengths and the statics where the baseline model cannot.

use nalgebra::{DMatrix, DVector, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sagcal::calib::{build_graph, CableModel, CalibrationOptions};
use sagcal::graph::{FactorGraph, VariableValue};
use sagcal::io::measurements::PoseMeasurement;
use sagcal::model::effect_kind::{EffectKind, EffectSet};
use sagcal::model::measurement::mark_time_order;
use sagcal::model::sensors::NoisePreset;
use sagcal::model::statics::{CableTension, Equilibrium};
use sagcal::model::{Effects, PlatformPose, Robot};
use sagcal::sim::closed_form::{sample_equilibria, Workspace};
use sagcal::sim::discretised::DiscretisedEquilibrium;
use sagcal::sim::effects::{measure_with_effects, solve_with_effects};

fn effects(specs: &[&str]) -> Effects {
    let mut e = Effects::default();
    for spec in specs {
        e.apply_spec(spec).unwrap();
    }
    e
}

fn equilibria(robot: &Robot, count: usize) -> Vec<Equilibrium> {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    sample_equilibria(robot, &Workspace::default_for(robot), count, &mut rng).unwrap()
}

/// Noise-free measurements and the true poses/tensions of discretised equilibria.
fn from_discretised(
    robot: &Robot,
    eqs: &[DiscretisedEquilibrium],
) -> (Vec<PoseMeasurement>, Vec<PlatformPose>, Vec<CableTension>) {
    let mut measurements = Vec::new();
    let mut poses = Vec::new();
    let mut tensions = Vec::new();
    for eq in eqs {
        let (roll_deg, pitch_deg, yaw_deg) = eq.pose.roll_pitch_yaw_deg();
        let force = eq.cables[robot.reference_cable].platform_force_n;
        measurements.push(PoseMeasurement {
            line: 0,
            position_m: eq.pose.position_m.into(),
            roll_deg,
            pitch_deg,
            yaw_deg,
            encoder_lengths_m: std::array::from_fn(|i| eq.paid_out_lengths_m[i] + robot.length_offsets_m[i]),
            reference_tension_n: force.norm(),
            excluded: Default::default(),
            order: None,
        });
        poses.push(eq.pose);
        tensions.push(CableTension {
            horizontal_n: Vector3::new(force.x, force.y, 0.0).norm(),
            vertical_n: force.z,
        });
    }
    (measurements, poses, tensions)
}

/// Largest |residual| of the factors of `kind`, metres or newtons.
fn worst_residual(graph: &FactorGraph, kind: &str) -> f64 {
    graph
        .factors
        .iter()
        .filter(|f| f.kind() == kind)
        .flat_map(|f| {
            f.evaluate(&graph.values, None)
                .unwrap()
                .iter()
                .copied()
                .collect::<Vec<_>>()
        })
        .fold(0.0, |m, r: f64| m.max(r.abs()))
}

fn options() -> CalibrationOptions {
    CalibrationOptions::new(NoisePreset::Paper.sigmas(1000.0))
}

#[test]
fn neutral_effects_reproduce_the_baseline_factors() {
    let robot = Robot::builtin("large").unwrap();
    let eqs = equilibria(&robot, 5);
    let measurements: Vec<PoseMeasurement> = eqs
        .iter()
        .map(|eq| {
            let (roll_deg, pitch_deg, yaw_deg) = eq.pose.roll_pitch_yaw_deg();
            PoseMeasurement {
                line: 0,
                position_m: (eq.pose.position_m + Vector3::new(0.03, -0.02, 0.01)).into(),
                roll_deg,
                pitch_deg,
                yaw_deg,
                encoder_lengths_m: std::array::from_fn(|i| eq.cable_lengths_m[i] + 0.01 * i as f64),
                reference_tension_n: eq.tensions[robot.reference_cable].magnitude_n() + 3.0,
                excluded: Default::default(),
                order: None,
            }
        })
        .collect();
    let poses: Vec<PlatformPose> = eqs.iter().map(|e| e.pose).collect();
    let tensions: Vec<CableTension> = eqs.iter().map(|e| e.tensions[robot.reference_cable]).collect();
    let baseline = build_graph(
        &robot,
        &measurements,
        &poses,
        &tensions,
        CableModel::Catenary,
        &options(),
    );
    let extended_options = CalibrationOptions {
        free_effects: EffectSet::of(EffectKind::Elastic),
        ..options()
    };
    let extended = build_graph(
        &robot,
        &measurements,
        &poses,
        &tensions,
        CableModel::Catenary,
        &extended_options,
    );
    assert!(baseline.effects.is_none() && extended.effects.is_some());
    let mut compared = 0;
    let mut worst = 0.0_f64;
    for (b, e) in baseline.graph.factors.iter().zip(&extended.graph.factors) {
        assert_eq!(b.kind(), e.kind());
        let rb = b.evaluate(&baseline.graph.values, None).unwrap();
        let re = e.evaluate(&extended.graph.values, None).unwrap();
        let scale = rb.amax().max(1e-3);
        worst = worst.max((rb - re).amax() / scale);
        compared += 1;
    }
    println!("{compared} factors compared, worst relative residual difference {worst:.2e}");
    assert!(worst < 1e-10, "{worst}");
}

/// Central differences of every free variable's block of every extended factor.
#[test]
fn extended_jacobians_match_central_differences() {
    let mut robot = Robot::builtin("large").unwrap();
    let all = [
        "elastic:ea_n=2e6",
        "pulley:radius_m=0.25",
        "encoder-scale:gain1=1.002,gain3=0.998",
        "loadcell:bias_n=5,gain=1.01",
        "com:dx_m=0.02,dy_m=-0.01,dz_m=0.05",
        "platform-weight:scale=1.05",
        "cable-weight:scale=0.93",
        "encoder-drift:rate1_m=1e-4,rate2_m=-2e-4,rate3_m=3e-4,rate4_m=5e-5",
        "encoder-backlash:b1_m=0.002,b2_m=-0.001,b3_m=0.003,b4_m=0.0015",
        "loadcell-drift:rate_n=0.5",
        "loadcell-friction:k=0.02",
        "attachments:dx1_m=0.01,dy1_m=-0.02,dx3_m=0.015,dy4_m=0.01",
    ];
    robot.effects = effects(&all);
    let eqs = equilibria(&robot, 3);
    // Rows in time order: the drift and the direction of motion act.
    let mut measurements: Vec<PoseMeasurement> = eqs
        .iter()
        .map(|eq| {
            let (roll_deg, pitch_deg, yaw_deg) = eq.pose.roll_pitch_yaw_deg();
            PoseMeasurement {
                line: 0,
                position_m: eq.pose.position_m.into(),
                roll_deg,
                pitch_deg,
                yaw_deg,
                encoder_lengths_m: eq.cable_lengths_m,
                reference_tension_n: eq.tensions[robot.reference_cable].magnitude_n(),
                excluded: Default::default(),
                order: None,
            }
        })
        .collect();
    mark_time_order(&mut measurements);
    assert!(measurements[1..]
        .iter()
        .all(|m| m.order.unwrap().direction.iter().all(|d| *d != 0)));
    let poses: Vec<PlatformPose> = eqs.iter().map(|e| e.pose).collect();
    let tensions: Vec<CableTension> = eqs.iter().map(|e| e.tensions[robot.reference_cable]).collect();
    let mut worst = 0.0_f64;
    for kind in EffectKind::ALL {
        let opts = CalibrationOptions {
            free_effects: EffectSet::of(kind),
            ..options()
        };
        let built = build_graph(&robot, &measurements, &poses, &tensions, CableModel::Catenary, &opts);
        let values = &built.graph.values;
        for factor in &built.graph.factors {
            let rows = factor.residual_dim();
            let mut blocks: Vec<DMatrix<f64>> = factor
                .variables()
                .iter()
                .map(|&v| DMatrix::zeros(rows, values.tangent_dim(v)))
                .collect();
            factor.evaluate(values, Some(&mut blocks)).unwrap();
            for (b, &var) in factor.variables().iter().enumerate() {
                let dim = values.tangent_dim(var);
                for c in 0..dim {
                    let step = match &values.variable(var).value {
                        VariableValue::Pose(_) => 1e-6,
                        // 1/n^2 moves the lengths (~100 m) by ~0.2 m per unit: a step of 1e-8
                        // would leave central differences at the rounding level.
                        VariableValue::Vector(_) if var == built.effects.unwrap().inverse_segments_squared => 1e-4,
                        // Millimetres on lengths of ~100 m: the residual is linear in them.
                        VariableValue::Vector(_)
                            if [
                                built.effects.unwrap().encoder_drift,
                                built.effects.unwrap().encoder_backlash,
                            ]
                            .contains(&var) =>
                        {
                            1e-2
                        }
                        VariableValue::Vector(v) => 1e-6 * v[c].abs().max(1e-2),
                    };
                    let eval = |sign: f64| -> DVector<f64> {
                        let mut moved = values.clone();
                        let mut delta = vec![0.0; dim];
                        delta[c] = sign * step;
                        moved.set(var, values.variable(var).value.retract(&delta));
                        factor.evaluate(&moved, None).unwrap()
                    };
                    let numeric = (eval(1.0) - eval(-1.0)) / (2.0 * step);
                    let analytic = blocks[b].column(c);
                    let scale = numeric.amax().max(analytic.amax()).max(1e-6);
                    let diff = (&numeric - analytic).amax() / scale;
                    assert!(
                        diff < 1e-5,
                        "{kind}: factor {} variable {} column {c}: relative difference {diff:.2e}",
                        factor.kind(),
                        values.variable(var).name
                    );
                    worst = worst.max(diff);
                }
            }
        }
    }
    println!("worst relative Jacobian difference over every block: {worst:.2e}");
}

/// At the discretised simulator's equilibria (n = 200 segments, its own
/// formulas) the extended model with the true effects leaves length and
/// height residuals near the simulator's discretisation error, while the
/// baseline model misses by centimetres.
#[test]
fn extended_model_matches_the_discretised_simulator() {
    for (name, specs, baseline_min_m, extended_max_m) in [
        ("large", &["elastic:ea_n=3e6"][..], 0.02, 2e-4),
        ("large", &["pulley:radius_m=0.2"][..], 0.05, 2e-4),
        ("large", &["elastic:ea_n=3e6", "pulley:radius_m=0.2"][..], 0.05, 3e-4),
        ("small", &["elastic:ea_n=2e5", "pulley:radius_m=0.05"][..], 0.005, 1e-4),
        ("large", &["platform-weight:scale=1.1"][..], 0.1, 2e-4),
        ("large", &["cable-weight:scale=0.85"][..], 0.1, 2e-4),
        (
            "large",
            &["attachments:dx1_m=0.02,dy1_m=-0.015,dx2_m=-0.01,dy3_m=0.02,dx4_m=0.015"][..],
            0.003,
            2e-4,
        ),
        (
            "small",
            &["platform-weight:scale=0.9", "cable-weight:scale=1.15"][..],
            0.1,
            1e-4,
        ),
    ] {
        let robot = Robot::builtin(name).unwrap();
        let e = effects(specs);
        let eqs = equilibria(&robot, 6);
        let solved = solve_with_effects(&robot, &e, &eqs, 200).unwrap();
        let (measurements, poses, tensions) = from_discretised(&robot, &solved);
        let baseline = build_graph(
            &robot,
            &measurements,
            &poses,
            &tensions,
            CableModel::Catenary,
            &options(),
        );
        let mut known = robot.clone();
        known.effects = e;
        let extended = build_graph(
            &known,
            &measurements,
            &poses,
            &tensions,
            CableModel::Catenary,
            &options(),
        );
        let b_len = worst_residual(&baseline.graph, "catenary_length");
        let b_height = worst_residual(&baseline.graph, "attachment_height");
        let e_len = worst_residual(&extended.graph, "catenary_length");
        let e_height = worst_residual(&extended.graph, "attachment_height");
        println!(
            "{name} {specs:?}: baseline worst length {b_len:.2e} m height {b_height:.2e} m; extended worst length {e_len:.2e} m height {e_height:.2e} m"
        );
        assert!(
            b_len.max(b_height) > baseline_min_m,
            "the effect must be visible to the baseline"
        );
        assert!(e_len < extended_max_m && e_height < extended_max_m);
    }
}

/// The effects of time and motion: the simulator's noise-free readings (rows
/// in order, each cable's true direction of last motion) against the
/// extended model with the true effects, which takes the directions from the
/// readings. From the second row on it leaves the discretisation error;
/// the baseline misses by the drift and backlash (millimetres) and the
/// friction (tens of newtons). The first row's direction is unknown to the
/// model (0): it misses there by the backlash and the friction.
#[test]
fn time_and_motion_match_the_simulator_after_the_first_row() {
    let robot = Robot::builtin("large").unwrap();
    let e = effects(&[
        "encoder-drift:rate1_m=5e-4,rate2_m=-3e-4,rate3_m=2e-4,rate4_m=-6e-4",
        "encoder-backlash:b1_m=0.003,b2_m=-0.002,b3_m=0.004,b4_m=0.001",
        "loadcell-drift:rate_n=1.5",
        "loadcell-friction:k=0.03",
    ]);
    let eqs = equilibria(&robot, 6);
    let solved = solve_with_effects(&robot, &e, &eqs, 200).unwrap();
    let (_, poses, tensions) = from_discretised(&robot, &solved);
    let none = NoisePreset::None.sigmas(robot.platform_weight_n);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let measurements = measure_with_effects(&robot, &e, &eqs, &none, 200, &mut rng).unwrap();
    assert_eq!(measurements[5].order.unwrap().row, 6);
    let mut known = robot.clone();
    known.effects = e;
    let build = |r: &Robot| build_graph(r, &measurements, &poses, &tensions, CableModel::Catenary, &options());
    let (baseline, extended) = (build(&robot), build(&known));
    // Per pose (factor order is pose order), the largest residual of `kind`.
    let per_pose = |g: &FactorGraph, kind: &str| -> Vec<f64> {
        g.factors
            .iter()
            .filter(|f| f.kind() == kind)
            .map(|f| f.evaluate(&g.values, None).unwrap().amax())
            .collect()
    };
    let (b_len, x_len) = (
        per_pose(&baseline.graph, "catenary_length"),
        per_pose(&extended.graph, "catenary_length"),
    );
    let (b_cell, x_cell) = (
        per_pose(&baseline.graph, "reference_tension"),
        per_pose(&extended.graph, "reference_tension"),
    );
    println!("lengths: baseline {b_len:?}, extended {x_len:?}; load cell: baseline {b_cell:?}, extended {x_cell:?}");
    for k in 1..6 {
        assert!(x_len[k] < 2e-4, "row {}: {}", k + 1, x_len[k]);
        assert!(x_cell[k] < 0.05, "row {}: {}", k + 1, x_cell[k]);
        assert!(
            b_len[k] > 1e-3,
            "row {}: the baseline sees the drift and backlash",
            k + 1
        );
    }
    // (Drift and friction may cancel on one row; not on all.)
    assert!(b_cell.iter().fold(0.0_f64, |m, r| m.max(*r)) > 20.0);
    // Row 1: the reference cable's unknown direction leaves k |T| on the load cell.
    let reference = tensions[0].magnitude_n();
    assert!(
        (x_cell[0] - 0.03 * reference).abs() < 0.01 * reference,
        "{} vs {reference}",
        x_cell[0]
    );
}

/// The segmented cable against the discretised simulator run with that many
/// segments: the baseline's misfit falls as `1/n^2`, the extended model with
/// `1/n^2` leaves a small part of it that falls faster.
#[test]
fn segmented_chain_matches_the_discretised_simulator() {
    for name in ["large", "small"] {
        let robot = Robot::builtin(name).unwrap();
        let eqs = equilibria(&robot, 6);
        let mut previous: Option<(f64, f64)> = None;
        for n in [5.0, 10.0, 20.0, 40.0] {
            let e = effects(&[&format!("segments:n={n}")]);
            let solved = solve_with_effects(&robot, &e, &eqs, 200).unwrap();
            let (measurements, poses, tensions) = from_discretised(&robot, &solved);
            let build = |r: &Robot| build_graph(r, &measurements, &poses, &tensions, CableModel::Catenary, &options());
            let baseline = build(&robot);
            let mut known = robot.clone();
            known.effects = e;
            let extended = build(&known);
            let worst =
                |g: &FactorGraph| worst_residual(g, "catenary_length").max(worst_residual(g, "attachment_height"));
            let (b, x) = (worst(&baseline.graph), worst(&extended.graph));
            println!("{name}, n = {n}: baseline worst {b:.3e} m, extended worst {x:.3e} m");
            if n >= 10.0 {
                assert!(x < 0.05 * b, "{name}, n = {n}: {x} vs {b}");
            }
            if let Some((b_prev, x_prev)) = previous {
                let ratio = b_prev / b;
                assert!((3.3..4.7).contains(&ratio), "{name}, n = {n}: baseline ratio {ratio}");
                assert!(x_prev / x > 6.0, "{name}, n = {n}: extended ratio {}", x_prev / x);
            }
            previous = Some((b, x));
        }
    }
}

/// The weights' scaling (`WEIGHT_SCALING` of src/diagnose/candidates.rs): a platform
/// `p` times and cables `c` times as heavy, read through a load cell of gain
/// `g`, predict the same readings as `(s p, s c, g / s)` with every tension
/// scaled by `s` (the catenary depends on `f_h / w`, the platform's balance
/// is linear in its weight). Every residual of the extended model agrees, so
/// the data cannot tell them apart and the diagnosis never fits all three.
#[test]
fn scaling_both_weights_is_seen_only_as_a_load_cell_gain() {
    let robot = Robot::builtin("large").unwrap();
    let eqs = equilibria(&robot, 4);
    let (measurements, poses, tensions) = {
        let solved = solve_with_effects(&robot, &effects(&["platform-weight:scale=1.1"]), &eqs, 50).unwrap();
        from_discretised(&robot, &solved)
    };
    let fitted = |specs: &[&str], s: f64| {
        let mut model = robot.clone();
        model.effects = effects(specs);
        let scaled: Vec<CableTension> = tensions
            .iter()
            .map(|t| CableTension {
                horizontal_n: s * t.horizontal_n,
                vertical_n: s * t.vertical_n,
            })
            .collect();
        let opts = CalibrationOptions {
            free_effects: EffectSet::of(EffectKind::LoadCell),
            ..options()
        };
        let built = build_graph(&model, &measurements, &poses, &scaled, CableModel::Catenary, &opts);
        let residuals: Vec<f64> = built
            .graph
            .factors
            .iter()
            .flat_map(|f| {
                f.evaluate(&built.graph.values, None)
                    .unwrap()
                    .iter()
                    .copied()
                    .collect::<Vec<_>>()
            })
            .collect();
        residuals
    };
    let s = 1.0 / 1.1;
    let heavier_platform = fitted(&["platform-weight:scale=1.1", "loadcell:gain=1.0"], 1.0);
    let lighter_cables = fitted(&["cable-weight:scale=0.9090909090909091", "loadcell:gain=1.1"], s);
    let other_model = fitted(&["cable-weight:scale=0.9090909090909091"], s);
    let worst = heavier_platform
        .iter()
        .zip(&lighter_cables)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    let different = heavier_platform
        .iter()
        .zip(&other_model)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    println!(
        "{} residuals: worst difference {worst:.2e}; without the load-cell gain {different:.2e}",
        heavier_platform.len()
    );
    assert!(worst < 1e-6, "{worst}");
    // The load cell does see the scale: the same cables without its gain differ by newtons.
    assert!(different > 1.0, "{different}");
}
