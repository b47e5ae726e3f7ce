//! Traces the segments of a ray file (written by `radiosity bench --dump-rays`) with this
//! crate's BVH and, for a baseline in the same process, with obvhs's compressed wide BVH:
//!
//!     radiosity bench --skip-large --dump-rays /tmp/rays.bin --force
//!     cargo run --release -p radiosity_accel --example ray_bench -- /tmp/rays.bin
//!
//! File: u32 triangle count, u32 segment count, the triangles (9 f32 each), the segments
//! (6 f32 each), little-endian. Prints rays/s of both, alternating rounds, and their ratio.
//! An optional second argument sets the number of rounds (default 5); each figure is the
//! best round. Rounds are timed by the thread's own time on a processor
//! (`/proc/thread-self/schedstat`, where there is one), so other work on a shared machine
//! slows the wall clock but not the figures much.

use std::time::Instant;

use glam::{Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    cwbvh::builder::build_cwbvh_from_tris,
    ray::{Ray, RayHit},
    rt_triangle::RtTriangle,
    triangle::Triangle,
};
use radiosity_accel::{BEST_BUILD_LIMIT, Bvh, RayQuery};

/// Seconds this thread has run on a processor, or wall-clock seconds since `start` where
/// the kernel does not say.
fn thread_seconds(start: Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .map_or_else(|| start.elapsed().as_secs_f64(), |ns| ns as f64 * 1e-9)
}

fn main() -> Result<(), String> {
    let path = std::env::args().nth(1).ok_or("usage: ray_bench RAYS.bin [ROUNDS]")?;
    let rounds: usize = match std::env::args().nth(2) {
        Some(r) => r.parse().map_err(|e| format!("rounds {r}: {e}"))?,
        None => 5,
    };
    let start = Instant::now();
    let data = std::fs::read(&path).map_err(|e| format!("{path}: {e}"))?;
    let word = |i: usize| u32::from_le_bytes(data[4 * i..4 * i + 4].try_into().unwrap());
    let float = |i: usize| f32::from_le_bytes(data[4 * i..4 * i + 4].try_into().unwrap());
    let (nt, ns) = (word(0) as usize, word(1) as usize);
    if data.len() != 8 + 36 * nt + 24 * ns {
        return Err(format!("{path}: {} bytes, expected {}", data.len(), 8 + 36 * nt + 24 * ns));
    }
    let v = |i: usize| Vec3::new(float(i), float(i + 1), float(i + 2));
    let tris: Vec<[Vec3; 3]> = (0..nt).map(|t| [v(2 + 9 * t), v(5 + 9 * t), v(8 + 9 * t)]).collect();
    let base = 2 + 9 * nt;
    let segs: Vec<(Vec3, Vec3)> = (0..ns).map(|s| (v(base + 6 * s), v(base + 6 * s + 3))).collect();

    let t = Instant::now();
    let ours = Bvh::new(&tris);
    let build_ours = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let obv: Vec<Triangle> =
        tris.iter().map(|t| Triangle { v0: t[0].into(), v1: t[1].into(), v2: t[2].into() }).collect();
    let params = if obv.len() <= BEST_BUILD_LIMIT {
        BvhBuildParams::very_slow_build()
    } else {
        BvhBuildParams::medium_build()
    };
    let cw = build_cwbvh_from_tris(&obv, params, &mut std::time::Duration::default());
    let leaves: Vec<RtTriangle> =
        cw.primitive_indices.iter().map(|&i| RtTriangle::from(&obv[i as usize])).collect();
    let build_cw = t.elapsed().as_secs_f64();
    println!("{nt} triangles, {ns} segments; build: ours {build_ours:.2} s, obvhs CwBvh {build_cw:.2} s");

    let cw_occluded = |a: Vec3, b: Vec3| {
        let d = Vec3A::from(b - a);
        let eps = 1e-7 * d.abs().max_element();
        let d =
            Vec3A::select(d.abs().cmplt(Vec3A::splat(eps)), Vec3A::splat(eps).copysign(d + Vec3A::ZERO), d);
        !cw.ray_traverse_miss(Ray::new(a.into(), d, 1e-4, 1.0 - 1e-4), |ray, id| leaves[id].intersect(ray))
    };
    let (mut best_ours, mut best_cw) = (f64::MAX, f64::MAX);
    let (mut blocked_ours, mut blocked_cw) = (0, 0);
    for _ in 0..rounds {
        let t = thread_seconds(start);
        blocked_ours = segs.iter().filter(|(a, b)| ours.occluded(*a, *b)).count();
        best_ours = best_ours.min(thread_seconds(start) - t);
        let t = thread_seconds(start);
        blocked_cw = segs.iter().filter(|(a, b)| cw_occluded(*a, *b)).count();
        best_cw = best_cw.min(thread_seconds(start) - t);
    }
    // Closest hits (the image renderer's query) along the segments' lines, unbounded, on a
    // fifth of them: the same triangle from both, or a tie in distance.
    let rays = &segs[..ns / 5];
    let cw_closest = |a: Vec3, b: Vec3| {
        let mut hit = RayHit::none();
        let ray = Ray::new(a.into(), Vec3A::from(b - a), 0.0, f32::INFINITY);
        cw.ray_traverse(ray, &mut hit, |ray, id| leaves[id].intersect(ray));
        (hit.t < f32::INFINITY).then(|| (cw.primitive_indices[hit.primitive_id as usize], hit.t))
    };
    let (mut best_ours_c, mut best_cw_c) = (f64::MAX, f64::MAX);
    let (mut hits_ours, mut hits_cw) = (0, 0);
    for _ in 0..rounds {
        let t = thread_seconds(start);
        hits_ours =
            rays.iter().filter(|(a, b)| ours.closest_hit(*a, *b - *a, f32::INFINITY).is_some()).count();
        best_ours_c = best_ours_c.min(thread_seconds(start) - t);
        let t = thread_seconds(start);
        hits_cw = rays.iter().filter(|(a, b)| cw_closest(*a, *b).is_some()).count();
        best_cw_c = best_cw_c.min(thread_seconds(start) - t);
    }
    let differ = rays
        .iter()
        .filter(|(a, b)| {
            let (x, y) = (ours.closest_hit(*a, *b - *a, f32::INFINITY), cw_closest(*a, *b));
            match (x, y) {
                (Some(x), Some((id, t))) => x.triangle != id && (x.t - t).abs() > 1e-5 * t,
                (x, y) => x.is_some() != y.is_some(),
            }
        })
        .count();
    let (c1, c2) = (rays.len() as f64 / best_ours_c / 1e6, rays.len() as f64 / best_cw_c / 1e6);
    println!(
        "closest hits: ours {c1:.2} M rays/s ({hits_ours} hit), obvhs CwBvh {c2:.2} M rays/s ({hits_cw} hit): {:.2}×, {differ} differ",
        c1 / c2
    );
    // Where the two disagree, the brute-force answer says who is right.
    let brute = radiosity_accel::BruteForce::new(&tris);
    for (a, b) in &segs {
        let (x, y) = (ours.occluded(*a, *b), cw_occluded(*a, *b));
        if x != y {
            println!("disagree on {a} -> {b}: ours {x}, CwBvh {y}, brute force {}", brute.occluded(*a, *b));
        }
    }
    let (r1, r2) = (ns as f64 / best_ours / 1e6, ns as f64 / best_cw / 1e6);
    println!(
        "ours {r1:.2} M rays/s ({blocked_ours} blocked), obvhs CwBvh {r2:.2} M rays/s ({blocked_cw} blocked): {:.2}×",
        r1 / r2
    );
    Ok(())
}
