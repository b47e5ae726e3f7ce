//! `radiosity bench`: fixed, seeded cases printed as a table and as JSON.
//!
//! Figures, not tests: the machines are shared and noisy, so each case prints its own rates
//! and the solve cases also print a ratio against the source document's figure.

use std::sync::Arc;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use glam::Vec3;
use radiosity_accel::{Bvh, RayQuery};
use radiosity_core::{Mesh, MeshParams};
use radiosity_solver::{Solver, SolverParams, occluder_triangles};
use rayon::prelude::*;
use serde_json::json;

use crate::prepare::write_output;

/// Arguments of `radiosity bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Also write the figures as JSON here (`-` for stdout).
    #[arg(long)]
    pub json: Option<String>,
    /// Overwrite an existing JSON file.
    #[arg(long)]
    pub force: bool,
    /// Element size of the Cornell case, mm (17 gives ~10 k elements).
    #[arg(long, default_value_t = 17.0)]
    pub cornell_element_size: f64,
}

fn solve_case(name: &str, mesh: Mesh, params: SolverParams) -> Result<serde_json::Value> {
    let mesh = Arc::new(mesh);
    let accel = Arc::new(Bvh::new(&occluder_triangles(&mesh)));
    let (patches, elements) = (mesh.patches.len(), mesh.elements.len());
    let mut solver = Solver::new(mesh, accel, params)?;
    let r = solver.solve();
    let secs = r.elapsed.as_secs_f64();
    println!(
        "{name:<34} {patches:>7} patches {elements:>8} elements {:>6} shots {secs:>9.3} s {:>7.2} M rays/s  unshot {:.2e} ({})",
        r.total_shots,
        r.rays as f64 / secs.max(1e-9) / 1e6,
        r.unshot_fraction,
        r.stop_reason.map_or("running", |s| s.as_str())
    );
    Ok(
        json!({"case": name, "patches": patches, "elements": elements, "shots": r.total_shots, "seconds": secs,
        "rays": r.rays, "unshot_fraction": r.unshot_fraction}),
    )
}

/// Runs `bench`.
pub fn run(a: BenchArgs) -> Result<()> {
    let threads = rayon::current_num_threads();
    println!("radiosity bench ({threads} threads)");
    let cornell = radiosity_io::resolve_scene("cornell")?;
    let mut cases = Vec::new();

    // (a) Occlusion rays: incoherent segments between random points on Cornell surfaces.
    let mesh = Mesh::build(&cornell, &MeshParams::try_new(100.0, 25.0)?)?;
    let tris = occluder_triangles(&mesh);
    let bvh = Bvh::new(&tris);
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f32 / (1u64 << 53) as f32
    };
    let elements = &mesh.elements;
    let segments: Vec<(Vec3, Vec3)> = (0..400_000)
        .map(|_| {
            let a = &elements[(next() * elements.len() as f32) as usize % elements.len()];
            let b = &elements[(next() * elements.len() as f32) as usize % elements.len()];
            ((a.centre + a.normal * 1e-3).as_vec3(), (b.centre + b.normal * 1e-3).as_vec3())
        })
        .collect();
    let time_rays = |parallel: bool| {
        let t = Instant::now();
        let blocked: usize = if parallel {
            segments.par_iter().filter(|(a, b)| bvh.occluded(*a, *b)).count()
        } else {
            segments.iter().filter(|(a, b)| bvh.occluded(*a, *b)).count()
        };
        (segments.len() as f64 / t.elapsed().as_secs_f64(), blocked)
    };
    let (one, blocked) = time_rays(false);
    let (all, _) = time_rays(true);
    println!(
        "occlusion rays (Cornell, {} triangles)   1 thread {:.2} M rays/s, {threads} threads {:.2} M rays/s ({:.2}×), {:.0} % blocked",
        bvh.triangle_count(),
        one / 1e6,
        all / 1e6,
        all / one,
        100.0 * blocked as f64 / segments.len() as f64
    );
    cases.push(
        json!({"case": "occlusion_rays", "triangles": bvh.triangle_count(), "rays_per_s_1_thread": one,
        "rays_per_s_all_threads": all, "threads": threads}),
    );

    // (b) The source document's case: ~100 facets, 1000 shots (it took about a minute).
    let seed = radiosity_io::resolve_scene("seed-room")?;
    let (lo, hi) = seed.bounds();
    let size = ((hi - lo).length() / 5.0).max(1e-6);
    let mut params = MeshParams::try_new(size, size)?;
    let mut seed_mesh = Mesh::build(&seed, &params)?;
    // Refine until there are at least 100 facets, as in the document.
    while seed_mesh.elements.len() < 100 {
        params = params.scaled(0.8);
        seed_mesh = Mesh::build(&seed, &params)?;
    }
    let p = SolverParams { max_shots: Some(1000), unshot_threshold: 1e-12, ..SolverParams::default() };
    let t = Instant::now();
    let mut v = solve_case("source document (≥100 facets, 1000 shots)", seed_mesh, p)?;
    let secs = t.elapsed().as_secs_f64();
    println!("  vs the document's ~60 s: {:.0}× faster", 60.0 / secs);
    v["speedup_vs_document"] = json!(60.0 / secs);
    cases.push(v);

    // (c) Cornell at ~10 k elements to unshot 1e-3.
    let m =
        Mesh::build(&cornell, &MeshParams::try_new(4.0 * a.cornell_element_size, a.cornell_element_size)?)?;
    cases.push(solve_case("Cornell to unshot 1e-3", m, SolverParams::default())?);

    if let Some(path) = &a.json {
        write_output(
            path,
            &serde_json::to_string_pretty(&json!({"threads": threads, "cases": cases}))?,
            a.force,
        )?;
    }
    Ok(())
}
