//! The renderer's own tests: gathering, interpolation, the camera, parameter checks.

use super::params::{RenderError, RenderParams, Shading};
use super::primary::{barycentric, inverse_bilinear};
use super::*;
use crate::cache::Site;
use crate::gather::{DirectMis, Gather};
use glam::{DVec2, DVec3};
use radiosity_core::random::Rng;
use radiosity_core::{Camera, CameraRays, Rgb};
use radiosity_mesh::Mesh;
use std::f64::consts::PI;
use std::sync::Arc;

use radiosity_core::{Facing, Material, MeshParams, Object, Polygon, Scene, Shape, Sides, Sphere};

/// A sample that gathers on its own (a cache covers its neighbours, not it) must spread
/// its rays over the whole hemisphere, not over its share of the pixel's grid, which is
/// one band of directions. On the Cornell box's ceiling 5 mm from the green wall (half the
/// hemisphere is that wall), 2 000 such samples of 8 rays, each the 4th of its pixel's 16,
/// average within 3 % of a 4 096-ray record (their noise, about 0.5 %, and the record's,
/// well under that). Given its share of the pixel's grid instead, it read twice the
/// record's irradiance.
#[test]
fn a_sample_that_gathers_alone_covers_the_whole_hemisphere() {
    let scene = radiosity_scenes::cornell_box();
    let problem = radiosity_solver::Problem::new(&scene, &scene.mesh_params()).unwrap();
    let mut solver = problem.solver(radiosity_solver::SolverParams::preview()).unwrap();
    solver.solve();
    let solution = solver.solution();
    let renderer = Renderer::new(problem.mesh().clone());
    let hit = renderer
        .trace(&solution, DVec3::new(5.0, 300.0, 300.0), DVec3::Y, Shading::Smooth)
        .unwrap()
        .expect("the ceiling");
    let (e, x) = (hit.element as usize, hit.p_world);
    let (n, origin) = renderer.shading_frame(e, x);
    let site = Site { point: x, normal: n, origin, pixel_size: 1.0 };
    let mut rng = Rng::for_task(1, 2, 3);
    let record = renderer.gather_record(&solution, &site, 4096, Shading::Smooth, &mut rng);
    let params = RenderParams { gather: Gather::Full, ..RenderParams::default() };
    let mis = DirectMis { lights: 0, cosines: params.gather_rays };
    let count = 2000;
    let alone: Rgb = (0..count)
        .map(|_| renderer.cosine_rays(&solution, origin, n, &params, 3, mis, true, false, &mut rng).1)
        .sum::<Rgb>()
        / f64::from(count);
    let (got, expected) = (alone.luminance(), record.irradiance.luminance());
    assert!((got / expected - 1.0).abs() < 0.03, "alone {got} against the record's {expected}");
}

/// A gathering ray that lands a hair's width away, on a floor element half in a blocker's
/// shadow, takes the light of the point it lands on and not the element's mean: under
/// the blocker (where nothing lights the floor, the rest of the scene being black) about
/// none; in the open, the lamp's direct light (the closed form of a point under a
/// square). A long ray still takes the element's mean.
#[test]
fn short_gathering_rays_see_the_light_where_they_land() {
    let light = Material::try_new("light", Rgb::ZERO, Rgb::splat(1.0)).unwrap();
    let grey = Material::try_new("grey", Rgb::splat(0.5), Rgb::ZERO).unwrap();
    let black = Material::try_new("black", Rgb::ZERO, Rgb::ZERO).unwrap();
    let square = |x0: f64, x1: f64, y0: f64, y1: f64, z: f64, up: bool| {
        let mut v =
            vec![DVec3::new(x0, y0, z), DVec3::new(x1, y0, z), DVec3::new(x1, y1, z), DVec3::new(x0, y1, z)];
        if !up {
            v.reverse();
        }
        Polygon::try_new(v).unwrap()
    };
    let object = |name: &str, material: usize, polygon: Polygon, sides: Sides| Object {
        name: name.into(),
        material,
        shape: Shape::Polygons(vec![polygon]),
        sides,
    };
    let objects = vec![
        object("lamp", 0, square(-0.25, 0.25, -0.25, 0.25, 1.0, false), Sides::One),
        object("floor", 1, square(-2.0, 2.0, -2.0, 2.0, 0.0, true), Sides::One),
        // Over x < 0.1 at half height: the floor's x < 0 is in full shadow.
        object("sheet", 2, square(-3.0, 0.1, -3.0, 3.0, 0.5, true), Sides::Two { emits_back: false }),
    ];
    let scene = Scene::try_new("half shadow", None, vec![light, grey, black], objects).unwrap();
    // One element for the whole floor, no cut along the shadow: the mesh's worst case.
    let mut params = MeshParams::try_new(8.0, 8.0).unwrap();
    params.shadow_outlines = false;
    params.contacts = false;
    params.corner_refinement = 0;
    params.adaptive_levels = 0;
    let problem = radiosity_solver::Problem::new(&scene, &params).unwrap();
    let mut solver = problem.solver(radiosity_solver::SolverParams::default()).unwrap();
    solver.solve();
    let solution = solver.solution();
    let renderer = Renderer::new(problem.mesh().clone());
    let mesh = renderer.mesh().clone();
    let floor = mesh.object_names.iter().position(|n| n == "floor").unwrap();
    let elements: Vec<usize> =
        (0..mesh.elements.len()).filter(|&e| mesh.element_object(e) == floor).collect();
    assert_eq!(elements.len(), 1, "the floor is one element");
    let e = elements[0];
    let mean = solution.element_radiosity[e].to_array()[0];
    let mut rng = Rng::for_task(1, 0, 0);
    let mut at = |x: f64, distance: f64| {
        let y = DVec3::new(x, 0.0, 0.0);
        (0..256)
            .map(|_| renderer.reflected(&solution, e, y, distance, Shading::Flat, &mut rng).to_array()[0])
            .sum::<f64>()
            / 256.0
    };
    let (shadow, open, far) = (at(-1.0, 1e-3), at(0.6, 1e-3), at(-1.0, 100.0));
    // ρ E F from a point 1 below a square lamp of side 0.5, 0.6 off its axis; F summed
    // over the four rectangles the point's foot cuts the lamp into (Howell B-3, a
    // differential area to a parallel rectangle from a corner).
    let corner = |a: f64, b: f64| {
        let (x, y) = (a.abs(), b.abs());
        let f = (x / (1.0 + x * x).sqrt() * (y / (1.0 + x * x).sqrt()).atan()
            + y / (1.0 + y * y).sqrt() * (x / (1.0 + y * y).sqrt()).atan())
            / (2.0 * PI);
        f * a.signum() * b.signum()
    };
    let f = corner(0.25 - 0.6, 0.25) - corner(-0.25 - 0.6, 0.25) - corner(0.25 - 0.6, -0.25)
        + corner(-0.25 - 0.6, -0.25);
    let expected = 0.5 * f;
    assert!(mean > 0.05 * expected, "the element's mean {mean} against {expected} in the open");
    assert!(shadow < 0.02 * mean, "under the sheet: {shadow}, the element's mean {mean}");
    assert!((open / expected - 1.0).abs() < 0.05, "in the open: {open}, closed form {expected}");
    assert_eq!(far, mean, "a long ray takes the element's mean");
}

/// A tessellated ball under a small lamp: from points whose interpolated normal sees the
/// lamp low over the horizon (cosine under 0.25), a shadow ray to the lamp meets nothing,
/// as on the round ball those normals describe. Leaving from the facets themselves, 36 of
/// the 204 such rays hit the neighbouring facets.
#[test]
fn shadow_rays_leave_a_smooth_ball_as_a_round_one() {
    let light = Material::try_new("light", Rgb::ZERO, Rgb::splat(1.0)).unwrap();
    let white = Material::try_new("white", Rgb::splat(0.5), Rgb::ZERO).unwrap();
    let lamp = [(-0.05, -0.05), (-0.05, 0.05), (0.05, 0.05), (0.05, -0.05)]
        .map(|(x, y)| DVec3::new(x, y, 10.0))
        .to_vec();
    let objects = vec![
        Object {
            name: "lamp".into(),
            material: 0,
            shape: Shape::Polygons(vec![Polygon::try_new(lamp).unwrap()]),
            sides: Sides::One,
        },
        Object {
            name: "ball".into(),
            material: 1,
            shape: Shape::Sphere(Sphere::try_new(DVec3::ZERO, 1.0, Facing::Outward).unwrap()),
            sides: Sides::One,
        },
    ];
    let scene = Scene::try_new("ball", None, vec![light, white], objects).unwrap();
    let mesh = Arc::new(Mesh::build(&scene, &MeshParams::try_new(0.5, 0.25).unwrap()).unwrap());
    let renderer = Renderer::new(mesh.clone());
    let target = DVec3::new(0.0, 0.0, 10.0);
    let (mut grazing, mut blocked, mut blocked_plain) = (0, 0, 0);
    for (e, el) in
        mesh.elements.iter().enumerate().filter(|&(e, _)| mesh.element_material(e).emission == Rgb::ZERO)
    {
        for &corner in el.vertex_indices() {
            let x = el.centre.lerp(mesh.positions[corner as usize], 0.8);
            let (n, origin) = renderer.shading_frame(e, x);
            let cos = n.dot((target - x).normalize());
            if !(0.0..0.25).contains(&cos) {
                continue;
            }
            grazing += 1;
            let hit = |origin: DVec3| renderer.blockers.occluded(origin.as_vec3(), target.as_vec3());
            blocked += usize::from(hit(origin));
            blocked_plain += usize::from(hit(x + n * renderer.lift));
        }
    }
    assert!(grazing > 100, "{grazing} points near the terminator");
    assert!(blocked * 100 <= grazing, "{blocked} of {grazing} shadow rays blocked");
    assert!(blocked_plain * 10 > grazing, "the facets block only {blocked_plain} of {grazing}");
}

#[test]
fn inverse_bilinear_inverts_the_bilinear_map() {
    let quads = [
        [DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(1.0, 1.0), DVec2::new(0.0, 1.0)],
        [DVec2::ZERO, DVec2::new(2.0, 0.0), DVec2::new(1.5, 1.0), DVec2::new(0.3, 0.8)],
        [DVec2::ZERO, DVec2::new(0.0, 1.0), DVec2::new(-1.2, 1.1), DVec2::new(-1.0, 0.0)],
    ];
    for [a, b, c, d] in quads {
        for i in 0..=10 {
            for j in 0..=10 {
                let (s, t) = (f64::from(i) / 10.0, f64::from(j) / 10.0);
                let p = a + (b - a) * s + (d - a) * t + (a - b + c - d) * (s * t);
                let (s2, t2) = inverse_bilinear(p, a, b, c, d);
                assert!((s - s2).abs() < 1e-9 && (t - t2).abs() < 1e-9, "({s}, {t}) -> ({s2}, {t2})");
            }
        }
    }
}

#[test]
fn barycentric_weights_sum_to_one_and_locate_points() {
    let (b, c) = (DVec2::new(2.0, 0.0), DVec2::new(0.0, 1.0));
    let w = barycentric(DVec2::new(0.5, 0.25), b, c);
    assert!((w[1] - 0.25).abs() < 1e-12 && (w[2] - 0.25).abs() < 1e-12 && (w[0] - 0.5).abs() < 1e-12);
    let w = barycentric(DVec2::new(5.0, 5.0), b, c);
    assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12 && w.iter().all(|x| *x >= 0.0));
}

#[test]
fn camera_puts_plus_x_on_the_left_when_looking_down_plus_z() {
    let cam = Camera::try_new(DVec3::ZERO, DVec3::Z, DVec3::Y, 60.0).unwrap();
    let rays = CameraRays::new(&cam, 100, 50);
    assert!(rays.direction(0.0, 25.0).x > 0.0);
    assert!(rays.direction(100.0, 25.0).x < 0.0);
    assert!(rays.direction(50.0, 0.0).y > 0.0);
    // The top edge is at half the vertical field of view.
    let top = rays.direction(50.0, 0.0);
    assert!((top.y.atan2(top.z).to_degrees() - 30.0).abs() < 1e-9);
}

#[test]
fn render_params_are_validated() {
    assert!(RenderParams::default().validate().is_ok());
    assert!(RenderParams::preview().validate().is_ok());
    assert!(RenderParams::high_quality().validate().is_ok());
    let bad = RenderParams { samples_per_pixel: 0, ..RenderParams::default() };
    assert!(matches!(bad.validate(), Err(RenderError::BadParameter { name: "samples_per_pixel", .. })));
    let bad = RenderParams { width: 0, ..RenderParams::default() };
    assert!(bad.validate().is_err());
}
