//! The sparse Levenberg-Marquardt on small problems with known answers.

use nalgebra::{DMatrix, DVector, Vector3};
use sagcal::graph::{Factor, FactorGraph, Noise, RobustKernel, VariableId, VariableValue};
use sagcal::solver::{marginal_covariance, optimize, Covariance, LmParams};

/// Range from a point variable to a known beacon: `|p - b| - d`.
struct Range {
    variables: [VariableId; 1],
    beacon: Vector3<f64>,
    measured_m: f64,
    noise: Noise,
}

impl Factor for Range {
    fn variables(&self) -> &[VariableId] {
        &self.variables
    }
    fn residual_dim(&self) -> usize {
        1
    }
    fn evaluate(&self, values: &sagcal::graph::Values, jacobians: Option<&mut [DMatrix<f64>]>) -> Option<DVector<f64>> {
        let p = values.vector(self.variables[0]);
        let d = Vector3::new(p[0], p[1], p[2]) - self.beacon;
        if let Some(j) = jacobians {
            let u = d.normalize();
            j[0].copy_from(&DMatrix::from_row_slice(1, 3, u.as_slice()));
        }
        Some(DVector::from_element(1, d.norm() - self.measured_m))
    }
    fn noise(&self) -> &Noise {
        &self.noise
    }
    fn kind(&self) -> &'static str {
        "range"
    }
}

fn beacons() -> Vec<Vector3<f64>> {
    vec![
        Vector3::new(0.0, 0.0, 10.0),
        Vector3::new(20.0, 0.0, 12.0),
        Vector3::new(0.0, 20.0, 9.0),
        Vector3::new(20.0, 20.0, 11.0),
        Vector3::new(10.0, -5.0, 0.0),
    ]
}

fn graph_with(
    beacons: &[Vector3<f64>],
    truth: Vector3<f64>,
    start: Vector3<f64>,
    kernel: RobustKernel,
) -> (FactorGraph, VariableId) {
    let mut graph = FactorGraph::new();
    let point = graph.values.insert(
        "point",
        VariableValue::Vector(DVector::from_column_slice(start.as_slice())),
    );
    for b in beacons {
        graph.add(Range {
            variables: [point],
            beacon: *b,
            measured_m: (truth - b).norm(),
            noise: Noise::new(DVector::from_element(1, 0.01), kernel),
        });
    }
    (graph, point)
}

#[test]
fn converges_from_far_and_covariance_is_the_inverse_information() {
    let truth = Vector3::new(7.0, 4.0, 3.0);
    let (mut graph, point) = graph_with(&beacons(), truth, Vector3::new(30.0, -20.0, 40.0), RobustKernel::None);
    let summary = optimize(&mut graph, &LmParams::default()).unwrap();
    assert!(summary.termination.converged(), "{:?}", summary.termination);
    let p = graph.values.vector(point);
    assert!((Vector3::new(p[0], p[1], p[2]) - truth).norm() < 1e-9, "{p}");
    assert!(summary.final_cost < 1e-18);
    assert!(summary.history.iter().all(|h| h.cost <= summary.initial_cost));
    // Closed form: (J^T W J)^-1 with rows u_j^T / sigma.
    let mut information = nalgebra::Matrix3::<f64>::zeros();
    for b in beacons() {
        let u = (truth - b).normalize();
        information += u * u.transpose() / (0.01 * 0.01);
    }
    let expected = information.try_inverse().unwrap();
    match marginal_covariance(&graph, &[point]).unwrap() {
        Covariance::Full(c) => {
            for i in 0..3 {
                for j in 0..3 {
                    assert!(
                        (c[(i, j)] - expected[(i, j)]).abs() < 1e-9 * expected.norm(),
                        "{c} vs {expected}"
                    );
                }
            }
        }
        other => panic!("expected a full covariance, got {other:?}"),
    }
}

#[test]
fn two_ranges_leave_a_circle_unobservable() {
    let truth = Vector3::new(7.0, 4.0, 3.0);
    let (mut graph, point) = graph_with(&beacons()[..2], truth, Vector3::new(8.0, 5.0, 2.0), RobustKernel::None);
    optimize(&mut graph, &LmParams::default()).unwrap();
    match marginal_covariance(&graph, &[point]).unwrap() {
        Covariance::RankDeficient(directions) => {
            assert_eq!(directions.len(), 1, "{directions:?}");
            // The free direction is perpendicular to both beacon lines of sight.
            let p = graph.values.vector(point);
            let p = Vector3::new(p[0], p[1], p[2]);
            let axis = (p - beacons()[0]).cross(&(p - beacons()[1])).normalize();
            let mut v = Vector3::zeros();
            for (name, coordinate, weight) in &directions[0].components {
                assert_eq!(name, "point");
                v[*coordinate] = *weight;
            }
            assert!(v.normalize().dot(&axis).abs() > 0.99, "{v} vs {axis}");
        }
        other => panic!("expected rank deficiency, got {other:?}"),
    }
}

#[test]
fn a_robust_kernel_resists_an_outlier() {
    let truth = Vector3::new(7.0, 4.0, 3.0);
    let mut all = beacons();
    all.push(Vector3::new(-10.0, 8.0, 5.0));
    all.push(Vector3::new(25.0, 12.0, 2.0));
    let solve = |kernel| {
        let (mut graph, point) = graph_with(&all, truth, Vector3::new(5.0, 5.0, 5.0), kernel);
        // Corrupt one range by 2 m (200 sigma).
        let mut factors = std::mem::take(&mut graph.factors);
        let outlier = Range {
            variables: [point],
            beacon: all[0],
            measured_m: (truth - all[0]).norm() + 2.0,
            noise: Noise::new(DVector::from_element(1, 0.01), kernel),
        };
        factors[0] = Box::new(outlier);
        graph.factors = factors;
        optimize(&mut graph, &LmParams::default()).unwrap();
        let p = graph.values.vector(point);
        (Vector3::new(p[0], p[1], p[2]) - truth).norm()
    };
    let plain = solve(RobustKernel::None);
    let cauchy = solve(RobustKernel::Cauchy(2.0));
    let huber = solve(RobustKernel::Huber(1.345));
    assert!(plain > 0.2, "least squares is pulled by the outlier: {plain}");
    assert!(cauchy < 0.01 * plain, "cauchy {cauchy} vs plain {plain}");
    assert!(huber < plain, "huber {huber} vs plain {plain}");
}

/// The factors that tell the solver they write every Jacobian entry (so it
/// does not zero their reused blocks) do: evaluated into blocks filled with
/// NaN, at a perturbed point of the benchmark graph, every entry comes back
/// finite. The five calibration factor types that claim it are all present
/// (the benchmark's inputs with their tension guards, which the benchmark
/// graph leaves out), so the test cannot pass empty.
#[test]
fn factors_that_claim_to_write_every_jacobian_entry_do() {
    use sagcal::calib::{build_graph, CableModel};
    use sagcal::experiments::benchmark::BenchmarkProblem;
    let problem = BenchmarkProblem::new(3, 5).expect("problem");
    let built = build_graph(
        &problem.initial,
        &problem.measurements,
        &problem.initial_poses,
        &problem.initial_tensions,
        CableModel::Catenary,
        &problem.options,
    );
    let values = &built.graph.values;
    let mut kinds = std::collections::BTreeSet::new();
    for factor in built.graph.factors.iter().filter(|f| f.writes_every_jacobian_entry()) {
        let rows = factor.residual_dim();
        let mut blocks: Vec<DMatrix<f64>> = factor
            .variables()
            .iter()
            .map(|&v| DMatrix::from_element(rows, values.tangent_dim(v), f64::NAN))
            .collect();
        let residual = factor.evaluate(values, Some(&mut blocks)).expect("defined");
        assert!(residual.iter().all(|r| r.is_finite()), "{}", factor.kind());
        for (slot, block) in blocks.iter().enumerate() {
            assert!(
                block.iter().all(|v| v.is_finite()),
                "{}: block {slot} has an entry left unwritten",
                factor.kind()
            );
        }
        kinds.insert(factor.kind());
    }
    let expected = [
        "attachment_height",
        "catenary_length",
        "pose_prior",
        "reference_tension",
        "tension_guard",
    ];
    assert_eq!(kinds.into_iter().collect::<Vec<_>>(), expected);
}

/// A solve (and a covariance) through a `SystemCache` that already holds the
/// system of a graph with the same structure ends bit for bit where a fresh
/// one ends; graphs of another structure (more poses, an offset held fixed)
/// in between get systems of their own and match fresh solves too.
#[test]
fn a_kept_linear_system_solves_exactly_as_a_new_one() {
    use sagcal::experiments::benchmark::BenchmarkProblem;
    use sagcal::solver::{marginal_covariance_cached, optimize_cached, SystemCache};
    let params = LmParams {
        max_iterations: 6,
        ..BenchmarkProblem::stopping()
    };
    let fresh = |poses: usize, fix_first: bool| {
        let mut built = BenchmarkProblem::new(poses, 3).unwrap().graph();
        if fix_first {
            built.graph.values.set_fixed(built.globals.length_offsets[0], true);
        }
        built
    };
    let mut cache = SystemCache::default();
    assert!(cache.is_empty());
    for (poses, fix_first) in [(9, false), (9, false), (12, false), (12, true), (12, true), (9, false)] {
        let mut cached = fresh(poses, fix_first);
        let with_cache = optimize_cached(&mut cached.graph, &params, &mut cache).unwrap();
        assert!(!cache.is_empty());
        let mut alone = fresh(poses, fix_first);
        let without = optimize(&mut alone.graph, &params).unwrap();
        let what = format!("{poses} poses, first offset fixed: {fix_first}");
        assert_eq!(with_cache.final_cost.to_bits(), without.final_cost.to_bits(), "{what}");
        assert_eq!(with_cache.iterations, without.iterations, "{what}");
        assert!(
            with_cache.final_cost < 1e-2 * with_cache.initial_cost,
            "{what}: the solve did its job"
        );
        for ((_, a), (_, b)) in cached.graph.values.iter().zip(alone.graph.values.iter()) {
            assert_eq!(a.value, b.value, "{what}");
        }
        let anchors = &cached.globals.anchors;
        let kept = marginal_covariance_cached(&cached.graph, anchors, &mut cache).unwrap();
        let new = marginal_covariance(&alone.graph, anchors).unwrap();
        match (kept, new) {
            (Covariance::Full(a), Covariance::Full(b)) => assert_eq!(a, b, "{what}"),
            other => panic!("{what}: {other:?}"),
        }
    }
    cache.clear();
    assert!(cache.is_empty());
}

/// A catenary calibration graph (the final stage of `calibrate`, pose priors
/// with orientation: the benchmark problem's graph, and the same poses with
/// the tension guards, solved with local refinement) has a fixed-size kernel
/// for every shape it gives the solver (the table of `solver::shapes`): its
/// solves take no general loop, on either path (`SAGCAL_SIMD`).
#[test]
fn a_calibration_graph_takes_no_general_loop() {
    use sagcal::calib::{build_graph, CableModel};
    use sagcal::experiments::benchmark::BenchmarkProblem;
    use sagcal::solver::{optimize_cached, Fallbacks, SystemCache};
    let problem = BenchmarkProblem::new(9, 1).unwrap();
    let with_guards = build_graph(
        &problem.initial,
        &problem.measurements,
        &problem.initial_poses,
        &problem.initial_tensions,
        CableModel::Catenary,
        &problem.options,
    );
    assert!(with_guards.graph.factors.iter().any(|f| f.kind() == "tension_guard"));
    let refined = LmParams {
        max_iterations: 6,
        ..LmParams::default()
    };
    for (mut built, params) in [(problem.graph(), BenchmarkProblem::stopping()), (with_guards, refined)] {
        assert!(built.graph.factors.iter().any(|f| f.kind() == "catenary_length"));
        let mut cache = SystemCache::default();
        let summary = optimize_cached(&mut built.graph, &params, &mut cache).unwrap();
        assert!(summary.iterations > 0 && summary.final_cost < summary.initial_cost);
        let graph = &built.graph;
        let system = cache
            .system(&graph.values, &graph.factors, &graph.local_groups)
            .unwrap();
        assert!(system.uses_block_elimination());
        assert_eq!(
            system.fallbacks(),
            Fallbacks::default(),
            "{} factors",
            graph.factors.len()
        );
    }
}
