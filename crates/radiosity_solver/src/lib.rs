//! Progressive-refinement radiosity by shooting: form factors, visibility, stop criteria.
//!
//! The solver returns data and never draws, reads files or parses arguments; callers own the
//! loop:
//!
//! ```
//! use std::sync::Arc;
//! use radiosity_core::{Mesh, furnace_box};
//! use radiosity_solver::{Solver, SolverParams, StepBudget, occluder_triangles};
//!
//! let scene = furnace_box(0.5, 1.0);
//! let mesh = Arc::new(Mesh::build(&scene, &scene.mesh_params()).unwrap());
//! let accel = Arc::new(radiosity_accel::Bvh::new(&occluder_triangles(&mesh)));
//! let mut solver = Solver::new(mesh, accel, SolverParams::default()).unwrap();
//! while solver.stop_reason().is_none() {
//!     let report = solver.step(StepBudget::Shots(64));
//!     let _snapshot = solver.solution(); // publish to a viewer, a progress bar, …
//!     assert!(report.unshot_fraction <= 1.0);
//! }
//! ```
#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub mod form_factor;
mod occluders;
mod sampling;
mod shaft;
mod solution;
mod solver;

pub use occluders::occluder_triangles;
pub use solution::{ObjectRadiosity, Solution};
pub use solver::{
    Ambient, EnergyBalance, FormFactorMethod, Overshoot, Solver, SolverError, SolverParams, StepBudget,
    StepReport, StopReason,
};
