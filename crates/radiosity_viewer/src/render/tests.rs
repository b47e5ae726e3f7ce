//! Tests of the view renderer: offscreen frames, colours, detail levels.

use super::*;
use radiosity_core::MeshParams;
use radiosity_scenes::furnace_box;

/// The furnace in plain 2 × 2-element patches (ungraded), whose outlines the tests count.
fn furnace_mesh() -> Mesh {
    let scene = furnace_box(0.5, 1.0);
    let params = MeshParams::try_new(0.5, 0.25).unwrap().with_corner_refinement(0).unwrap();
    Mesh::build(&scene, &params).unwrap()
}

#[test]
fn triangles_face_their_elements() {
    let mesh = furnace_mesh();
    for (e, [a, b, c]) in oriented_triangles(&mesh) {
        let p = |i: u32| mesh.positions[i as usize];
        let n = (p(b) - p(a)).cross(p(c) - p(a));
        assert!(n.dot(mesh.elements[e as usize].normal) > 0.0);
    }
}

#[test]
fn edge_flags_mark_element_and_patch_outlines() {
    let mesh = furnace_mesh();
    let tris = oriented_triangles(&mesh);
    let flags = edge_flags(&mesh, &tris);
    let element_edges: u32 = flags.iter().map(|f| (f & 0b010101).count_ones()).sum();
    let patch_edges: u32 = flags.iter().map(|f| (f & 0b101010).count_ones()).sum();
    // Quads split in two: each triangle has two element edges and one diagonal.
    let quads = mesh.elements.iter().filter(|e| e.vertex_count == 4).count() as u32;
    let tris_only = mesh.elements.len() as u32 - quads;
    assert_eq!(element_edges, quads * 4 + tris_only * 3);
    // 2×2 elements per patch: each element has 2 of its 4 edges on the patch outline.
    assert_eq!(patch_edges, quads * 2 + tris_only * 2, "{} quads", quads);
    for f in flags {
        for i in 0..3 {
            let bits = (f >> (2 * i)) & 3;
            assert_ne!(bits, 2, "a patch edge is always an element edge");
        }
    }
}

/// Furnace: B = E / (1 − ρ) = 2 everywhere, so radiance 2/π wherever one looks.
#[test]
fn auto_exposure_of_a_uniform_scene_maps_its_radiance_to_middle_grey() {
    let mesh = furnace_mesh();
    let s = Solution { element_radiosity: vec![Rgb::splat(2.0); mesh.elements.len()], ..Default::default() };
    let extent = crate::SceneExtent::new(DVec3::ZERO, DVec3::ONE);
    let cam = crate::FlyCamera::from_scene_camera(
        &radiosity_core::Camera::try_new(DVec3::splat(0.5), DVec3::new(0.5, 0.5, 1.0), DVec3::Y, 60.0)
            .unwrap(),
        &extent,
    );
    let m = cam.clip_from_view(1.0) * cam.view_from_world();
    let ev = auto_exposure_ev(&mesh, &s, m, cam.position).unwrap();
    let expected = (radiosity_image::AUTO_EXPOSURE_KEY / (2.0 / std::f64::consts::PI)).log2();
    assert!((ev - expected).abs() < 1e-9, "{ev} vs {expected}");
    // Looking from outside, through the culled wall, still sees the lit far side.
    let dark = Solution { element_radiosity: vec![Rgb::ZERO; mesh.elements.len()], ..Default::default() };
    assert_eq!(auto_exposure_ev(&mesh, &dark, m, cam.position), None);
}

/// From the Cornell box's camera, the viewer's automatic exposure is that of
/// `render --exposure auto` (the same meter over the CPU renderer's pixels) within a
/// quarter of a stop: the solid-angle weights stand in for pixel counts, occlusion by the
/// blocks aside.
#[test]
fn auto_exposure_agrees_with_the_cpu_renderer() {
    use radiosity_solver::{Problem, SolverParams, StepBudget};
    let scene = radiosity_scenes::cornell_box();
    let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
    let mesh = problem.mesh();
    let mut solver = problem.solver(SolverParams::preview()).unwrap();
    solver.step(StepBudget::Shots(200));
    let solution = solver.solution();
    let camera = scene.camera.unwrap();
    let params = radiosity_image::RenderParams::preview();
    let picture = radiosity_image::Renderer::new(mesh.clone()).render(&solution, &camera, &params).unwrap();
    let cpu = radiosity_image::Exposure::Auto.ev_for(&picture.radiance);
    let (lo, hi) = mesh.bounds();
    let fly = crate::FlyCamera::from_scene_camera(&camera, &crate::SceneExtent::new(lo, hi));
    let aspect = f64::from(params.width) / f64::from(params.height);
    let gpu =
        auto_exposure_ev(mesh, &solution, fly.clip_from_view(aspect) * fly.view_from_world(), fly.position)
            .unwrap();
    eprintln!("viewer {gpu:.3} EV, render {cpu:.3} EV");
    assert!((gpu - cpu).abs() < 0.25, "viewer {gpu:.3} EV, render {cpu:.3} EV");
}

#[test]
fn false_colour_range_spans_four_decades_at_most() {
    let mesh = furnace_mesh();
    let s = Solution {
        vertex_radiosity: vec![Rgb::splat(1e-9), Rgb::splat(0.5), Rgb::splat(100.0), Rgb::ZERO],
        element_unshot: vec![Rgb::splat(-2.0), Rgb::ZERO],
        ..Default::default()
    };
    let (lo, hi) = false_colour_range(&s, &mesh, DisplayMode::FalseColour);
    assert!((hi - 2.0).abs() < 1e-9 && (lo + 2.0).abs() < 1e-9, "{lo} {hi}");
    let (lo, hi) = false_colour_range(&s, &mesh, DisplayMode::Unshot);
    assert!(lo < hi && (hi - 2f64.log10()).abs() < 0.51);
    assert_eq!(false_colour_range(&Solution::default(), &mesh, DisplayMode::Smooth), (-1.0, 0.0));
}

/// The furnace (ρ = 0.5, emission 1, B = 2 everywhere) receives E = (B − emission)/ρ = 2:
/// what the illuminance mode shows and the middle of its scale; a black surface shows none.
#[test]
fn illuminance_is_radiosity_less_emission_over_reflectance() {
    let mut mesh = furnace_mesh();
    let s = Solution { element_radiosity: vec![Rgb::splat(2.0); mesh.elements.len()], ..Default::default() };
    for e in 0..mesh.elements.len() {
        assert!((irradiance_of(&mesh, e, Rgb::splat(2.0)) - Rgb::splat(2.0)).max_channel().abs() < 1e-12);
    }
    // One value everywhere: the scale is a decade centred on it.
    let (lo, hi) = false_colour_range(&s, &mesh, DisplayMode::Illuminance);
    assert!(((lo + hi) / 2.0 - 2f64.log10()).abs() < 1e-9, "{lo} {hi}");
    mesh.materials[0].reflectance = Rgb::ZERO;
    let black =
        (0..mesh.elements.len()).find(|&e| mesh.element_material(e).reflectance == Rgb::ZERO).unwrap();
    assert_eq!(irradiance_of(&mesh, black, Rgb::splat(2.0)), Rgb::ZERO);
}

#[test]
fn false_colour_ramp_goes_from_blue_to_red() {
    let dark = false_colour(0.0);
    assert!(dark.iter().all(|c| *c < 0.2), "starts near black: {dark:?}");
    let [r, _, b] = false_colour(0.15);
    assert!(b > 0.9 && r < 0.3, "then blue");
    let [_, g, _] = false_colour(0.5);
    assert!(g > 0.9, "green in the middle");
    let [r, g, b] = false_colour(0.9);
    assert!(r > 0.7 && g < 0.2 && b < 0.1, "red at the top");
}
