//! Photometry against closed forms (CIE 171:2006's test cases, re-derived here): lux from
//! point luminaires over a black plane, a cosine distribution from an IES file, and the
//! inter-reflection of a closed box; bad photometric files as one-line errors, exit 2.
//!
//! Tolerances: 0.5 % (the issue's goal) where the figure is a closed form; the direct light at
//! a grid point is exact up to the interpolation of the table and floating point, so those
//! tests hold to 1e-6 when the table holds the distribution exactly.

use std::path::Path;
use std::process::Command;

use radiosity_core::glam::DVec3;
use radiosity_core::{LUMENS_PER_WATT, Scene};
use radiosity_image::{GridParams, Renderer, grid_illuminance, grid_statistics};
use radiosity_solver::{Problem, SolverParams};

/// An IES LM-63-2002 file of a rotationally symmetric distribution I(γ), absolute photometry.
pub(crate) fn ies(gammas: &[f64], candela: &[f64]) -> String {
    let join = |v: &[f64]| v.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(" ");
    format!(
        "IESNA:LM-63-2002\n[TEST] closed form\nTILT=NONE\n1 -1 1 {} 1 1 2 0 0 0\n1 1 0\n{}\n0\n{}\n",
        gammas.len(),
        join(gammas),
        join(candela)
    )
}

/// Writes `files` into a fresh folder and loads `scene` (a TOML text) from it.
pub(crate) fn load(scene: &str, files: &[(&str, String)]) -> (tempfile::TempDir, Scene) {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let loaded = radiosity_io::load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    (dir, loaded.scene)
}

/// A black floor 40 × 40 m (so nothing reflects), a luminaire `h` above its centre, and a
/// 9 × 9 grid of 8 × 8 m on it.
fn over_black_plane(file: &str, h: f64) -> String {
    let grid = "[[grid]]\nname = \"floor\"\norigin = [-4, 0, -4]\nu = [8, 0, 0]\nv = [0, 0, 8]\n\
                divisions = [9, 9]\nheight = 0.0001\n";
    over_black_plane_with(file, h, "", grid)
}

/// A black 40 × 40 m floor, the luminaire of `file` at height `h` over its centre (with the
/// `[[luminaire]]` keys of `luminaire`), the `grids` given and one element per 5 m: a scene
/// where every lux is direct light.
pub(crate) fn over_black_plane_with(file: &str, h: f64, luminaire: &str, grids: &str) -> String {
    format!(
        r#"
units = "m"
[[material]]
name = "black"
reflectance = [0, 0, 0]
[[object]]
name = "floor"
type = "polygon"
vertices = [[-20, 0, -20], [-20, 0, 20], [20, 0, 20], [20, 0, -20]]
material = "black"
[[luminaire]]
file = "{file}"
position = [0, {h}, 0]
{luminaire}
{grids}
[mesh]
patch_size = 10
element_size = 5
adaptive_levels = 0
"#
    )
}

/// Solves `scene` to convergence and returns its grids' lux.
pub(crate) fn grids_of(scene: &Scene) -> Vec<radiosity_image::GridIlluminance> {
    let problem = Problem::new(scene, &scene.mesh_params()).unwrap();
    let mut solver =
        problem.solver(SolverParams { unshot_threshold: 1e-5, ..SolverParams::default() }).unwrap();
    solver.solve();
    let solution = solver.solution();
    let renderer = Renderer::new(problem.mesh().clone());
    scene
        .lighting
        .grids
        .iter()
        .map(|g| {
            grid_illuminance(
                &renderer,
                &solution,
                problem.ray_queries().as_ref(),
                &scene.lighting,
                g,
                &GridParams::default(),
            )
            .unwrap()
        })
        .collect()
}

/// CIE 171 5.2: an isotropic point source of I cd at height h over a black plane gives
/// E = I·h/d³ at every point (inverse-square law times the cosine of incidence h/d).
#[test]
fn isotropic_point_over_black_plane_follows_the_inverse_square_law() {
    let i = 1000.0;
    let h = 2.5;
    let (_dir, scene) =
        load(&over_black_plane("iso.ies", h), &[("iso.ies", ies(&[0.0, 90.0, 180.0], &[i, i, i]))]);
    let grid = &grids_of(&scene)[0];
    assert_eq!(grid.lux.len(), 81);
    for (p, e) in grid.points.iter().zip(&grid.lux) {
        let w = DVec3::new(0.0, h, 0.0) - *p;
        let d = w.length();
        let expected = i * w.y / (d * d * d);
        assert!((e / expected - 1.0).abs() < 1e-6, "at {p}: {e} lx, expected {expected}");
    }
    // Statistics of the grid: its mean, minimum (a corner) and U0.
    let (min, avg, max, u0) = grid_statistics(&grid.lux);
    assert_eq!((min, avg, max, u0), (grid.min, grid.avg, grid.max, grid.uniformity));
    let corner = grid.points[0];
    let above = h - corner.y;
    let d2 = corner.x.powi(2) + corner.z.powi(2) + above * above;
    assert!((min / (i * above / d2.powf(1.5)) - 1.0).abs() < 1e-6, "{min} at the corner {corner}");
    assert!((max / (i / (above * above)) - 1.0).abs() < 1e-6, "centre point straight below: {max}");
    assert!((u0 - min / avg).abs() < 1e-12);
}

/// A Lambertian (cosine) distribution read from an IES file at 1° steps: E = I₀·cos γ·cos θ/d²
/// (γ from the nadir, θ the incidence); on a horizontal plane below, both are h/d. Linear
/// interpolation of cos γ between 1° samples errs by at most 4e-5 of it below 80°.
#[test]
fn a_cosine_ies_distribution_gives_the_cosine_law() {
    let i0 = 2000.0;
    let h = 3.0;
    let gammas: Vec<f64> = (0..=90).map(f64::from).collect();
    let candela: Vec<f64> = gammas.iter().map(|g| i0 * g.to_radians().cos()).collect();
    let (_dir, scene) = load(&over_black_plane("lambert.ies", h), &[("lambert.ies", ies(&gammas, &candela))]);
    // The file's flux is π·I₀ (a Lambertian emitter), to the table's resolution.
    let flux = scene.lighting.luminaires[0].flux();
    assert!((flux / (std::f64::consts::PI * i0) - 1.0).abs() < 5e-4, "{flux}");
    let grid = &grids_of(&scene)[0];
    for (p, e) in grid.points.iter().zip(&grid.lux) {
        let w = DVec3::new(0.0, h, 0.0) - *p;
        let d = w.length();
        let cos = w.y / d;
        let expected = i0 * cos * cos / (d * d);
        assert!((e / expected - 1.0).abs() < 2e-4, "at {p}: {e} lx, expected {expected}");
    }
}

/// CIE 171 5.x (the integrating sphere, here a closed cube): a luminaire of flux Φ inside a
/// closed enclosure of reflectance ρ gives an area-weighted mean illuminance
/// Φ / (A (1 − ρ)) over all its surfaces, whatever the distribution and the position: all
/// light is absorbed in the end, a fraction (1 − ρ) per reflection. The solve's illuminance
/// is E = B/ρ (no emission); the luminaire is off-centre and aimed sideways so the direct
/// light is uneven. Tolerance 0.5 %: the direct light is integrated over each element by four
/// points, and the solve stops at 1e-5 of its light unshot.
#[test]
fn a_closed_box_holds_flux_over_area_times_one_minus_rho() {
    let rho = 0.6;
    let i = 100.0;
    let scene_text = format!(
        r#"
units = "m"
[[material]]
name = "grey"
reflectance = [{rho}, {rho}, {rho}]
[[object]]
name = "box"
type = "box"
min = [0, 0, 0]
max = [2, 1.5, 1]
normals = "inward"
material = "grey"
[[luminaire]]
file = "iso.ies"
position = [0.6, 1.0, 0.4]
aim = [1, -0.3, 0.2]
multiplier = 1.5
[mesh]
patch_size = 0.25
element_size = 0.0625
adaptive_levels = 0
"#
    );
    let gammas = [0.0, 45.0, 90.0, 135.0, 180.0];
    let candela = [i, 0.8 * i, 0.5 * i, 0.3 * i, 0.2 * i];
    let (_dir, scene) = load(&scene_text, &[("iso.ies", ies(&gammas, &candela))]);
    let flux = scene.lighting.luminaire_flux();
    let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
    let mut solver =
        problem.solver(SolverParams { unshot_threshold: 1e-5, ..SolverParams::default() }).unwrap();
    solver.solve();
    let solution = solver.solution();
    let mesh = problem.mesh();
    let (mut area, mut sum) = (0.0, 0.0);
    for (e, el) in mesh.elements.iter().enumerate() {
        area += el.area;
        sum += solution.element_radiosity[e].luminance() / rho * el.area;
    }
    let mean_lux = sum / area * LUMENS_PER_WATT;
    let expected = flux / (area * (1.0 - rho));
    assert!((area - 2.0 * (2.0 * 1.5 + 2.0 + 1.5)).abs() < 1e-9);
    assert!((mean_lux / expected - 1.0).abs() < 0.005, "{mean_lux} lx, expected {expected}");
    let energy = solver.energy();
    assert!(energy.residual().max_channel().abs() < 1e-9, "{energy:?}");
}

/// Units: the same room in millimetres gives the same lux.
#[test]
fn units_scale_lux() {
    let i = 500.0;
    let metres = over_black_plane("iso.ies", 2.0);
    let mm = metres
        .replace("units = \"m\"", "units = \"mm\"")
        .replace(
            "[[-20, 0, -20], [-20, 0, 20], [20, 0, 20], [20, 0, -20]]",
            "[[-20000, 0, -20000], [-20000, 0, 20000], [20000, 0, 20000], [20000, 0, -20000]]",
        )
        .replace("position = [0, 2, 0]", "position = [0, 2000, 0]")
        .replace("origin = [-4, 0, -4]", "origin = [-4000, 0, -4000]")
        .replace("u = [8, 0, 0]", "u = [8000, 0, 0]")
        .replace("v = [0, 0, 8]", "v = [0, 0, 8000]")
        .replace("height = 0.0001", "height = 0.1")
        .replace("patch_size = 10", "patch_size = 10000")
        .replace("element_size = 5", "element_size = 5000");
    let file = [("iso.ies", ies(&[0.0, 180.0], &[i, i]))];
    let (_a, m) = load(&metres, &file);
    let (_b, mm) = load(&mm, &file);
    let (gm, gmm) = (&grids_of(&m)[0], &grids_of(&mm)[0]);
    assert!((gm.avg / gmm.avg - 1.0).abs() < 1e-4, "{} vs {}", gm.avg, gmm.avg);
    assert!((gm.max - i / 4.0).abs() < 1e-3 * gm.max, "{}", gm.max);
}

/// Emitters given in lumens: a white 1000 lm square panel facing a black plane has
/// 683 · Y(E) · A = 1000 lm of power.
#[test]
fn lumens_on_a_material_set_its_power() {
    let text = r#"
units = "cm"
[[material]]
name = "panel"
reflectance = [0, 0, 0]
lumens = 1000
cct = 3000
[[material]]
name = "black"
reflectance = [0, 0, 0]
[[object]]
name = "panel"
type = "polygon"
vertices = [[0, 100, 0], [50, 100, 0], [50, 100, 50], [0, 100, 50]]
material = "panel"
[[object]]
name = "floor"
type = "polygon"
vertices = [[0, 0, 0], [0, 0, 50], [50, 0, 50], [50, 0, 0]]
material = "black"
"#;
    let (_dir, scene) = load(text, &[]);
    let lumens = scene.emitted_power().luminance() * LUMENS_PER_WATT;
    assert!((lumens - 1000.0).abs() < 1e-9, "{lumens}");
    let warm = scene.materials[0].emission;
    assert!(warm.r > warm.b, "3000 K is warm: {warm:?}");
}

fn radiosity(args: &[&str], dir: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).current_dir(dir).output().unwrap()
}

/// `--light-scale` scales luminaires as it scales emitters: the same scene's grid reads
/// exactly k times the lux (direct light only, over the black plane; linear throughout).
#[test]
fn light_scale_scales_luminaires() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("iso.ies"), ies(&[0.0, 180.0], &[400.0, 400.0])).unwrap();
    std::fs::write(dir.path().join("scene.toml"), over_black_plane("iso.ies", 2.0)).unwrap();
    let avg = |scale: &str| {
        let o = radiosity(&["solve", "scene.toml", "--light-scale", scale, "--json", "-", "-q"], dir.path());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let doc: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        doc["grids"][0]["avg"].as_f64().unwrap()
    };
    let (one, k) = (avg("1"), avg("2.5"));
    assert!(one > 0.0 && (k / one - 2.5).abs() < 1e-9, "{one} lx, scaled {k} lx");
}

/// A luminaire whose photometric centre lies inside a closed object (a fitting's body
/// modelled as a block) is one warning line naming both; the one outside it is not named.
/// A scene whose only luminaire lights nothing says so, not "give a material an emission".
#[test]
fn a_luminaire_inside_a_solid_warns() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("iso.ies"), ies(&[0.0, 180.0], &[400.0, 400.0])).unwrap();
    let scene = |positions: &str| {
        format!(
            r#"
units = "m"
[[material]]
name = "grey"
reflectance = [0.5, 0.5, 0.5]
[[object]]
name = "floor"
type = "polygon"
vertices = [[-2, 0, -2], [-2, 0, 2], [2, 0, 2], [2, 0, -2]]
material = "grey"
[[object]]
name = "housing"
type = "box"
min = [-0.2, 2.0, -0.2]
max = [0.2, 2.2, 0.2]
material = "grey"
[[luminaire]]
name = "lamp"
file = "iso.ies"
positions = {positions}
[mesh]
patch_size = 1
element_size = 0.5
"#
        )
    };
    std::fs::write(dir.path().join("scene.toml"), scene("[[0, 2.1, 0], [1, 2.1, 0]]")).unwrap();
    let o = radiosity(&["info", "scene.toml"], dir.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("inside the closed object")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].starts_with("warning: luminaire 'lamp #1'") && warnings[0].contains("'housing'"),
        "{err}"
    );

    std::fs::write(dir.path().join("scene.toml"), scene("[[0, 2.1, 0]]")).unwrap();
    let o = radiosity(&["solve", "scene.toml", "--json", "-", "-q"], dir.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("none of the scene's 1 luminaire(s) lights any surface"), "{err}");
}

/// A broken photometric file is one line naming the file and the line, exit 2, and nothing is
/// written.
#[test]
fn bad_photometric_files_are_one_line_errors() {
    let good = ies(&[0.0, 90.0], &[100.0, 50.0]);
    let cases = [
        ("truncated", good.replace("100 50", "100"), ":8:"),
        ("negative", good.replace("100 50", "100 -50"), ":8:"),
        ("order", good.replace("0 90\n", "90 0\n"), ":6:"),
        ("type B", good.replace("1 1 2 0 0 0", "1 2 2 0 0 0"), ":4:"),
    ];
    for (what, text, line) in cases {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("bad.ies"), &text).unwrap();
        std::fs::write(dir.path().join("scene.toml"), over_black_plane("bad.ies", 2.0)).unwrap();
        let o = radiosity(&["solve", "scene.toml", "--json", "out.json", "--grid-csv", "g.csv"], dir.path());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        let last = err.trim().lines().last().unwrap_or_default();
        assert!(last.contains(&format!("bad.ies{line}")), "{what}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{what}: {err}");
        assert!(!dir.path().join("out.json").exists() && !dir.path().join("g.csv").exists(), "{what}");
    }
}

/// The office scene: `solve --json` reports grids in lux, the luminaires and the unit, and
/// `--grid-csv` writes every point.
#[test]
fn the_office_reports_its_work_plane() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let scene = root.join("scenes/photometry/office.toml");
    let o = radiosity(
        &[
            "solve",
            scene.to_str().unwrap(),
            "--json",
            "r.json",
            "--grid-csv",
            "g.csv",
            "--max-shots",
            "200",
            "-q",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    assert_eq!(doc["units"], "m");
    assert_eq!(doc["luminaires"].as_array().unwrap().len(), 6);
    let grid = &doc["grids"][0];
    assert_eq!(grid["unit"], "lx");
    let points = grid["points"].as_array().unwrap();
    // EN 12464-1 for 5 m: p = 0.2 · 5^log10(5) = 0.62 m → 9 × 5 cells.
    assert_eq!(points.len(), 45);
    let (avg, min) = (grid["avg"].as_f64().unwrap(), grid["min"].as_f64().unwrap());
    assert!((200.0..2000.0).contains(&avg), "{avg}");
    assert!((grid["uniformity"].as_f64().unwrap() - min / avg).abs() < 1e-9);
    let csv = std::fs::read_to_string(dir.path().join("g.csv")).unwrap();
    assert_eq!(csv.lines().count(), 46);
}

/// The path tracer knows luminaires: over the black plane its grid irradiance is the inverse-
/// square law (no noise: nothing reflects, the luminaire's term is exact), and in the closed
/// box its area-weighted mean illuminance is Φ / (A (1 − ρ)) within 3 σ.
#[test]
fn the_path_tracer_meets_the_same_closed_forms() {
    use radiosity_reference::{EstimateParams, PathBudget, Reference};
    let i = 800.0;
    let h = 2.0;
    let (_dir, scene) = load(&over_black_plane("iso.ies", h), &[("iso.ies", ies(&[0.0, 180.0], &[i, i]))]);
    let points: Vec<(DVec3, DVec3)> =
        scene.lighting.grids[0].points().into_iter().map(|p| (p, DVec3::Y)).collect();
    let params = EstimateParams { budget: PathBudget::Fixed { paths: 4096 }, ..EstimateParams::default() };
    let reference = Reference::new(&scene);
    let to_lux = scene.lighting.unit().lux_per_irradiance();
    for ((p, _), e) in points.iter().zip(reference.estimate_points(&points, &params, &|_| {}, &|| false)) {
        let w = DVec3::new(0.0, h, 0.0) - *p;
        let expected = i * w.y / w.length().powi(3);
        assert!(
            (e.luminance * to_lux / expected - 1.0).abs() < 1e-6,
            "at {p}: {} vs {expected}",
            e.luminance * to_lux
        );
    }

    let rho = 0.5;
    let text = format!(
        r#"
units = "m"
[[material]]
name = "grey"
reflectance = [{rho}, {rho}, {rho}]
[[object]]
name = "box"
type = "box"
min = [0, 0, 0]
max = [1, 1, 1]
normals = "inward"
material = "grey"
[[luminaire]]
file = "iso.ies"
position = [0.3, 0.6, 0.5]
"#
    );
    let (_dir, scene) = load(&text, &[("iso.ies", ies(&[0.0, 90.0, 180.0], &[100.0, 60.0, 20.0]))]);
    let flux = scene.lighting.luminaire_flux();
    let params = EstimateParams { budget: PathBudget::Fixed { paths: 200_000 }, ..EstimateParams::default() };
    let estimates = Reference::new(&scene).estimate_objects(&params, &|_| {});
    let b = &estimates.objects[0].estimate;
    // E = B / ρ over the whole box (one object of area 6).
    let (mean, se) = (b.luminance / rho * LUMENS_PER_WATT, b.luminance_stderr / rho * LUMENS_PER_WATT);
    let expected = flux / (6.0 * (1.0 - rho));
    assert!((mean - expected).abs() < 3.0 * se, "{mean} ± {se} lx, expected {expected}");
    assert!(se < 0.01 * expected, "{se}");
}
