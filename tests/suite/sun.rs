//! The `[sun]`: parallel light from a direction at infinity that shoots first, exactly, by
//! shadow rays towards it, against closed forms, in the solver and in `verify`'s path tracer.

use radiosity_core::{LUMENS_PER_WATT, Scene};
use radiosity_solver::{Problem, Solver, SolverParams};

use crate::photometry::load;

/// The roof of [`skylight`] with a 1 × 1 m opening over the floor's middle.
const OPENING: &str = "[[0, 3, 0], [4, 3, 0], [4, 3, 1.5], [0, 3, 1.5]],
  [[0, 3, 2.5], [4, 3, 2.5], [4, 3, 4], [0, 3, 4]],
  [[0, 3, 1.5], [1.5, 3, 1.5], [1.5, 3, 2.5], [0, 3, 2.5]],
  [[2.5, 3, 1.5], [4, 3, 1.5], [4, 3, 2.5], [2.5, 3, 2.5]]";

/// A grey floor (ρ = 0.5) of 4 × 4 m under a black roof 3 m up made of the faces `roof` (none
/// when empty), lit by a sun along `towards` of `lux` on a plane facing it; 0.25 m elements.
fn skylight(towards: [f64; 3], lux: f64, roof: &str) -> (tempfile::TempDir, Scene) {
    let roof = if roof.is_empty() {
        String::new()
    } else {
        format!(
            "[[object]]\nname = \"roof\"\ntype = \"polygons\"\nmaterial = \"black\"\nfaces = [\n  {roof},\n]\n"
        )
    };
    let text = format!(
        r#"
units = "m"
[sun]
direction = {towards:?}
illuminance = {lux}
[[material]]
name = "grey"
reflectance = [0.5, 0.5, 0.5]
[[material]]
name = "black"
reflectance = [0, 0, 0]
[[object]]
name = "floor"
type = "polygon"
material = "grey"
vertices = [[0, 0, 0], [0, 0, 4], [4, 0, 4], [4, 0, 0]]
{roof}
[mesh]
patch_size = 0.5
element_size = 0.25
"#
    );
    load(&text, &[])
}

/// `scene` solved with the default parameters.
fn solved(scene: &Scene) -> Solver {
    let mut solver =
        Problem::new(scene, &scene.mesh_params()).unwrap().solver(SolverParams::default()).unwrap();
    solver.solve();
    solver
}

/// The floor's power in a solve, Σ B A (green channel), W.
fn floor_power(solver: &Solver) -> f64 {
    let mesh = solver.mesh().clone();
    let radiosity = solver.solution().element_radiosity;
    (0..mesh.elements.len())
        .filter(|&e| mesh.object_names[mesh.element_object(e)] == "floor")
        .map(|e| radiosity[e].g * mesh.elements[e].area)
        .sum()
}

/// An open floor under a sun 60° from the zenith: every element gets E cos 60° (lux / 683 W
/// per m² of Y on a plane facing the sun), so B = ρ E cos 60° on each, to round-off: nothing
/// else lights it and a plane does not see itself.
#[test]
fn the_sun_lights_an_open_floor_by_the_cosine_law() {
    let t = 60f64.to_radians();
    let (_dir, scene) = skylight([t.sin(), t.cos(), 0.0], 100_000.0, "");
    let sun = scene.lighting.sun.expect("a sun");
    assert!((sun.irradiance.luminance() * LUMENS_PER_WATT / 100_000.0 - 1.0).abs() < 1e-12);
    let solver = solved(&scene);
    let expected = 0.5 * sun.irradiance.g * t.cos();
    for b in solver.solution().element_radiosity {
        assert!((b.g / expected - 1.0).abs() < 1e-9, "{} against {expected}", b.g);
    }
}

/// Through a 1 × 1 m opening in a black roof, a sun straight overhead lights 1 m² of the
/// floor: the floor's power Σ B A is ρ E · 1 m². The opening's edges fall on element edges
/// (0.25 m elements, opening at 1.5–2.5 m), so every element is lit whole or not at all:
/// asserted to 1e-6. The path tracer's floor (the same light by next-event estimation) within
/// 3 standard errors of it.
#[test]
fn the_sun_through_a_roof_opening_lights_its_area() {
    use radiosity_reference::{EstimateParams, PathBudget, Reference};
    let (_dir, scene) = skylight([0.0, 1.0, 0.0], 68_300.0, OPENING);
    let e = scene.lighting.sun.unwrap().irradiance.g;
    assert!((e / 100.0 - 1.0).abs() < 1e-12, "{e} W/m²");
    let expected = 0.5 * e * 1.0;
    let power = floor_power(&solved(&scene));
    assert!((power / expected - 1.0).abs() < 1e-6, "floor power {power} W against {expected}");
    let reference = Reference::new(&scene);
    let params = EstimateParams { budget: PathBudget::Fixed { paths: 20_000 }, ..EstimateParams::default() };
    let objects = reference.estimate_objects(&params, &|_| {}).objects;
    let floor = objects.iter().find(|o| o.name == "floor").unwrap();
    let (mean, se) = (floor.estimate.luminance, floor.estimate.luminance_stderr);
    let want = expected / 16.0;
    assert!((mean - want).abs() <= 3.0 * se, "path tracer {mean} ± {se} against {want}");
}

/// Through a slit 0.1 m wide in a black roof, across two columns of 0.25 m floor elements
/// (x from 1.95 to 2.05 m), a sun straight overhead lights 0.4 m² of the floor: its power is
/// ρ E · 0.4 m². Each of those elements is a fifth lit, along its side: points kept a third of
/// an element away from its sides (the fan centroids the luminaires use) miss such a strip or
/// take a quarter of the element for it; the sun's jittered points over the whole element
/// measured −0.21 %. Asserted: within 3 %, about three times the spread of 16 samples per
/// element over 32 elements.
#[test]
fn the_sun_through_a_slit_lights_a_strip_narrower_than_an_element() {
    let slit = "[[0, 3, 0], [1.95, 3, 0], [1.95, 3, 4], [0, 3, 4]],
  [[2.05, 3, 0], [4, 3, 0], [4, 3, 4], [2.05, 3, 4]]";
    let (_dir, scene) = skylight([0.0, 1.0, 0.0], 68_300.0, slit);
    let power = floor_power(&solved(&scene));
    let expected = 0.5 * 100.0 * 0.4;
    eprintln!("slit: floor power {power} W against {expected} ({:+.2} %)", (power / expected - 1.0) * 100.0);
    assert!((power / expected - 1.0).abs() < 0.03, "floor power {power} W against {expected}");
}

/// A `[sun]` needs a direction and exactly one of illuminance or irradiance: each mistake is
/// one line naming the key.
#[test]
fn a_sun_missing_its_direction_or_light_is_refused_by_key() {
    let cases = [
        ("illuminance = 1000", "sun.direction"),
        ("direction = [0, 1, 0]", "illuminance"),
        ("direction = [0, 0, 0]\nilluminance = 1000", "sun.direction"),
        ("direction = [0, 1, 0]\nilluminance = 1000\nirradiance = [1, 1, 1]", "sun.illuminance"),
        ("direction = [0, 1, 0]\nilluminance = -5", "sun.illuminance"),
        ("direction = [0, 1, 0]\nirradiance = [1, 1, 1]\ncolour = [1, 0, 0]", "sun.colour"),
    ];
    for (sun, key) in cases {
        let message = match load_sun("", sun) {
            Ok(_) => panic!("[sun] {sun:?} was taken"),
            Err(e) => e,
        };
        assert!(message.contains(key) && !message.contains('\n'), "[sun] {sun:?}: {message}");
    }
}

/// A sun overhead over a floor under a lid lights nothing: the solve refuses to start with
/// one line saying why, not a black picture.
#[test]
fn a_sun_that_lights_nothing_is_refused_with_a_reason() {
    // A lid over the whole floor, facing down: closed as far as a sun overhead goes.
    let lid = "[[0, 3, 0], [4, 3, 0], [4, 3, 4], [0, 3, 4]]";
    let (_dir, scene) = skylight([0.0, 1.0, 0.0], 100_000.0, lid);
    let err = Problem::new(&scene, &scene.mesh_params()).unwrap().solver(SolverParams::default()).err();
    assert_eq!(err, Some(radiosity_solver::SolverError::DarkDaylight));
    let message = radiosity_solver::SolverError::DarkDaylight.to_string();
    assert!(message.contains("sun") && !message.contains('\n'), "{message}");
}

/// Writes a one-floor scene with `[sun]` table `sun` (and `extra` before it) and loads it.
fn load_sun(extra: &str, sun: &str) -> Result<Scene, String> {
    load_with_table(extra, "sun", sun)
}

/// Writes a one-floor scene with table `[name]` holding `body` (and `extra` before it) and
/// loads it; the error's text when it does not load.
pub(crate) fn load_with_table(extra: &str, name: &str, body: &str) -> Result<Scene, String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    let text = format!(
        "{extra}\n[{name}]\n{body}\n[[material]]\nname = \"g\"\nreflectance = [0.5, 0.5, 0.5]\n[[object]]\nname = \"f\"\n\
         type = \"polygon\"\nmaterial = \"g\"\nvertices = [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]\n"
    );
    std::fs::write(&path, text).unwrap();
    radiosity_io::load_scene(&path).map(|l| l.scene).map_err(|e| e.to_string())
}

/// A sun placed by latitude, longitude and time: at Greenwich's solar noon on the 2026 June
/// solstice it stands 90° − 51.48° + 23.44° = 61.96° high, due south, which in a y-up file
/// whose north is −z (the default) is +z; in a z-up file (north +y by default) the same
/// sun, turned to y-up, stands as high. Within 0.05° of elevation and 0.5° of azimuth.
#[test]
fn a_sun_placed_by_place_and_time_stands_where_the_almanac_puts_it() {
    let sun = "latitude = 51.4779\nlongitude = 0\ntime = 2026-06-21T12:01:50Z\nilluminance = 100000";
    let elevation = (90.0f64 - 51.4779 + 23.437).to_radians();
    for extra in ["", "up = \"z\""] {
        let towards = load_sun(extra, sun).unwrap().lighting.sun.expect("a sun").towards;
        assert!((towards.y.asin() - elevation).abs() < 0.05f64.to_radians(), "{extra:?}: {towards}");
        assert!(towards.x.abs() < 0.01, "due south: {towards}");
    }
    let south_y_up = load_sun("", sun).unwrap().lighting.sun.unwrap().towards;
    assert!(south_y_up.z > 0.4, "north is −z, so south is +z: {south_y_up}");
    // North given as +x: south is −x.
    let turned = load_sun("", &format!("{sun}\nnorth = [1, 0, 0]")).unwrap().lighting.sun.unwrap().towards;
    assert!(turned.x < -0.4 && turned.z.abs() < 0.01, "{turned}");
}

/// A sun placed by time refuses, in one line naming the key: a time without its offset from
/// UTC, a time when the sun is below the horizon, a latitude out of range or missing, and a
/// direction given as well.
#[test]
fn a_sun_placed_by_time_refuses_what_cannot_place_it() {
    let cases = [
        ("latitude = 48.85\nlongitude = 2.35\ntime = 2026-06-21T12:00:00\nilluminance = 1000", "sun.time"),
        (
            "latitude = 48.85\nlongitude = 2.35\ntime = 2026-06-21T23:00:00+02:00\nilluminance = 1000",
            "below the horizon",
        ),
        ("latitude = 98\nlongitude = 2.35\ntime = 2026-06-21T12:00:00Z\nilluminance = 1000", "sun.latitude"),
        ("longitude = 2.35\ntime = 2026-06-21T12:00:00Z\nilluminance = 1000", "sun.latitude"),
        (
            "direction = [0, 1, 0]\nlatitude = 48.85\nlongitude = 2.35\ntime = 2026-06-21T12:00:00Z\nilluminance = 1000",
            "sun.direction",
        ),
        (
            "latitude = 48.85\nlongitude = 2.35\ntime = 2026-06-21T12:00:00Z\nnorth = [0, 1, 0]\nilluminance = 1000",
            "sun.north",
        ),
    ];
    for (sun, key) in cases {
        let message = match load_sun("", sun) {
            Ok(_) => panic!("[sun] {sun:?} was taken"),
            Err(e) => e,
        };
        assert!(message.contains(key) && !message.contains('\n'), "[sun] {sun:?}: {message}");
    }
}
