//! Canonical test scenes with closed-form answers, shared by tests, benches and examples; the
//! built-in scene names load the same scenes from `scenes/` (a test checks that they agree).
//! See `shared/references/closed_forms.md` for the closed forms.
//!
//! Kept apart from the scene vocabulary (`radiosity_core`), which every crate builds on, so
//! that a change to a test scene rebuilds only what uses it.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

use glam::DVec3;

use radiosity_core::{
    Camera, Facing, Material, MeshParams, Object, Polygon, PolygonMesh, Rgb, Scene, Shape, Sides,
    SolverSettings, Sphere, box_faces,
};

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
        vec![Object { name: "box".into(), material: 0, shape: Shape::Polygons(faces), sides: Sides::One }],
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
        vec![Object { name: "dome".into(), material: 0, shape: Shape::Sphere(sphere), sides: Sides::One }],
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
            sides: Sides::One,
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
            Object {
                name: "emitter".into(),
                material: 0,
                shape: Shape::Polygons(vec![lower]),
                sides: Sides::One,
            },
            Object {
                name: "receiver".into(),
                material: 1,
                shape: Shape::Polygons(vec![upper]),
                sides: Sides::One,
            },
        ],
    )
    .expect("plates scene is valid");
    s.mesh = Some(MeshParams::try_new(size / 4.0, size / 16.0).expect("sizes > 0"));
    s
}

/// A two-sided unit plate (reflectance `rho`, normal −z, at z = 1) between two unit lamps
/// one apart on each side, both black: `below` at z = 0 facing +z with emission `e_below`,
/// `above` at z = 2 facing −z with `e_above`. The plate hides each lamp from the other and
/// its faces do not see each other, so each face gets its own lamp's light only, reflected
/// once: B_front = ρ·E_below·F, B_back = ρ·E_above·F with F = 0.199825 (Howell C-11).
///
/// # Panics
/// When `rho` is outside [0, 1) or an emission is negative.
pub fn two_sided_plate(rho: f64, e_below: f64, e_above: f64) -> Scene {
    let square = |z: f64, up: bool| {
        let mut v = vec![
            DVec3::new(0.0, 0.0, z),
            DVec3::new(1.0, 0.0, z),
            DVec3::new(1.0, 1.0, z),
            DVec3::new(0.0, 1.0, z),
        ];
        if !up {
            v.reverse();
        }
        Shape::Polygons(vec![Polygon::try_new(v).expect("square")])
    };
    let mut s = Scene::try_new(
        "Two-sided plate",
        None,
        vec![material("below", 0.0, e_below), material("above", 0.0, e_above), material("grey", rho, 0.0)],
        vec![
            Object::new("below", 0, square(0.0, true)),
            Object { sides: Sides::Two { emits_back: false }, ..Object::new("plate", 2, square(1.0, false)) },
            Object::new("above", 1, square(2.0, false)),
        ],
    )
    .expect("plate scene is valid");
    s.mesh = Some(MeshParams::try_new(0.25, 1.0 / 16.0).expect("sizes > 0"));
    s
}

/// A UV sphere as a model mesh, outward facing: `segments` facets around (≥ 3) and
/// `segments / 2` rings (≥ 2), triangles at the poles and quads between; one surface per
/// facet once meshed, as a tessellated model from a file would be.
///
/// # Panics
/// When `segments` < 4 or `radius` is not > 0.
pub fn uv_sphere_mesh(center: DVec3, radius: f64, segments: usize) -> PolygonMesh {
    assert!(segments >= 4 && radius > 0.0, "a sphere of 4+ segments and radius > 0");
    let rings = segments / 2;
    let point = |theta: f64, phi: f64| {
        center + DVec3::new(theta.sin() * phi.cos(), -theta.cos(), theta.sin() * phi.sin()) * radius
    };
    let mut positions = vec![center - DVec3::Y * radius];
    for r in 1..rings {
        let theta = std::f64::consts::PI * r as f64 / rings as f64;
        for k in 0..segments {
            positions.push(point(theta, 2.0 * std::f64::consts::PI * k as f64 / segments as f64));
        }
    }
    positions.push(center + DVec3::Y * radius);
    let top = (positions.len() - 1) as u32;
    let at = |r: usize, k: usize| (1 + (r - 1) * segments + k % segments) as u32;
    let mut faces = Vec::new();
    for k in 0..segments {
        // Counter-clockwise seen from outside.
        faces.push(vec![0, at(1, k), at(1, k + 1)]);
        faces.push(vec![top, at(rings - 1, k + 1), at(rings - 1, k)]);
        for r in 1..rings - 1 {
            faces.push(vec![at(r, k), at(r + 1, k), at(r + 1, k + 1), at(r, k + 1)]);
        }
    }
    PolygonMesh::try_new(positions, faces).expect("a UV sphere's facets are planar and convex")
}

fn polygon(points: &[[f64; 3]]) -> Polygon {
    Polygon::try_new(points.iter().map(|p| DVec3::from_array(*p)).collect())
        .expect("Cornell polygon is valid")
}

/// The Cornell box exactly as `scenes/cornell.toml` (and the built-in scene `cornell`) gives
/// it: the Cornell University Program of Computer Graphics' measured geometry in mm, its
/// reflectances reduced to linear sRGB (Rec. 709, D65), the light in a hole cut in the
/// ceiling, emitting downward only; open towards the camera. Meshed with patches of 140 mm
/// and elements of 35 mm; solved to unshot 1e-3. A test in the scene loader checks that the
/// file loads equal to this.
pub fn cornell_box() -> Scene {
    let m = |name: &str, rho: [f64; 3], e: [f64; 3]| {
        Material::try_new(name, Rgb::from_array(rho), Rgb::from_array(e)).expect("Cornell material in range")
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
        shape: Shape::Polygons(faces.iter().map(|f| polygon(f)).collect()),
        sides: Sides::One,
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
            .expect("Cornell camera");
    let mut scene =
        Scene::try_new("Cornell box", Some(camera), materials, objects).expect("Cornell scene is valid");
    scene.mesh = Some(MeshParams::try_new(140.0, 35.0).expect("sizes > 0"));
    scene.solver = SolverSettings { unshot_threshold: Some(0.001), ..SolverSettings::default() };
    scene
}
