//! Times a fine furnace box solve: `cargo run --release -p radiosity_solver --example furnace_speed -- 0.02`.

use std::sync::Arc;

use radiosity_accel::Bvh;
use radiosity_core::{Mesh, MeshParams, furnace_box};
use radiosity_solver::{Solver, SolverParams, occluder_triangles};

fn main() {
    let element: f64 = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(0.05);
    let scene = furnace_box(0.5, 1.0);
    let mesh = Arc::new(Mesh::build(&scene, &MeshParams::try_new(element * 4.0, element).unwrap()).unwrap());
    let accel = Arc::new(Bvh::new(&occluder_triangles(&mesh)));
    let (p, e) = (mesh.patches.len(), mesh.elements.len());
    let mut s = Solver::new(mesh, accel, SolverParams::default()).unwrap();
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
