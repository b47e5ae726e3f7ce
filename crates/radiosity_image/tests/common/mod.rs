//! Scenes and helpers shared by the integration tests.
#![allow(dead_code)] // each test binary uses its own subset

use std::sync::Arc;

use radiosity_core::glam::DVec3;
use radiosity_core::{Camera, Material, Mesh, MeshParams, Object, Polygon, Rgb, Scene, Shape};
use radiosity_solver::{Solution, Solver, SolverParams, occluder_triangles};

fn poly(points: &[[f64; 3]]) -> Polygon {
    Polygon::try_new(points.iter().map(|p| DVec3::from_array(*p)).collect()).expect("valid polygon")
}

/// The Cornell box exactly as `scenes/cornell.toml` gives it (measured geometry in mm,
/// reflectances in linear sRGB, the light in a hole in the ceiling), built here because this
/// crate does not depend on the scene-file loader.
pub fn cornell_box() -> Scene {
    let m = |name: &str, rho: [f64; 3], e: [f64; 3]| {
        Material::try_new(name, Rgb::from_array(rho), Rgb::from_array(e)).expect("valid material")
    };
    let materials = vec![
        m("white", [0.738263, 0.736006, 0.738435], [0.0; 3]),
        m("green", [0.068861, 0.398126, 0.08673], [0.0; 3]),
        m("red", [0.493818, 0.049037, 0.051125], [0.0; 3]),
        m("light", [0.0; 3], [65.3094, 34.0744, 8.7042]),
    ];
    let (white, green, red, light) = (0, 1, 2, 3);
    let o = |name: &str, material: usize, faces: &[&[[f64; 3]]]| Object {
        name: name.into(),
        material,
        shape: Shape::Polygons(faces.iter().map(|f| poly(f)).collect()),
    };
    let objects = vec![
        o("floor", white, &[&[[552.8, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 559.2], [549.6, 0.0, 559.2]]]),
        o(
            "ceiling",
            white,
            &[
                &[[556.0, 548.8, 0.0], [556.0, 548.8, 227.0], [0.0, 548.8, 227.0], [0.0, 548.8, 0.0]],
                &[[556.0, 548.8, 332.0], [556.0, 548.8, 559.2], [0.0, 548.8, 559.2], [0.0, 548.8, 332.0]],
                &[[213.0, 548.8, 227.0], [213.0, 548.8, 332.0], [0.0, 548.8, 332.0], [0.0, 548.8, 227.0]],
                &[[556.0, 548.8, 227.0], [556.0, 548.8, 332.0], [343.0, 548.8, 332.0], [343.0, 548.8, 227.0]],
            ],
        ),
        o(
            "back_wall",
            white,
            &[&[[549.6, 0.0, 559.2], [0.0, 0.0, 559.2], [0.0, 548.8, 559.2], [556.0, 548.8, 559.2]]],
        ),
        o(
            "right_wall",
            green,
            &[&[[0.0, 0.0, 559.2], [0.0, 0.0, 0.0], [0.0, 548.8, 0.0], [0.0, 548.8, 559.2]]],
        ),
        o(
            "left_wall",
            red,
            &[
                &[[552.8, 0.0, 0.0], [549.6, 0.0, 559.2], [556.0, 548.8, 559.2]],
                &[[552.8, 0.0, 0.0], [556.0, 548.8, 559.2], [556.0, 548.8, 0.0]],
            ],
        ),
        o(
            "short_block_top",
            white,
            &[&[[130.0, 165.0, 65.0], [82.0, 165.0, 225.0], [240.0, 165.0, 272.0], [290.0, 165.0, 114.0]]],
        ),
        o(
            "short_block_1",
            white,
            &[&[[290.0, 0.0, 114.0], [290.0, 165.0, 114.0], [240.0, 165.0, 272.0], [240.0, 0.0, 272.0]]],
        ),
        o(
            "short_block_2",
            white,
            &[&[[130.0, 0.0, 65.0], [130.0, 165.0, 65.0], [290.0, 165.0, 114.0], [290.0, 0.0, 114.0]]],
        ),
        o(
            "short_block_3",
            white,
            &[&[[82.0, 0.0, 225.0], [82.0, 165.0, 225.0], [130.0, 165.0, 65.0], [130.0, 0.0, 65.0]]],
        ),
        o(
            "short_block_4",
            white,
            &[&[[240.0, 0.0, 272.0], [240.0, 165.0, 272.0], [82.0, 165.0, 225.0], [82.0, 0.0, 225.0]]],
        ),
        o(
            "tall_block_top",
            white,
            &[&[[423.0, 330.0, 247.0], [265.0, 330.0, 296.0], [314.0, 330.0, 456.0], [472.0, 330.0, 406.0]]],
        ),
        o(
            "tall_block_1",
            white,
            &[&[[423.0, 0.0, 247.0], [423.0, 330.0, 247.0], [472.0, 330.0, 406.0], [472.0, 0.0, 406.0]]],
        ),
        o(
            "tall_block_2",
            white,
            &[&[[472.0, 0.0, 406.0], [472.0, 330.0, 406.0], [314.0, 330.0, 456.0], [314.0, 0.0, 456.0]]],
        ),
        o(
            "tall_block_3",
            white,
            &[&[[314.0, 0.0, 456.0], [314.0, 330.0, 456.0], [265.0, 330.0, 296.0], [265.0, 0.0, 296.0]]],
        ),
        o(
            "tall_block_4",
            white,
            &[&[[265.0, 0.0, 296.0], [265.0, 330.0, 296.0], [423.0, 330.0, 247.0], [423.0, 0.0, 247.0]]],
        ),
        o(
            "light",
            light,
            &[&[[343.0, 548.8, 227.0], [343.0, 548.8, 332.0], [213.0, 548.8, 332.0], [213.0, 548.8, 227.0]]],
        ),
    ];
    let camera =
        Camera::try_new(DVec3::new(278.0, 273.0, -800.0), DVec3::new(278.0, 273.0, 0.0), DVec3::Y, 39.3076)
            .expect("valid camera");
    let mut scene = Scene::try_new("Cornell box", Some(camera), materials, objects).expect("valid scene");
    scene.mesh = Some(MeshParams::try_new(140.0, 35.0).expect("valid sizes"));
    scene
}

/// Meshes `scene` with its own parameters and solves it to a stop criterion.
pub fn solve(scene: &Scene, params: SolverParams) -> (Arc<Mesh>, Solution) {
    let mesh = Arc::new(Mesh::build(scene, &scene.mesh_params()).expect("mesh"));
    let accel = Arc::new(radiosity_accel::Bvh::new(&occluder_triangles(&mesh)));
    let mut solver = Solver::new(mesh.clone(), accel, params).expect("solver");
    solver.solve();
    (mesh, solver.solution())
}
