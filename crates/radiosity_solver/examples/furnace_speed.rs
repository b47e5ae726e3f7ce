//! Times a fine furnace box solve: `cargo run --release -p radiosity_solver --example furnace_speed -- 0.02`.

use radiosity_core::MeshParams;
use radiosity_scenes::furnace_box;
use radiosity_solver::{Problem, SolverParams};

fn main() {
    let element: f64 = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(0.05);
    let scene = furnace_box(0.5, 1.0);
    let problem = Problem::new(&scene, &MeshParams::try_new(element * 4.0, element).unwrap()).unwrap();
    let (p, e) = (problem.mesh().patches.len(), problem.mesh().elements.len());
    let mut s = problem.solver(SolverParams::default()).unwrap();
    let r = s.solve();
    println!(
        "{p} patches, {e} elements: {} shots in {:.3} s ({:.2} ms/shot), {} rays, {:?}",
        r.total_shots,
        r.elapsed.as_secs_f64(),
        1e3 * r.elapsed.as_secs_f64() / r.total_shots as f64,
        r.rays,
        r.stop_reason
    );
}
