//! The built-in scenes: each parses, the canonical ones equal the core's functions, and the
//! seed room is the scene the source document describes.

use std::path::Path;

use radiosity_core::glam::DVec3;
use radiosity_core::{Facing, Shape};
use radiosity_io::{BUILTIN_SCENES, LoadError, builtin_scene, load_scene, resolve_scene};
use radiosity_mesh::Mesh;

#[test]
fn every_builtin_parses() {
    for name in BUILTIN_SCENES {
        let scene = builtin_scene(name).unwrap_or_else(|| panic!("{name} is listed but not built in"));
        assert!(scene.mesh.is_some(), "{name} sets its [mesh]");
        assert!(scene.emitted_power().max_channel() > 0.0, "{name} has a light");
    }
    assert!(builtin_scene("no-such-scene").is_none());
}

#[test]
fn builtins_equal_their_files_on_disk() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    for name in BUILTIN_SCENES {
        let path = dir.join(format!("{name}.toml"));
        assert_eq!(load_scene(&path).unwrap().scene, builtin_scene(name).unwrap(), "{name}");
        let resolved = resolve_scene(path.to_str().unwrap()).unwrap();
        assert_eq!(resolved.scene, builtin_scene(name).unwrap(), "{name}");
        assert!(resolved.warnings.is_empty(), "{name}: {:?}", resolved.warnings);
    }
}

#[test]
fn furnace_equals_the_canonical_scene() {
    assert_eq!(builtin_scene("furnace").unwrap(), radiosity_scenes::furnace_box(0.5, 1.0));
}

#[test]
fn two_plates_equals_the_canonical_scene() {
    assert_eq!(builtin_scene("two-plates").unwrap(), radiosity_scenes::two_plates(1.0, 1.0, 0.5, 1.0));
}

/// `scenes/cornell.toml` and the library's Cornell box are one scene: tests and benches that
/// build the box in code solve what the command line solves.
#[test]
fn cornell_equals_the_canonical_scene() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    assert_eq!(load_scene(&dir.join("cornell.toml")).unwrap().scene, radiosity_scenes::cornell_box());
    assert_eq!(builtin_scene("cornell").unwrap(), radiosity_scenes::cornell_box());
}

#[test]
fn cornell_is_the_measured_box() {
    let s = resolve_scene("cornell").unwrap().scene;
    assert_eq!(s.name, "Cornell box");
    assert_eq!(s.materials.len(), 4);
    assert_eq!(s.objects.len(), 16);
    let light = s.objects.iter().find(|o| o.name == "light").unwrap();
    assert_eq!(s.materials[light.material].emission.to_array(), [65.3094, 34.0744, 8.7042]);
    assert_eq!(s.camera.unwrap().fov_y_deg, 39.3076);
    assert_eq!(s.solver.unshot_threshold, Some(0.001));
}

#[test]
fn seed_room_is_the_documents_scene() {
    let s = builtin_scene("seed-room").unwrap();
    let (lo, hi) = s.bounds();
    assert_eq!((lo, hi), (DVec3::ZERO, DVec3::new(5.0, 3.0, 4.0)), "a 5 x 3 x 4 m room");
    let centre = (lo + hi) * 0.5;

    // Walls, floor and ceiling face the inside; one of them is coloured.
    let walls = ["floor", "ceiling", "back_wall", "front_wall", "left_wall", "right_wall"];
    let mut coloured = 0;
    for name in walls {
        let o = s.objects.iter().find(|o| o.name == name).unwrap_or_else(|| panic!("{name}"));
        let Shape::Polygons(ps) = &o.shape else { panic!("{name} is a polygon") };
        assert!((centre - ps[0].vertices()[0]).dot(ps[0].normal()) > 0.0, "{name} faces the inside");
        let rho = s.materials[o.material].reflectance;
        coloured += usize::from(rho.r != rho.g || rho.g != rho.b);
    }
    assert!(coloured >= 1, "at least one coloured wall or floor");

    // A square ceiling light just below the ceiling, facing down.
    let light = s.objects.iter().find(|o| s.materials[o.material].is_emitter()).unwrap();
    let Shape::Polygons(ps) = &light.shape else { panic!("the light is a polygon") };
    assert_eq!(ps.len(), 1);
    assert!((ps[0].normal() - DVec3::NEG_Y).length() < 1e-12, "the light faces down");
    assert!(ps[0].vertices().iter().all(|v| v.y > 2.9 && v.y < 3.0), "just below the ceiling");

    // One rotated outward block and one outward sphere.
    let block = s.objects.iter().find(|o| o.name == "block").unwrap();
    let Shape::Polygons(faces) = &block.shape else { panic!("the block is a box") };
    assert_eq!(faces.len(), 6);
    let centre_block = faces.iter().flat_map(|f| f.vertices()).sum::<DVec3>() / 24.0;
    assert!(faces.iter().all(|f| (f.vertices()[0] - centre_block).dot(f.normal()) > 0.0), "outward");
    assert!(faces.iter().any(|f| f.normal().x.abs() > 1e-3 && f.normal().z.abs() > 1e-3), "rotated");
    let ball = s.objects.iter().find(|o| matches!(o.shape, Shape::Sphere(_))).unwrap();
    let Shape::Sphere(sphere) = ball.shape else { unreachable!() };
    assert_eq!(sphere.facing, Facing::Outward);

    // The camera stands inside the room.
    let cam = s.camera.unwrap();
    assert!(cam.position.cmpgt(lo).all() && cam.position.cmplt(hi).all());

    // 10 to 100 patches per wall: the document's discretisation, its uniform grid. (The cut
    // along the block's shadow outlines, which the document does not have, adds pieces of a
    // few small patches each there, and is left out.)
    let mesh = Mesh::build(&s, &s.mesh_params().with_shadow_outlines(false)).unwrap();
    for surface in &mesh.surfaces {
        let name = &mesh.object_names[surface.object as usize];
        if walls.contains(&name.as_str()) {
            let patches = surface.patches.len();
            assert!((10..=100).contains(&patches), "{name} has {patches} patches");
        }
    }
}

#[test]
fn unknown_names_list_the_builtins() {
    let e = resolve_scene("cornel").unwrap_err();
    assert!(matches!(e, LoadError::UnknownScene { .. }));
    assert_eq!(e.exit_code(), 2);
    assert_eq!(
        e.to_string(),
        "'cornel' is neither a scene file nor a built-in scene (built-ins: cornell, furnace, seed-room, two-plates)"
    );
}

#[test]
fn a_toml_argument_is_always_a_path() {
    let e = resolve_scene("cornell.toml").unwrap_err();
    assert!(matches!(e, LoadError::Unreadable { .. }), "{e}");
}
