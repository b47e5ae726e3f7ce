//! Helpers shared by the solver's integration tests (each test file uses some of them).
#![allow(dead_code)]

use radiosity_core::{Rgb, Scene};
use radiosity_solver::{Problem, Solver, SolverParams, StopReason};

/// A solver for `scene` meshed with its own parameters.
pub fn solver_for(scene: &Scene, params: SolverParams) -> Solver {
    Problem::new(scene, &scene.mesh_params()).unwrap().solver(params).unwrap()
}

/// `scene` solved to `threshold`, asserting that it converged.
pub fn converged(scene: &Scene, threshold: f64) -> Solver {
    let mut s = solver_for(scene, SolverParams { unshot_threshold: threshold, ..SolverParams::default() });
    let r = s.solve();
    assert_eq!(r.stop_reason, Some(StopReason::Converged));
    s
}

/// |a − b| / |b|.
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The element radiosity after `shots` shots (default parameters) on a pool of `threads`.
pub fn radiosity_on_threads(scene: &Scene, params: &SolverParams, threads: usize) -> Vec<Rgb> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mut s = solver_for(scene, params.clone());
        s.solve();
        s.solution().element_radiosity
    })
}

/// Asserts that `scene` solved with `params` gives the same bits on 1 and 2 threads.
pub fn same_on_one_and_two_threads(scene: &Scene, params: &SolverParams) {
    assert!(
        radiosity_on_threads(scene, params, 1) == radiosity_on_threads(scene, params, 2),
        "1 and 2 threads differ"
    );
}
