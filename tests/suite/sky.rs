//! The `[sky]`: diffuse light from a dome at infinity that shoots first, by shadow rays towards
//! it, against closed forms, in the solver, in `verify`'s path tracer and in the grids'
//! daylight factors.

use std::f64::consts::PI;
use std::process::Command;

use radiosity_core::{LUMENS_PER_WATT, Scene};
use radiosity_solver::{Problem, Solver, SolverParams};

use crate::photometry::load;

/// A grey (ρ = 0.5) 1 × 1 m floor at the foot of a light well: four black walls 1 m high, open
/// at the top, under a `model` sky of `amount` (`illuminance = …` or `irradiance = …`), with
/// `rays` per element and 5 cm elements; `extra` is more scene text.
fn well(model: &str, amount: &str, rays: u32, walls: bool, extra: &str) -> (tempfile::TempDir, Scene) {
    let walls = if walls {
        r#"[[object]]
name = "walls"
type = "polygons"
material = "black"
faces = [
  [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
  [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]],
  [[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]],
  [[1, 0, 0], [1, 0, 1], [1, 1, 1], [1, 1, 0]],
]"#
    } else {
        ""
    };
    let text = format!(
        r#"
units = "m"
[sky]
model = "{model}"
{amount}
rays = {rays}
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
vertices = [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]
{walls}
{extra}
[mesh]
patch_size = 0.1
element_size = 0.05
"#
    );
    load(&text, &[])
}

/// `scene` solved with the default parameters.
pub(crate) fn solved(scene: &Scene) -> Solver {
    let mut solver =
        Problem::new(scene, &scene.mesh_params()).unwrap().solver(SolverParams::default()).unwrap();
    solver.solve();
    solver
}

/// The area-weighted mean radiosity (green) of object `name` in a solve.
pub(crate) fn mean_radiosity(solver: &Solver, name: &str) -> f64 {
    let mesh = solver.mesh().clone();
    let radiosity = solver.solution().element_radiosity;
    let (mut power, mut area) = (0.0, 0.0);
    for e in (0..mesh.elements.len()).filter(|&e| mesh.object_names[mesh.element_object(e)] == name) {
        power += radiosity[e].g * mesh.elements[e].area;
        area += mesh.elements[e].area;
    }
    power / area
}

/// View factor between two directly opposed parallel rectangles a × b at distance c
/// (Howell's catalogue, C-11).
pub(crate) fn opposed_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    2.0 / (PI * x * y)
        * ((((1.0 + x2) * (1.0 + y2)) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

/// An open floor under a uniform sky receives exactly its horizontal illuminance (every ray
/// leaves the scene and brings the same): B = ρ E_h on every element, to round-off. Under an
/// overcast sky of 10 000 lx its rays bring more near the zenith than near the horizon: 64
/// stratified rays per element, the floor's mean within 0.2 % (measured −0.01 %) and every
/// element within 2 %.
#[test]
fn an_open_floor_receives_the_sky_s_horizontal_illuminance() {
    let (_dir, scene) = well("uniform", "irradiance = [1, 1, 1]", 64, false, "");
    for b in solved(&scene).solution().element_radiosity {
        assert!((b.g / 0.5 - 1.0).abs() < 1e-9, "{} against 0.5", b.g);
    }
    let (_dir, scene) = well("cie-overcast", "illuminance = 10000", 64, false, "");
    let sky = scene.lighting.sky.clone().expect("a sky");
    let e = sky.horizontal_irradiance();
    assert!((e.luminance() * LUMENS_PER_WATT / 10_000.0 - 1.0).abs() < 1e-12);
    let solver = solved(&scene);
    let expected = 0.5 * e.g;
    for b in solver.solution().element_radiosity {
        assert!((b.g / expected - 1.0).abs() < 0.02, "{} against {expected}", b.g);
    }
    let b = mean_radiosity(&solver, "floor");
    eprintln!("overcast: floor {b:.5} against {expected:.5} ({:+.3} %)", (b / expected - 1.0) * 100.0);
    assert!((b / expected - 1.0).abs() < 0.002, "floor {b} against {expected}");
}

/// A vertical wall alone under the overcast sky receives (π/2 + 4/3) / (7π/3) = 0.3962 of the
/// horizontal illuminance (∫ L cos θ dω over the half of its hemisphere above the horizon,
/// L ∝ 1 + 2 cos θ_z), and under a uniform sky one half. 64 stratified rays per element over
/// 400 elements: the wall's mean within 0.5 % (measured +0.04 % overcast, exact uniform).
#[test]
fn a_wall_under_the_sky_receives_its_share_of_the_dome() {
    let wall = r#"[[object]]
name = "wall"
type = "polygon"
material = "grey"
vertices = [[10, 0, 0], [10, 1, 0], [10, 1, 1], [10, 0, 1]]"#;
    for (model, share) in [("cie-overcast", (PI / 2.0 + 4.0 / 3.0) / (7.0 * PI / 3.0)), ("uniform", 0.5)] {
        let (_dir, scene) = well(model, "irradiance = [1, 1, 1]", 64, false, wall);
        // The wall faces away from the floor behind it: it sees the sky alone.
        let b = mean_radiosity(&solved(&scene), "wall");
        let expected = 0.5 * share;
        eprintln!("{model}: wall {b:.5} against {expected:.5} ({:+.3} %)", (b / expected - 1.0) * 100.0);
        assert!((b / expected - 1.0).abs() < 0.005, "{model}: {b} against {expected}");
    }
}

/// Down a light well (a 1 m cube, black walls, open top) a uniform sky lights the floor by
/// its view factor to the opening: E = π L F = E_h F, F = 0.19982 (Howell C-11). 256 rays
/// per element over 400 elements, each seeing the sky in a fifth of its directions: the
/// floor's mean within 1.5 % (about five of its standard errors; measured −0.28 %). The path
/// tracer, which finds the sky only where its bounces leave the scene, within 3 of its own.
#[test]
fn the_sky_down_a_light_well_lights_the_floor_by_its_view_factor() {
    use radiosity_reference::{EstimateParams, PathBudget, Reference};
    let (_dir, scene) = well("uniform", "irradiance = [1, 1, 1]", 256, true, "");
    let f = opposed_rectangles(1.0, 1.0, 1.0);
    assert!((f - 0.19982).abs() < 1e-4, "C-11 gives {f}");
    let expected = 0.5 * f;
    let b = mean_radiosity(&solved(&scene), "floor");
    eprintln!("well: floor {b:.5} against {expected:.5} ({:+.2} %)", (b / expected - 1.0) * 100.0);
    assert!((b / expected - 1.0).abs() < 0.015, "floor {b} against {expected}");
    let reference = Reference::new(&scene);
    let params = EstimateParams { budget: PathBudget::Fixed { paths: 40_000 }, ..EstimateParams::default() };
    let objects = reference.estimate_objects(&params, &|_| {}).objects;
    let floor = objects.iter().find(|o| o.name == "floor").unwrap();
    let (mean, se) = (floor.estimate.luminance, floor.estimate.luminance_stderr);
    eprintln!("well: path tracer {mean:.5} ± {se:.5}");
    assert!((mean - expected).abs() <= 3.0 * se, "path tracer {mean} ± {se} against {expected}");
}

/// Under a CIE clear sky with its sun 40° up (`model = "cie-clear"` takes the `[sun]`'s
/// position), an open floor receives the sky's horizontal illuminance plus the sun's
/// E sin 40°: 64 stratified rays per element over a dome brightest by the sun, the floor's
/// mean within 0.5 % (measured below 0.1 %). A wall facing the sun's side gets more of the
/// dome than one facing away, and the path tracer agrees with the solve on both walls within
/// 3 of its standard errors plus 1 % (the walls' 5 cm elements against the sun's sharp
/// grazing light are exact; the dome's rays leave 0.5 %).
#[test]
fn a_clear_sky_is_brightest_around_its_sun() {
    use radiosity_reference::{EstimateParams, PathBudget, Reference};
    let el = 40f64.to_radians();
    let walls = format!(
        r#"[sun]
direction = [{}, {}, 0]
irradiance = [2, 2, 2]
[[object]]
name = "sunward"
type = "polygon"
material = "grey"
vertices = [[10, 0, 0], [10, 1, 0], [10, 1, 1], [10, 0, 1]]
[[object]]
name = "shaded"
type = "polygon"
material = "grey"
vertices = [[-10, 0, 0], [-10, 0, 1], [-10, 1, 1], [-10, 1, 0]]"#,
        el.cos(),
        el.sin()
    );
    let (_dir, scene) = well("cie-clear", "irradiance = [1, 1, 1]", 64, false, &walls);
    let sky = scene.lighting.sky.clone().expect("a sky");
    assert!(matches!(sky.model, radiosity_core::SkyModel::CieClear { .. }));
    let solver = solved(&scene);
    let expected = 0.5 * (1.0 + 2.0 * el.sin());
    let floor = mean_radiosity(&solver, "floor");
    eprintln!("clear: floor {floor:.5} against {expected:.5} ({:+.3} %)", (floor / expected - 1.0) * 100.0);
    assert!((floor / expected - 1.0).abs() < 0.005, "floor {floor} against {expected}");
    let (sunward, shaded) = (mean_radiosity(&solver, "sunward"), mean_radiosity(&solver, "shaded"));
    // Less the sun's direct E cos 40° on the sunward wall: what the dome gives each.
    let dome = sunward - 0.5 * 2.0 * el.cos();
    assert!(dome > 1.5 * shaded, "sunward dome {dome}, shaded {shaded}");
    let reference = Reference::new(&scene);
    let params = EstimateParams { budget: PathBudget::Fixed { paths: 20_000 }, ..EstimateParams::default() };
    let objects = reference.estimate_objects(&params, &|_| {}).objects;
    for (name, solve) in [("sunward", sunward), ("shaded", shaded)] {
        let o = objects.iter().find(|o| o.name == name).unwrap();
        let (mean, se) = (o.estimate.luminance, o.estimate.luminance_stderr);
        eprintln!("clear: {name} solve {solve:.5}, path tracer {mean:.5} ± {se:.5}");
        assert!(
            (mean - solve).abs() <= 3.0 * se + 0.01 * solve,
            "{name}: path tracer {mean} ± {se}, solve {solve}"
        );
    }
}

/// A calculation grid on the well's floor under an overcast sky of 10 000 lx: `grid` prints
/// the mean daylight factor, Em over the open sky's 10 000 lx, and `solve --json` carries it.
/// The overcast sky is brighter towards the zenith than the uniform one of the same
/// horizontal illuminance, so the well's floor, which sees only the sky's middle, has a
/// daylight factor above its view factor (20.0 %): asserted between 20 and 35 %.
#[test]
fn a_grid_under_the_sky_reports_its_daylight_factor() {
    let grid = r#"[[grid]]
name = "floor"
surface = "floor"
divisions = [4, 4]"#;
    let (dir, _scene) = well("cie-overcast", "illuminance = 10000", 64, true, grid);
    let scene = dir.path().join("scene.toml");
    let json = dir.path().join("report.json");
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["solve", scene.to_str().unwrap(), "-q", "--json", json.to_str().unwrap()])
        .output()
        .expect("run radiosity");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("DF %"), "no daylight factor column:\n{stdout}");
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let sky_lux = report["sky_lux"].as_f64().expect("the sky's illuminance");
    assert!((sky_lux / 10_000.0 - 1.0).abs() < 1e-9, "{sky_lux} lx");
    let df = report["grids"][0]["daylight_factor"].as_f64().expect("a daylight factor");
    assert!((20.0..35.0).contains(&df), "daylight factor {df} %");
}

/// A `[sky]` with a wrong model, ray count or amount is refused with one line naming the key.
#[test]
fn a_sky_with_a_bad_key_is_refused_by_key() {
    let cases = [
        ("model = \"clear\"\nilluminance = 1000", "sky.model"),
        ("model = \"cie-clear\"\nilluminance = 1000", "give a [sun]"),
        ("illuminance = 1000\nrays = 0", "sky.rays"),
        ("illuminance = 1000\nrays = 100000", "sky.rays"),
        ("rays = 16", "illuminance"),
        ("illuminance = 1000\nirradiance = [1, 1, 1]", "sky.illuminance"),
        ("irradiance = [0, 0, 0]", "sky.irradiance"),
        ("illuminance = 1000\nturbidity = 3", "turbidity"),
        ("map = \"missing.hdr\"", "sky.map"),
        ("map = \"sky.png\"", "expected a linear HDR image"),
        ("map = \"sky.exr\"", "Radiance's .hdr format"),
        ("model = \"uniform\"\nmap = \"sky.hdr\"", "sky.model"),
        ("illuminance = 1000\nscale = 2", "sky.scale"),
        ("illuminance = 1000\nrotation = 90", "sky.rotation"),
    ];
    for (sky, key) in cases {
        let message = match crate::sun::load_with_table("", "sky", sky) {
            Ok(_) => panic!("[sky] {sky:?} was taken"),
            Err(e) => e,
        };
        assert!(message.contains(key) && !message.contains('\n'), "[sky] {sky:?}: {message}");
    }
}

/// A sky over a floor under a lid lights nothing: refused with one line, as a dark sun is.
#[test]
fn a_sky_that_lights_nothing_is_refused_with_a_reason() {
    let lid = r#"[[object]]
name = "lid"
type = "polygon"
material = "black"
vertices = [[-1, 1, -1], [2, 1, -1], [2, 1, 2], [-1, 1, 2]]"#;
    let (_dir, scene) = well("uniform", "illuminance = 1000", 16, true, lid);
    let err = Problem::new(&scene, &scene.mesh_params()).unwrap().solver(SolverParams::default()).err();
    assert_eq!(err, Some(radiosity_solver::SolverError::DarkDaylight));
}

/// A picture shows the sky where its view leaves the scene: from above the open floor,
/// looking at the horizon, the top rows see a uniform sky of irradiance 1 at radiance 1/π,
/// and the bottom rows the floor (B = 0.5, radiance 0.5/π).
/// Without the sky the top rows are black.
#[test]
fn a_picture_shows_the_sky_where_the_view_leaves_the_scene() {
    use radiosity_core::glam::DVec3;
    use radiosity_image::{RenderParams, Renderer, Shading};
    let (_dir, scene) = well("uniform", "irradiance = [1, 1, 1]", 16, false, "");
    let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
    let mut solver = problem.solver(SolverParams::default()).unwrap();
    solver.solve();
    let solution = solver.solution();
    let camera =
        radiosity_core::Camera::try_new(DVec3::new(0.5, 0.1, 0.0), DVec3::new(0.5, 0.1, 1.0), DVec3::Y, 60.0)
            .unwrap();
    let params = RenderParams {
        width: 32,
        height: 32,
        samples_per_pixel: 1,
        shading: Shading::Flat,
        ..RenderParams::default()
    };
    let renderer = Renderer::new(problem.mesh().clone());
    let dark = renderer.render(&solution, &camera, &params).unwrap().radiance;
    let lit = renderer.with_sky(scene.lighting.sky).render(&solution, &camera, &params).unwrap().radiance;
    let (sky, floor) = (1.0 / PI, 0.5 / PI);
    assert_eq!(dark.pixel(16, 0).g, 0.0, "no sky: nothing seen above the horizon");
    assert!((lit.pixel(16, 0).g - sky).abs() < 1e-9, "sky pixel {} against {sky}", lit.pixel(16, 0).g);
    assert!(
        (lit.pixel(16, 31).g - floor).abs() < 1e-6,
        "floor pixel {} against {floor}",
        lit.pixel(16, 31).g
    );
}

/// A Radiance `.hdr` file of `w × h` texels (flat RGBE scanlines), each `texel(column, row)`.
fn write_hdr(path: &std::path::Path, w: usize, h: usize, texel: impl Fn(usize, usize) -> [f32; 3]) {
    let mut bytes = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
    for row in 0..h {
        for column in 0..w {
            let c = texel(column, row);
            let v = c[0].max(c[1]).max(c[2]);
            if v < 1e-30 {
                bytes.extend_from_slice(&[0, 0, 0, 0]);
                continue;
            }
            // v = m 2^e with m in [0.5, 1): the mantissas are the channels at 256 / 2^e.
            let e = v.log2().floor() as i32 + 1;
            let scale = 256.0 / 2f32.powi(e);
            bytes.extend(c.map(|x| (x * scale) as u8));
            bytes.push((e + 128) as u8);
        }
    }
    std::fs::write(path, bytes).unwrap();
}

/// An environment map as the sky. A map bright (radiance 1) over its upper half and black
/// below is the uniform sky of irradiance π: an open floor gets B = ρ π on every element
/// (within 0.3 %: the bilinear lookup blurs the horizon over half a texel of 64 rows), and the
/// path tracer agrees within 3 of its standard errors. A map brighter in its middle columns
/// lights a wall facing north (−z, the map's middle) more than one facing south, and turned
/// by `rotation = 180` the other way round.
#[test]
fn an_environment_map_lights_the_scene_as_its_texels_say() {
    use radiosity_reference::{EstimateParams, PathBudget, Reference};
    let dir = tempfile::tempdir().unwrap();
    write_hdr(&dir.path().join("half.hdr"), 128, 64, |_, row| if row < 32 { [1.0; 3] } else { [0.0; 3] });
    write_hdr(&dir.path().join("north.hdr"), 128, 64, |column, row| {
        let bright = row < 32 && (48..80).contains(&column);
        [if bright {
            8.0
        } else if row < 32 {
            1.0
        } else {
            0.0
        }; 3]
    });
    let scene_text = |map: &str, extra: &str| {
        format!(
            r#"units = "m"
[sky]
map = "{map}"
{extra}
[[material]]
name = "grey"
reflectance = [0.5, 0.5, 0.5]
[[object]]
name = "floor"
type = "polygon"
material = "grey"
vertices = [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]
[[object]]
name = "north"
type = "polygon"
material = "grey"
vertices = [[10, 0, 10], [10, 1, 10], [11, 1, 10], [11, 0, 10]]
[[object]]
name = "south"
type = "polygon"
material = "grey"
vertices = [[10, 0, -10], [11, 0, -10], [11, 1, -10], [10, 1, -10]]
[mesh]
patch_size = 0.25
element_size = 0.125
"#
        )
    };
    let load = |text: String| {
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, text).unwrap();
        radiosity_io::load_scene(&path).unwrap_or_else(|e| panic!("{e}")).scene
    };
    let scene = load(scene_text("half.hdr", ""));
    let e = scene.lighting.sky.as_ref().unwrap().horizontal_irradiance();
    assert!((e.g / PI - 1.0).abs() < 1e-9, "horizontal irradiance {} against π", e.g);
    let solver = solved(&scene);
    let floor = mean_radiosity(&solver, "floor");
    eprintln!("map: floor {floor:.5} against {:.5}", 0.5 * PI);
    assert!((floor / (0.5 * PI) - 1.0).abs() < 0.003, "floor {floor} against {}", 0.5 * PI);
    let reference = Reference::new(&scene);
    let params = EstimateParams { budget: PathBudget::Fixed { paths: 20_000 }, ..EstimateParams::default() };
    let objects = reference.estimate_objects(&params, &|_| {}).objects;
    let traced = objects.iter().find(|o| o.name == "floor").unwrap();
    let (mean, se) = (traced.estimate.luminance, traced.estimate.luminance_stderr);
    assert!((mean - 0.5 * PI).abs() <= 3.0 * se + 1e-3, "path tracer {mean} ± {se}");
    for (rotation, brighter, darker) in [("", "north", "south"), ("rotation = 180", "south", "north")] {
        let solver = solved(&load(scene_text("north.hdr", rotation)));
        let (b, d) = (mean_radiosity(&solver, brighter), mean_radiosity(&solver, darker));
        eprintln!("map {rotation}: {brighter} {b:.4}, {darker} {d:.4}");
        assert!(b > 1.5 * d, "{rotation}: {brighter} {b} against {darker} {d}");
    }
}

/// A scene file with another up axis is turned upright with everything in it: a clear sky's
/// sun and a map's middle column turn with the `[sun]` and the zenith (in a z-up file the
/// clear sky's brightest place stays where the `[sun]` is; a map's middle faces the file's
/// north, +y there).
#[test]
fn a_z_up_sky_turns_with_the_scene() {
    let extra = "up = \"z\"\n[sun]\ndirection = [0.3, 0.2, 1]\nilluminance = 100000";
    let scene =
        crate::sun::load_with_table(extra, "sky", "model = \"cie-clear\"\nilluminance = 10000").unwrap();
    let towards = scene.lighting.sun.as_ref().unwrap().towards;
    let sky = scene.lighting.sky.as_ref().unwrap();
    assert!((sky.zenith - radiosity_core::glam::DVec3::Y).length() < 1e-12, "{}", sky.zenith);
    match &sky.model {
        radiosity_core::SkyModel::CieClear { sun } => {
            assert!((*sun - towards).length() < 1e-12, "{sun} vs {towards}")
        }
        other => panic!("{other:?}"),
    }
    let dir = tempfile::tempdir().unwrap();
    write_hdr(&dir.path().join("m.hdr"), 8, 4, |_, _| [1.0; 3]);
    let path = dir.path().join("scene.toml");
    std::fs::write(
        &path,
        "up = \"z\"\n[sky]\nmap = \"m.hdr\"\n[[material]]\nname = \"g\"\nreflectance = [0.5, 0.5, 0.5]\n\
         [[object]]\nname = \"f\"\ntype = \"polygon\"\nmaterial = \"g\"\nvertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n",
    )
    .unwrap();
    let scene = radiosity_io::load_scene(&path).unwrap().scene;
    match &scene.lighting.sky.as_ref().unwrap().model {
        // The file's +y (its north) is −z once turned upright.
        radiosity_core::SkyModel::Map { forward, .. } => {
            assert!((*forward - radiosity_core::glam::DVec3::NEG_Z).length() < 1e-12, "{forward}")
        }
        other => panic!("{other:?}"),
    }
}
