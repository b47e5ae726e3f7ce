//! Criterion benchmarks of the solver's hot kernels: `cargo bench -p radiosity_solver --features bench`.
//!
//! Per-call figures for the exact form factor (far, clipped, integrated over a receiver),
//! occlusion rays through the BVH and through a shaft's candidate list, and one whole shot
//! on a furnace box, so a change to a kernel shows up here before it shows up in
//! `radiosity bench`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{DVec3, Vec3};
use radiosity_accel::{Bvh, CandidateTriangles, RayQuery, Segments4};
use radiosity_core::MeshParams;
use radiosity_scenes::furnace_box;
use radiosity_solver::form_factor::{
    Rule, for_each_point, point_to_polygon, point_to_polygon_in_front, point_to_polygon_in_front_x4,
    points_to_polygon_in_front_x4,
};
use radiosity_solver::{Problem, SolverParams, StepBudget};

fn square(z: f64, size: f64) -> Vec<DVec3> {
    vec![
        DVec3::new(0.0, 0.0, z),
        DVec3::new(size, 0.0, z),
        DVec3::new(size, size, z),
        DVec3::new(0.0, size, z),
    ]
}

fn form_factors(c: &mut Criterion) {
    let shooter = square(1.0, 0.2);
    let p = DVec3::new(0.4, 0.3, 0.0);
    c.bench_function("point_to_polygon far", |b| {
        b.iter(|| point_to_polygon(black_box(p), DVec3::Z, black_box(&shooter)))
    });
    c.bench_function("point_to_polygon_in_front far", |b| {
        b.iter(|| point_to_polygon_in_front(black_box(p), DVec3::Z, black_box(&shooter)))
    });
    c.bench_function("point_to_polygon_in_front_x4 far (f32 lanes)", |b| {
        b.iter(|| point_to_polygon_in_front_x4(black_box(p), DVec3::Z, black_box(&shooter)))
    });
    // Four receivers at once, one per lane: divide by four for a per-receiver figure.
    let four = [p, p + DVec3::X * 0.01, p + DVec3::Y * 0.01, p + DVec3::new(0.01, 0.01, 0.0)];
    c.bench_function("points_to_polygon_in_front_x4 far, 4 receivers (f32 lanes)", |b| {
        b.iter(|| points_to_polygon_in_front_x4(black_box(&four), &[DVec3::Z; 4], 4, black_box(&shooter)))
    });
    // A receiver perpendicular to the shooter and touching it: clipping does real work.
    let wall = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.0, 0.2, 0.0), DVec3::new(0.0, 0.2, 1.0)];
    c.bench_function("point_to_polygon clipped", |b| {
        b.iter(|| point_to_polygon(black_box(DVec3::new(0.05, 0.1, 0.1)), DVec3::Z, black_box(&wall)))
    });
    let receiver = square(0.0, 0.05);
    c.bench_function("area_to_polygon gauss 4x4", |b| {
        b.iter(|| {
            let mut f = 0.0;
            for_each_point(black_box(&receiver), 4, Rule::Gauss, |q, w| {
                f += w * point_to_polygon(q, DVec3::Z, &shooter)
            });
            f
        })
    });
}

/// Deterministic points for ray benchmarks.
fn points(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = radiosity_core::random::XorShift64::new(seed);
    let mut next = move || rng.next_f32();
    (0..n).map(|_| Vec3::new(next(), next(), next()) * 10.0).collect()
}

fn rays(c: &mut Criterion) {
    let corners = points(3000, 0x9e37_79b9_7f4a_7c15);
    let tris: Vec<[Vec3; 3]> = corners
        .chunks(3)
        .map(|t| [t[0], t[0] + (t[1] - Vec3::splat(5.0)) * 0.1, t[0] + (t[2] - Vec3::splat(5.0)) * 0.1])
        .collect();
    let ends = points(2048, 7);
    let bvh = Bvh::new(&tris);
    c.bench_function("bvh occluded (1000 triangles)", |b| {
        let mut i = 0;
        b.iter(|| {
            i = (i + 2) % ends.len();
            bvh.occluded(ends[i], ends[i + 1])
        })
    });
    let few: Vec<u32> = (0..12).collect();
    let candidates = CandidateTriangles::new(&tris);
    c.bench_function("candidate list occluded (12 triangles)", |b| {
        let mut i = 0;
        b.iter(|| {
            i = (i + 2) % ends.len();
            candidates.occluded_by(ends[i], ends[i + 1], black_box(&few))
        })
    });
    let mut list = few.clone();
    c.bench_function("candidate list occluded, 4 rays at once (12 triangles)", |b| {
        let mut i = 0;
        b.iter(|| {
            i = (i + 8) % (ends.len() - 8);
            let from = [ends[i], ends[i + 1], ends[i + 2], ends[i + 3]];
            let to = [ends[i + 4], ends[i + 5], ends[i + 6], ends[i + 7]];
            candidates.occluded_x4(&Segments4::new(&from, &to, 4), black_box(&mut list))
        })
    });
}

fn shots(c: &mut Criterion) {
    let scene = furnace_box(0.7, 1.0);
    let problem = Problem::new(&scene, &MeshParams::try_new(0.25, 0.05).unwrap()).unwrap();
    let elements = problem.mesh().elements.len();
    let mut solver = problem.solver(SolverParams { unshot_threshold: 1e-12, ..Default::default() }).unwrap();
    c.bench_function(&format!("one shot, furnace box, {elements} elements"), |b| {
        b.iter(|| solver.step(StepBudget::Shots(1)))
    });
}

criterion_group!(benches, form_factors, rays, shots);
criterion_main!(benches);
