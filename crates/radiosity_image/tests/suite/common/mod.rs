//! Helpers shared by the integration tests.
#![allow(dead_code)] // each test binary uses its own subset

use std::sync::Arc;

use radiosity_core::Scene;
use radiosity_mesh::Mesh;
use radiosity_solver::{Problem, Solution, SolverParams};

/// Meshes `scene` with its own parameters and solves it to a stop criterion.
pub fn solve(scene: &Scene, params: SolverParams) -> (Arc<Mesh>, Solution) {
    let problem = Problem::new(scene, &scene.mesh_params()).expect("mesh");
    let mut solver = problem.solver(params).expect("solver");
    solver.solve();
    (problem.mesh().clone(), solver.solution())
}
