//! Canonical test scenes with closed-form answers, shared by tests, benches and the built-in
//! scene names (see `shared/references/closed_forms.md`).

use glam::DVec3;

use crate::scene::{Facing, Object, Polygon, Scene, Shape, Sphere, box_faces};
use crate::{Material, MeshParams, Rgb};

fn material(name: &str, rho: f64, emission: f64) -> Material {
    Material::try_new(name, Rgb::splat(rho), Rgb::splat(emission)).expect("canonical material in range")
}

/// The furnace: a closed unit-metre box, lit from inside, every face with reflectance `rho`
/// and emission `emission`. Closed form: B = E / (1 − ρ) everywhere.
///
/// # Panics
/// When `rho` is outside [0, 1) or `emission` is negative (a bug in the caller).
pub fn furnace_box(rho: f64, emission: f64) -> Scene {
    let faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Inward, 0.0).expect("unit box");
    let mut s = Scene::try_new(
        "Furnace box",
        None,
        vec![material("furnace", rho, emission)],
        vec![Object { name: "box".into(), material: 0, shape: Shape::Polygons(faces) }],
    )
    .expect("furnace scene is valid");
    s.mesh = Some(MeshParams::try_new(0.5, 0.125).expect("sizes > 0"));
    s
}

/// A closed sphere of radius 1 seen from inside, reflectance `rho`, emission `emission`.
/// Closed form: B = E / (1 − ρ) everywhere.
///
/// # Panics
/// When `rho` is outside [0, 1) or `emission` is negative.
pub fn furnace_sphere(rho: f64, emission: f64) -> Scene {
    let sphere = Sphere::try_new(DVec3::ZERO, 1.0, Facing::Inward).expect("unit sphere");
    let mut s = Scene::try_new(
        "Furnace sphere",
        None,
        vec![material("furnace", rho, emission)],
        vec![Object { name: "dome".into(), material: 0, shape: Shape::Sphere(sphere) }],
    )
    .expect("furnace scene is valid");
    s.mesh = Some(MeshParams::try_new(0.4, 0.4).expect("sizes > 0"));
    s
}

/// A closed unit cube, each face its own object, the floor emitting E = 1, every face with
/// reflectance `rho`; meshed with one patch and one element per face. With ρ = 0.5 the exact
/// discrete solution is floor 1.0909, every other face 0.1818.
///
/// # Panics
/// When `rho` is outside [0, 1).
pub fn unit_cube_floor_light(rho: f64) -> Scene {
    let faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Inward, 0.0).expect("unit box");
    let names = ["floor", "ceiling", "wall_-z", "wall_+z", "wall_-x", "wall_+x"];
    let objects = faces
        .into_iter()
        .zip(names)
        .enumerate()
        .map(|(i, (f, n))| Object {
            name: n.into(),
            material: usize::from(i != 0),
            shape: Shape::Polygons(vec![f]),
        })
        .collect();
    let mut s = Scene::try_new(
        "Unit cube",
        None,
        vec![material("light", rho, 1.0), material("wall", rho, 0.0)],
        objects,
    )
    .expect("cube scene is valid");
    s.mesh = Some(MeshParams::try_new(1.0, 1.0).expect("sizes > 0"));
    s
}

/// Two directly opposed parallel squares of side `size` at distance `distance` (Howell C-11):
/// the lower one (`emitter`, at z = 0, facing +z) emits E = `emission` and reflects nothing,
/// the upper one (`receiver`, facing −z) has reflectance `rho`. Open scene: light escapes.
/// To first order the receiver's mean radiosity is ρ·E·F₁₂.
///
/// # Panics
/// When `rho` is outside [0, 1) or sizes are not positive.
pub fn two_plates(size: f64, distance: f64, rho: f64, emission: f64) -> Scene {
    let sq = |z: f64| {
        [
            DVec3::new(0.0, 0.0, z),
            DVec3::new(size, 0.0, z),
            DVec3::new(size, size, z),
            DVec3::new(0.0, size, z),
        ]
    };
    let lower = Polygon::try_new(sq(0.0).to_vec()).expect("square");
    let mut upper = sq(distance).to_vec();
    upper.reverse();
    let upper = Polygon::try_new(upper).expect("square");
    let mut s = Scene::try_new(
        "Two plates",
        None,
        vec![material("light", 0.0, emission), material("grey", rho, 0.0)],
        vec![
            Object { name: "emitter".into(), material: 0, shape: Shape::Polygons(vec![lower]) },
            Object { name: "receiver".into(), material: 1, shape: Shape::Polygons(vec![upper]) },
        ],
    )
    .expect("plates scene is valid");
    s.mesh = Some(MeshParams::try_new(size / 4.0, size / 16.0).expect("sizes > 0"));
    s
}
