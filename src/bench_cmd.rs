//! `radiosity bench`: fixed, seeded cases printed as a table and as JSON.
//!
//! Figures, not tests: the machines are shared and noisy, so where a baseline exists it runs
//! in the same process and the case prints the ratio (the solver's reference path against
//! its fast path; the source document's minute).
//!
//! Cases: (a) occlusion rays on a ~100 k-triangle Cornell box (finely tessellated blocks and
//! two spheres), incoherent surface-to-surface segments, 1 thread and all threads;
//! (b) the source document's case, ≥ 100 facets × 1000 shots; (c) the Cornell box at ~10 k
//! elements (fast and reference path), ~15 k on one thread and ~100 k elements to unshot
//! 1e-3; (d) the peak heap of every solve case and the bytes per element; (e) with `--big`,
//! models from files (load, mesh and solve to 1 % unshot, peak heap per triangle), and with
//! `--big-baseline` the same without clustering; (f) with `--real`, real rooms solved as
//! `solve` does and judged against `verify`'s path tracer (`bench_real.rs`); given `--real`,
//! the fixed cases (a)–(d) are left out, as a real room is what that run is for.

use std::f64::consts::PI;
use std::io::Write;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use glam::{DVec3, Vec3};
use radiosity_accel::{Bvh, RayQuery};
use radiosity_core::random::XorShift64;
use radiosity_core::{MeshParams, Scene, Shape};
use radiosity_mesh::Mesh;
use radiosity_solver::{Problem, SolverParams};
use rayon::prelude::*;
use serde_json::json;

use crate::alloc;
use crate::output::{self, Targets};

/// Arguments of `radiosity bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Also write the figures as JSON here (`-` for stdout).
    #[arg(long)]
    pub json: Option<String>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    /// Leave out the ~100 k-element solve (it takes the longest).
    #[arg(long)]
    pub skip_large: bool,
    /// Write the triangles and segments of the ray case here (binary, for
    /// `scripts/embree_bench.py`, which traces the same rays with Embree).
    #[arg(long)]
    pub dump_rays: Option<String>,
    /// Also load, mesh and solve this scene to 1 % unshot (a big model, e.g. one written by
    /// `scripts/make_big_room.py`): time, peak heap and bytes per triangle. Repeatable.
    #[arg(long, value_name = "SCENE")]
    pub big: Vec<String>,
    /// With --big: solve each once more with every facet shooting on its own (no
    /// clustering), and print the ratio. Slow on big models: that is the point.
    #[arg(long)]
    pub big_baseline: bool,
    /// A real room (scene file, OBJ, glTF; e.g. one written by `scripts/real_rooms.py`):
    /// load and mesh it as `solve` does, time the solve to 1 % and 0.1 % unshot, peak heap,
    /// energy audit, and `verify`'s comparison with the path tracer. Repeatable; leaves out
    /// the fixed cases.
    #[arg(long, value_name = "SCENE")]
    pub real: Vec<String>,
    /// With --real: seconds of path tracing for each scene's reference.
    #[arg(long, default_value_t = 60.0, value_name = "S", allow_negative_numbers = true)]
    pub real_reference_seconds: f64,
}

/// Triangles of a UV sphere with `stacks × slices` cells.
fn uv_sphere(centre: DVec3, radius: f64, stacks: usize, slices: usize) -> Vec<[DVec3; 3]> {
    let at = |i: usize, j: usize| {
        let (theta, phi) = (PI * i as f64 / stacks as f64, 2.0 * PI * j as f64 / slices as f64);
        centre + radius * DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    let mut out = Vec::with_capacity(2 * stacks * slices);
    for i in 0..stacks {
        for j in 0..slices {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if i + 1 < stacks {
                out.push([a, b, c]);
            }
            if i > 0 {
                out.push([a, c, d]);
            }
        }
    }
    out
}

/// The Cornell box for the ray case: its walls and light as they are, each block face cut
/// into `n × n` quads (two triangles each), and two finely tessellated spheres.
fn ray_scene(cornell: &Scene, n: usize) -> Vec<[DVec3; 3]> {
    let mut tris = Vec::new();
    for object in &cornell.objects {
        let Shape::Polygons(polys) = &object.shape else { continue };
        for poly in polys {
            let v = poly.vertices();
            if object.name.contains("block") && v.len() == 4 {
                let at = |u: f64, w: f64| {
                    v[0] * ((1.0 - u) * (1.0 - w))
                        + v[1] * (u * (1.0 - w))
                        + v[2] * (u * w)
                        + v[3] * ((1.0 - u) * w)
                };
                let s = n as f64;
                for i in 0..n {
                    for j in 0..n {
                        let (u0, u1, w0, w1) =
                            (i as f64 / s, (i + 1) as f64 / s, j as f64 / s, (j + 1) as f64 / s);
                        tris.push([at(u0, w0), at(u1, w0), at(u1, w1)]);
                        tris.push([at(u0, w0), at(u1, w1), at(u0, w1)]);
                    }
                }
            } else {
                tris.extend((1..v.len() - 1).map(|k| [v[0], v[k], v[k + 1]]));
            }
        }
    }
    tris.extend(uv_sphere(DVec3::new(400.0, 90.0, 120.0), 80.0, 120, 160));
    tris.extend(uv_sphere(DVec3::new(130.0, 420.0, 300.0), 70.0, 120, 160));
    tris
}

/// `count` segments between area-uniform random points of `tris`, lifted off their surfaces
/// along the normals: radiosity-like rays, from everywhere to everywhere.
fn random_segments(tris: &[[DVec3; 3]], count: usize, lift: f64) -> Vec<(Vec3, Vec3)> {
    let mut cdf = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in tris {
        total += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        cdf.push(total);
    }
    let mut rng = XorShift64::new(0x2545_F491_4F6C_DD1D);
    let point = |rng: &mut XorShift64| {
        let k = cdf.partition_point(|&c| c < rng.next_f64() * total).min(tris.len() - 1);
        let t = &tris[k];
        let (s, v) = (rng.next_f64().sqrt(), rng.next_f64());
        let p = t[0] * (1.0 - s) + t[1] * (s * (1.0 - v)) + t[2] * (s * v);
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        (p, n)
    };
    (0..count)
        .map(|_| {
            let ((a, na), (b, nb)) = (point(&mut rng), point(&mut rng));
            // Lift each end towards the other so it leaves its own surface on the open side.
            let side = |n: DVec3, d: DVec3| if n.dot(d) >= 0.0 { n } else { -n };
            ((a + side(na, b - a) * lift).as_vec3(), (b + side(nb, a - b) * lift).as_vec3())
        })
        .collect()
}

/// Writes the ray case for `scripts/embree_bench.py`: little-endian u32 triangle count,
/// u32 segment count, then 9 f32 per triangle and 6 f32 per segment.
fn dump_rays(path: &str, tris: &[[Vec3; 3]], segments: &[(Vec3, Vec3)], force: bool) -> Result<()> {
    let mut out = Vec::with_capacity(8 + tris.len() * 36 + segments.len() * 24);
    out.write_all(&(tris.len() as u32).to_le_bytes())?;
    out.write_all(&(segments.len() as u32).to_le_bytes())?;
    for v in tris.iter().flatten() {
        for c in v.to_array() {
            out.write_all(&c.to_le_bytes())?;
        }
    }
    for (a, b) in segments {
        for c in a.to_array().into_iter().chain(b.to_array()) {
            out.write_all(&c.to_le_bytes())?;
        }
    }
    output::write_file(std::path::Path::new(path), force, &out)
}

/// Case (a): occlusion rays per second on one thread and on all.
fn occlusion_case(cornell: &Scene, dump: Option<&str>, force: bool) -> Result<serde_json::Value> {
    let tris64 = ray_scene(cornell, 40);
    let tris: Vec<[Vec3; 3]> = tris64.iter().map(|t| t.map(|p| p.as_vec3())).collect();
    let t = Instant::now();
    let bvh = Bvh::new(&tris);
    let build = t.elapsed().as_secs_f64();
    let segments = random_segments(&tris64, 1_000_000, 1e-3);
    if let Some(path) = dump {
        dump_rays(path, &tris, &segments, force)?;
    }
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
    let threads = rayon::current_num_threads();
    output::stdout(&format!(
        "(a) occlusion rays, {} triangles (BVH build {build:.2} s): 1 thread {:.2} M rays/s, {threads} threads {:.2} M rays/s ({:.2}×); {:.1} % of {} segments blocked\n",
        tris.len(),
        one / 1e6,
        all / 1e6,
        all / one,
        100.0 * blocked as f64 / segments.len() as f64,
        segments.len()
    ))?;
    Ok(json!({"case": "occlusion_rays", "triangles": tris.len(), "segments": segments.len(),
        "blocked": blocked, "bvh_build_seconds": build, "rays_per_s_1_thread": one,
        "rays_per_s_all_threads": all, "threads": threads}))
}

/// Meshes, solves and prints one line: time, shots, rays, and the peak heap of the whole
/// case (mesh, BVH and solver state) above what was live before it.
fn solve_case(
    id: &str,
    name: &str,
    mesh: impl FnOnce() -> Result<Mesh>,
    params: SolverParams,
) -> Result<serde_json::Value> {
    alloc::reset_peak();
    let before = alloc::live();
    let problem = Problem::from_mesh(Arc::new(mesh()?));
    let (patches, elements) = (problem.mesh().patches.len(), problem.mesh().elements.len());
    let mut solver = problem.solver(params)?;
    let r = solver.solve();
    let peak = alloc::peak().saturating_sub(before);
    let secs = r.elapsed.as_secs_f64();
    output::stdout(&format!(
        "{name:<40} {patches:>6} patches {elements:>7} elements {:>5} shots {secs:>8.3} s {:>6.2} M rays/s  unshot {:.2e} ({})  peak heap {:.1} MB ({:.0} B/element)\n",
        r.total_shots,
        r.rays as f64 / secs.max(1e-9) / 1e6,
        r.unshot_fraction,
        r.stop_reason.map_or("running", |s| s.as_str()),
        peak as f64 / 1e6,
        peak as f64 / elements as f64,
    ))?;
    Ok(json!({"case": id, "patches": patches, "elements": elements, "shots": r.total_shots,
        "seconds": secs, "rays": r.rays, "unshot_fraction": r.unshot_fraction,
        "peak_heap_bytes": peak, "bytes_per_element": peak as f64 / elements as f64}))
}

/// (e) A big model from a file: load, mesh (with the scene's or default mesh settings, as
/// `solve` does), solve to 1 % unshot; the peak heap of the whole case per input triangle.
fn big_case(scene_arg: &str, clustering: bool) -> Result<serde_json::Value> {
    alloc::reset_peak();
    let before = alloc::live();
    let start = Instant::now();
    let mut scene = radiosity_io::resolve_scene(scene_arg)?.scene;
    // As `solve` does without `--sides`: closed models lit from one side are one-sided.
    radiosity_mesh::seal_closed_objects(&mut scene);
    let loaded = start.elapsed().as_secs_f64();
    let problem = Problem::new(&scene, &scene.mesh_params())?;
    let meshed = start.elapsed().as_secs_f64() - loaded;
    let triangles = problem.mesh().occluders.len();
    let (patches, elements) = (problem.mesh().patches.len(), problem.mesh().elements.len());
    let params = SolverParams { unshot_threshold: 0.01, clustering, ..SolverParams::default() };
    let mut solver = problem.solver(params)?;
    let groups = solver.shooter_groups();
    let r = solver.solve();
    let secs = r.elapsed.as_secs_f64();
    let peak = alloc::peak().saturating_sub(before);
    let how = if clustering { format!("{groups} groups") } else { "facets alone".into() };
    output::stdout(&format!(
        "(e) {scene_arg} ({how})\n    {triangles} triangles {patches} patches {elements} elements: load {loaded:.2} s, mesh {meshed:.2} s, solve {secs:.2} s ({} shots, unshot {:.2e}), peak heap {:.0} MB ({:.0} B/triangle)\n",
        r.total_shots,
        r.unshot_fraction,
        peak as f64 / 1e6,
        peak as f64 / triangles.max(1) as f64,
    ))?;
    Ok(json!({"case": "big", "scene": scene_arg, "clustering": clustering, "groups": groups,
        "triangles": triangles, "patches": patches, "elements": elements, "load_seconds": loaded,
        "mesh_seconds": meshed, "solve_seconds": secs, "shots": r.total_shots,
        "unshot_fraction": r.unshot_fraction, "peak_heap_bytes": peak,
        "bytes_per_triangle": peak as f64 / triangles.max(1) as f64}))
}

/// The Cornell box meshed with its own patch size and elements of `element_size` mm.
fn cornell_mesh(cornell: &Scene, element_size: f64) -> Result<Mesh> {
    let patch = cornell.mesh_params().patch_size.max(element_size);
    Ok(Mesh::build(cornell, &MeshParams::try_new(patch, element_size)?)?)
}

/// Runs `bench`.
pub fn run(a: BenchArgs) -> Result<()> {
    let mut targets = Targets::new(a.force);
    if let Some(path) = a.json.as_deref().filter(|p| *p != "-") {
        targets.file(std::path::Path::new(path), "--json")?;
    }
    if let Some(path) = a.dump_rays.as_deref() {
        targets.file(std::path::Path::new(path), "--dump-rays")?;
    }
    if !a.real.is_empty() {
        crate::bench_real::check_reference_seconds(a.real_reference_seconds)?;
    }
    let threads = rayon::current_num_threads();
    output::stdout(&format!("radiosity bench ({threads} threads)\n"))?;
    let mut cases = if a.real.is_empty() { fixed_cases(&a)? } else { Vec::new() };

    for scene in &a.big {
        let clustered = big_case(scene, true)?;
        if a.big_baseline {
            let alone = big_case(scene, false)?;
            let ratio = alone["solve_seconds"].as_f64().unwrap_or(f64::NAN)
                / clustered["solve_seconds"].as_f64().unwrap_or(f64::NAN);
            output::stdout(&format!(
                "    clustered facets solve {ratio:.1}× faster than facets shooting alone\n"
            ))?;
            cases.push(json!({"case": "big_clustered_vs_alone", "clustered": clustered, "alone": alone,
                "speedup": ratio}));
        } else {
            cases.push(clustered);
        }
    }

    if !a.real.is_empty() {
        output::stdout(&crate::bench_real::header())?;
    }
    for scene in &a.real {
        cases.push(crate::bench_real::real_case(scene, a.real_reference_seconds)?);
    }

    if let Some(path) = &a.json {
        let text = serde_json::to_string_pretty(&json!({"threads": threads, "cases": cases}))? + "\n";
        if path == "-" {
            output::stdout(&text)?;
        } else {
            output::write_file(std::path::Path::new(path), a.force, text.as_bytes())?;
        }
    }
    Ok(())
}

/// Cases (a)–(d).
fn fixed_cases(a: &BenchArgs) -> Result<Vec<serde_json::Value>> {
    let cornell = radiosity_scenes::cornell_box();
    let mut cases = vec![occlusion_case(&cornell, a.dump_rays.as_deref(), a.force)?];

    // (b) The source document's case: ~100 facets, 1000 shots (it took about a minute).
    let seed = radiosity_io::resolve_scene("seed-room")?.scene;
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
    let mut v =
        solve_case("source_document", "(b) source document (≥100 facets, 1000 shots)", || Ok(seed_mesh), p)?;
    let secs = v["seconds"].as_f64().unwrap_or(f64::NAN);
    output::stdout(&format!("    vs the document's ~60 s: {:.0}× faster\n", 60.0 / secs))?;
    v["speedup_vs_document"] = json!(60.0 / secs);
    cases.push(v);

    // (c) Cornell at ~10 k elements, fast path against the reference path in this process.
    let fast = solve_case(
        "cornell_10k",
        "(c) Cornell ~10 k elements",
        || cornell_mesh(&cornell, 18.0),
        SolverParams::default(),
    )?;
    let reference = solve_case(
        "cornell_10k_reference",
        "    same, reference path (no shortcuts)",
        || cornell_mesh(&cornell, 18.0),
        SolverParams { reference_path: true, ..SolverParams::default() },
    )?;
    let ratio =
        reference["seconds"].as_f64().unwrap_or(f64::NAN) / fast["seconds"].as_f64().unwrap_or(f64::NAN);
    output::stdout(&format!("    fast path {ratio:.2}× faster than the reference path\n"))?;
    cases.push(json!({"case": "cornell_10k_fast_vs_reference", "fast": fast, "reference": reference,
        "speedup": ratio}));
    // The single-core target: ~15 k elements on one thread.
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    cases.push(one_thread.install(|| {
        solve_case(
            "cornell_15k_1_thread",
            "(c) Cornell ~15 k elements, 1 thread",
            || cornell_mesh(&cornell, 14.3),
            SolverParams::default(),
        )
    })?);
    if !a.skip_large {
        cases.push(solve_case(
            "cornell_100k",
            "(c) Cornell ~100 k elements",
            || cornell_mesh(&cornell, 5.7),
            SolverParams::default(),
        )?);
    }

    Ok(cases)
}
