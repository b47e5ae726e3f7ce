//! Every shortcut of the solver that is meant to change only its speed gives the same answer
//! as the reference path (`SolverParams::reference_path`): per-patch shaft culling with
//! candidate lists, per-patch quadrature decisions, unclipped form factors for patches that
//! face the shooter, the four-lane f32 form factor for far, facing patches, and each shooter's
//! row of form factors kept for its later shots (which must be bit-identical to recomputing
//! it, whatever the memory budget).
//!
//! Tolerance: the shortcuts choose the same quadrature and the same rays as the reference. The
//! f32 kernel is within 3e-7 absolute and ~4e-7 relative in total of the f64 one (its own
//! test), so elements agree to 1e-5 relative. A ray that grazes a triangle edge may come out
//! differently in the tree and in a candidate list, moving that element's share of one shot
//! by its ray's share of the visibility (an eighth from a bright shooter, all of it from a
//! dim one, whose shot is small). Adaptive subdivision puts the smallest elements on shadow
//! edges, where rays graze the blockers' edges (the seed room: 0.21 % of its 17.9 k elements
//! differed). A shooter's row is also computed again when its unshot power has drifted past a
//! threshold (`first_shots`), a decision that 1e-7 apart can take one way on one path and the
//! other on the other; with it the seed room, meshed here with elements laid fine near other
//! geometry too (`proximity_refinement = 1`), has 63 of its 22.9 k elements (0.28 %) off. An
//! element in a slit lit only through it (the ceiling above the seed room's lamp, which hangs
//! 5 cm below it) gets all its light from rays grazing the slit's edges and is some fifty
//! times dimmer than the ceiling around the lamp, so one flipped ray moves it by several per
//! cent of its own value but by a thousandth of its object's mean. So: every element within
//! 1e-5 relative, except at most 0.5 % of elements, none of them off by more than 5 % of its
//! own value or 0.5 % of its object's mean; per-object means within 1e-4.

use radiosity_core::{MeshParams, Scene};
use radiosity_scenes::{furnace_box, two_plates, unit_cube_floor_light};
use radiosity_solver::{Problem, Solution, SolverParams};

fn solve(problem: &Problem, reference_path: bool, max_shots: u64) -> Solution {
    solve_with(
        problem,
        SolverParams { reference_path, max_shots: Some(max_shots), ..SolverParams::default() },
    )
}

fn solve_with(problem: &Problem, params: SolverParams) -> Solution {
    let mut solver = problem.solver(params).unwrap();
    solver.solve();
    solver.solution()
}

fn compare(name: &str, scene: &Scene, max_shots: u64) {
    compare_meshed(name, scene, &scene.mesh_params(), max_shots);
}

fn compare_meshed(name: &str, scene: &Scene, params: &MeshParams, max_shots: u64) {
    let problem = Problem::new(scene, params).unwrap();
    let mesh = problem.mesh();
    let fast = solve(&problem, false, max_shots);
    let reference = solve(&problem, true, max_shots);
    assert_eq!(fast.shots, reference.shots, "{name}");
    let (fo, ro) = (fast.object_radiosity(mesh), reference.object_radiosity(mesh));
    // Each object's brightest mean channel, of either face.
    let means: Vec<f64> = ro
        .iter()
        .map(|o| o.radiosity.max_channel().max(o.radiosity_back.map_or(0.0, |b| b.max_channel())))
        .collect();
    let mut off = 0;
    for (e, (a, b)) in fast.element_radiosity.iter().zip(&reference.element_radiosity).enumerate() {
        let mean = means[mesh.element_object(e)];
        for (x, y) in [(a.r, b.r), (a.g, b.g), (a.b, b.b)] {
            let d = (x - y).abs() / y.abs().max(1e-300);
            if d > 1e-5 {
                assert!(
                    d < 0.05 || (x - y).abs() < 0.005 * mean,
                    "{name}: element {e}: {x} vs reference {y} (object mean {mean})"
                );
                off += 1;
                break;
            }
        }
    }
    let n = mesh.elements.len();
    assert!(off * 1000 <= 5 * n, "{name}: {off} of {n} elements differ");
    for (f, r) in fo.iter().zip(&ro) {
        for (x, y) in [(f.radiosity.r, r.radiosity.r), (f.radiosity.g, r.radiosity.g)] {
            assert!((x - y).abs() <= 1e-4 * y.abs().max(1e-12), "{name}: {}: {x} vs {y}", f.name);
        }
    }
}

#[test]
fn closed_form_scenes_solve_the_same_on_both_paths() {
    compare("furnace", &furnace_box(0.9, 1.0), 400);
    compare("two plates", &two_plates(1.0, 1.0, 0.5, 1.0), 200);
    compare("unit cube", &unit_cube_floor_light(0.5), 400);
}

#[test]
fn the_cornell_box_solves_the_same_on_both_paths() {
    let scene = radiosity_io::builtin_scene("cornell").unwrap();
    compare("cornell", &scene, 300);
}

#[test]
fn the_seed_room_solves_the_same_on_both_paths() {
    let scene = radiosity_io::builtin_scene("seed-room").unwrap();
    let params = scene.mesh_params().with_proximity_refinement(1).unwrap();
    compare_meshed("seed-room", &scene, &params, 300);
}

/// Kept rows are a pure cache: with none kept, all kept, or the budget running out half way
/// (so some shooters are recomputed and some replayed), every element is bit-identical.
#[test]
fn kept_rows_change_nothing_whatever_the_budget() {
    let scene = radiosity_io::builtin_scene("cornell").unwrap();
    let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
    let mesh = problem.mesh();
    let with = |row_cache_bytes| {
        solve_with(
            &problem,
            SolverParams {
                max_shots: Some(400),
                row_cache_bytes: Some(row_cache_bytes),
                ..SolverParams::default()
            },
        )
    };
    let all = with(usize::MAX);
    // One row of the Cornell box is at most 4 bytes per element: this keeps about ten.
    let some = with(40 * mesh.elements.len());
    let none = with(0);
    assert_eq!(all.shots, 400);
    assert_eq!(all.element_radiosity, none.element_radiosity);
    assert_eq!(some.element_radiosity, none.element_radiosity);
    assert_eq!(all.element_unshot, none.element_unshot);
}

/// One thread or two give bit-identical solutions on a mesh large enough for every parallel
/// part of a shot (the receiving patches' first pass, penumbra rays, and, above 32 k
/// elements only, gathering the row, the uneven shooters' power sums and applying the shot,
/// block by block of patches).
#[test]
fn one_and_two_threads_agree_on_a_large_cornell_box() {
    let scene = radiosity_io::builtin_scene("cornell").unwrap();
    let params = radiosity_core::MeshParams::try_new(scene.mesh_params().patch_size, 9.0).unwrap();
    let problem = Problem::new(&scene, &params).unwrap();
    let mesh = problem.mesh();
    assert!(mesh.elements.len() > 32_768, "{} elements", mesh.elements.len());
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| solve_with(&problem, SolverParams { max_shots: Some(60), ..SolverParams::default() }))
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.shots, 60);
    assert_eq!(one.element_radiosity, two.element_radiosity);
    assert_eq!(one.element_unshot, two.element_unshot);
}
