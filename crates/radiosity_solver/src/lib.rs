//! Progressive-refinement radiosity by shooting: form factors, visibility, stop criteria.
//!
//! The solver returns data and never draws, reads files or parses arguments; callers own the
//! loop:
//!
//! ```
//! use radiosity_scenes::furnace_box;
//! use radiosity_solver::{Problem, SolverParams, StepBudget};
//!
//! let scene = furnace_box(0.5, 1.0);
//! let problem = Problem::new(&scene, &scene.mesh_params()).unwrap(); // mesh + ray queries
//! let mut solver = problem.solver(SolverParams::default()).unwrap();
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
mod problem;
mod sampling;
mod shaft;
mod solution;
mod solver;

pub use occluders::{hull_triangles, occluder_queries, occluder_triangles};
pub use problem::Problem;
pub use solution::{ObjectRadiosity, Solution};
pub use solver::{
    Ambient, EnergyBalance, FormFactorMethod, Overshoot, Solver, SolverError, SolverParams, StepBudget,
    StepReport, StopReason, UNSHOT_FLOOR, shooter_groups,
};
