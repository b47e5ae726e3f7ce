//! Lux against closed forms that need no table: a point source in the centre of a closed
//! sphere (the integrating sphere), and the inverse-square and cosine laws over a floor and on
//! a wall, checked on the solver's elements, on `[[grid]]` points and, for the sphere, with
//! the path tracer of `verify`.
//!
//! Each tolerance is derived from the discretisation it checks and stated where it is used.

use radiosity_core::glam::DVec3;
use radiosity_core::{LUMENS_PER_WATT, Scene};
use radiosity_image::{GridParams, Renderer, grid_illuminance};
use radiosity_mesh::Mesh;
use radiosity_solver::{Problem, SolverParams};

use crate::photometry::{grids_of, ies, load, over_black_plane_with};

/// Illuminance (lx) of every element from its radiosity, E = B / ρ (scenes in metres).
fn element_lux(mesh: &Mesh, radiosity: &[radiosity_core::Rgb]) -> Vec<f64> {
    (0..mesh.elements.len())
        .map(|e| {
            radiosity[e].luminance() / mesh.element_material(e).reflectance.luminance() * LUMENS_PER_WATT
        })
        .collect()
}

/// The solid angle of the convex polygon `corners` seen from `p`, sr: the sum of its fan
/// triangles' by Van Oosterom & Strackee (1983), tan(Ω/2) = a·(b × c) / (|a||b||c| +
/// (a·b)|c| + (b·c)|a| + (c·a)|b|).
fn solid_angle(p: DVec3, corners: &[DVec3]) -> f64 {
    (1..corners.len() - 1)
        .map(|k| {
            let (a, b, c) = (corners[0] - p, corners[k] - p, corners[k + 1] - p);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            (2.0 * a.dot(b.cross(c)).atan2(den)).abs()
        })
        .sum()
}

/// A closed sphere of radius `r` and reflectance `rho`, facing in, an isotropic luminaire of
/// `candela` at its centre.
fn integrating_sphere(r: f64, rho: f64, candela: f64, element: f64) -> (tempfile::TempDir, Scene) {
    let text = format!(
        r#"
units = "m"
[[material]]
name = "grey"
reflectance = [{rho}, {rho}, {rho}]
[[object]]
name = "sphere"
type = "sphere"
center = [0, 0, 0]
radius = {r}
normals = "inward"
material = "grey"
[[luminaire]]
file = "iso.ies"
position = [0, 0, 0]
[mesh]
patch_size = {element}
element_size = {element}
adaptive_levels = 0
"#
    );
    load(&text, &[("iso.ies", ies(&[0.0, 180.0], &[candela, candela]))])
}

/// The integrating sphere, solved: a point source of I cd at the centre of a closed sphere of
/// radius R lights every point of it with E_d = I / R² directly (d = R, normal incidence),
/// and, as every point of a sphere sees every other with the same form factor dA / 4πR²
/// (`references/closed_forms.md`), the reflected light is uniform too: E = E_d + ρE, so
/// E = I / R² · 1 / (1 − ρ).
///
/// The solver's sphere is a polyhedron of flat facets with their corners on the sphere. A
/// facet whose plane lies at h from the centre has every point at h ≤ d ≤ R with cos θ = h/d,
/// so its direct light I·h/d³ lies between I·h/R³ and I/h², whatever points sample it: the
/// worst facet's direct figure must lie within those bounds relative to I / R² (0.48 % for
/// these facets of side s = πR/32). The facets close around the source, so Σ E·A = I·4π
/// exactly and the area-weighted mean direct light is I·4π / A_facets, over I/R² by the
/// facets' area deficit 4πR²/A − 1. The solver samples each facet at the centroids of its
/// fan triangles rather than integrating: with E ≈ (I/h²)(1 − 3r²/2h²) about the facet's
/// foot, those points (⟨r²⟩ = s²/9 on a square) read above the mean (⟨r²⟩ = s²/6) by
/// s²/(12h²), 8e-4 here; the mean may differ from the deficit by 1e-3. The total light adds
/// the reflected part, uniform on the sphere; its mean is Φ / (A (1 − ρ)) by energy
/// conservation, so it holds to the deficit as the direct light does (the 1e-5 left unshot
/// is far below). Its worst facet is allowed the direct bound plus the deficit plus 2e-3
/// (the sampling's excess, and as much again for the form factors between flat facets).
#[test]
fn a_point_source_in_a_closed_sphere_lights_it_evenly() {
    let (r, rho, i) = (1.5, 0.5, 300.0);
    let (_dir, scene) = integrating_sphere(r, rho, i, 0.15);
    let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
    let mesh = problem.mesh();
    let mut solver =
        problem.solver(SolverParams { unshot_threshold: 1e-5, ..SolverParams::default() }).unwrap();
    let direct = element_lux(mesh, &solver.solution().element_radiosity);
    solver.solve();
    let total = element_lux(mesh, &solver.solution().element_radiosity);

    let area: f64 = mesh.elements.iter().map(|e| e.area).sum();
    let deficit = 4.0 * std::f64::consts::PI * r * r / area - 1.0;
    let e_direct = i / (r * r);
    let e_total = e_direct / (1.0 - rho);
    let (mut worst_direct, mut worst_total, mut worst_bound) = (0.0_f64, 0.0_f64, 0.0_f64);
    let (mut mean_direct, mut mean_total) = (0.0, 0.0);
    for (k, el) in mesh.elements.iter().enumerate() {
        let h = el.normal.dot(el.centre).abs();
        let (lo, hi) = (h / r - 1.0, (r / h).powi(2) - 1.0);
        let err = direct[k] / e_direct - 1.0;
        assert!(
            err >= lo - 1e-9 && err <= hi + 1e-9,
            "facet {k}: direct {} lx, bounds {lo} .. {hi}",
            direct[k]
        );
        let err_total = total[k] / e_total - 1.0;
        let bound = lo.abs().max(hi) + deficit.abs() + 2e-3;
        assert!(err_total.abs() <= bound, "facet {k}: total {} lx, {err_total} vs {bound}", total[k]);
        worst_direct = worst_direct.max(err.abs());
        worst_total = worst_total.max(err_total.abs());
        worst_bound = worst_bound.max(lo.abs().max(hi));
        mean_direct += direct[k] * el.area / area;
        mean_total += total[k] * el.area / area;
    }
    let (mean_d, mean_t) = (mean_direct / e_direct - 1.0, mean_total / e_total - 1.0);
    eprintln!(
        "integrating sphere, {} facets, area deficit {deficit:.5}: direct worst {worst_direct:.5} (bound {worst_bound:.5}) mean {mean_d:.6}; total worst {worst_total:.5} mean {mean_t:.6}",
        mesh.elements.len()
    );
    assert!((mean_d - deficit).abs() <= 1e-3, "mean direct {mean_d} vs the area deficit {deficit}");
    assert!((mean_t - deficit).abs() <= 1e-3, "mean total {mean_t} vs the area deficit {deficit}");
}

/// The same sphere by `verify`'s path tracer, on the exact sphere: every point receives
/// exactly I / R² from the luminaire by next-event estimation (no variance at all), and the
/// total is I / R² / (1 − ρ) within 3 standard errors of its estimate (plus 1e-9 of round-off).
#[test]
fn the_path_tracer_meets_the_integrating_sphere() {
    use radiosity_reference::{EstimateParams, PathBudget, Reference};
    let (r, rho, i) = (1.5, 0.5, 300.0);
    let (_dir, scene) = integrating_sphere(r, rho, i, 0.15);
    let reference = Reference::new(&scene);
    let lux = |max_reflections: u32, paths: u64| {
        let params = EstimateParams {
            budget: PathBudget::Fixed { paths },
            max_reflections,
            ..EstimateParams::default()
        };
        let e = &reference.estimate_objects(&params, &|_| {}).objects[0].estimate;
        (e.luminance / rho * LUMENS_PER_WATT, e.luminance_stderr / rho * LUMENS_PER_WATT)
    };
    let e_direct = i / (r * r);
    let (direct, direct_se) = lux(1, 4096);
    assert!((direct - e_direct).abs() <= 3.0 * direct_se + 1e-9 * e_direct, "{direct} ± {direct_se} lx");
    let e_total = e_direct / (1.0 - rho);
    let (total, se) = lux(u32::MAX, 100_000);
    eprintln!(
        "path tracer, integrating sphere: direct {:.3e} relative, total {:.5} relative ± {:.5}",
        direct / e_direct - 1.0,
        total / e_total - 1.0,
        se / e_total
    );
    assert!((total - e_total).abs() <= 3.0 * se, "{total} ± {se} lx, expected {e_total}");
    assert!(se < 0.01 * e_total, "{se}");
}

/// Grey floor and wall (ρ = 0.5), an isotropic source of I cd at height h; grids on both.
fn floor_and_wall(i: f64, h: f64, element: f64) -> (tempfile::TempDir, Scene) {
    let text = format!(
        r#"
units = "m"
[[material]]
name = "grey"
reflectance = [0.5, 0.5, 0.5]
[[object]]
name = "floor"
type = "polygon"
vertices = [[-4, 0, -4], [-4, 0, 4], [3, 0, 4], [3, 0, -4]]
material = "grey"
[[object]]
name = "wall"
type = "polygon"
vertices = [[3, 0, -4], [3, 0, 4], [3, 4, 4], [3, 4, -4]]
material = "grey"
[[luminaire]]
file = "iso.ies"
position = [0, {h}, 0]
[[grid]]
name = "work plane"
origin = [-3.5, 0, -3.5]
u = [6, 0, 0]
v = [0, 0, 7]
divisions = [12, 14]
height = 0.8
[[grid]]
name = "wall"
origin = [2.999, 0, -3.5]
u = [0, 0, 7]
v = [0, 4, 0]
divisions = [14, 8]
normal = [-1, 0, 0]
[mesh]
patch_size = {element}
element_size = {element}
adaptive_levels = 0
"#
    );
    load(&text, &[("iso.ies", ies(&[0.0, 180.0], &[i, i]))])
}

/// The cosine and inverse-square laws for a point source of I cd at height h over a floor
/// (CIE 171:2006 test case 5.2): at a horizontal point a distance x off the nadir,
/// E = I·cos θ / d² = I·cos³θ / h²; on a vertical plane at distance a from the source,
/// E = I·cos θ_v / d² with cos θ_v = a / d.
///
/// Grid points: the direct light at a point is the law itself, by a shadow ray; only round-off
/// separates them (1e-6).
///
/// Elements: the solver's direct light on an element is the law sampled at the centroids of
/// its fan triangles; the exact mean is I·Ω/A, Ω the element's solid angle from the source
/// (the law integrated over it). A rule exact for linear functions errs by at most
/// ½·max‖∇²E‖·(s²/6 + s²/9) on an element of longest side s (the second moments about its
/// centre of the element, at most a square's s²/6, and of its sample points, s²/9), and
/// ‖∇²E‖ ≤ 3E/a² for E = I·a/d³ at distance a from the plane. With s ≤ a/5, E varies over an
/// element by less than a factor 2 ((1 + s/a)⁴ ≈ 2.07 at most), so the relative error is
/// below 2 · ½ · 3/a² · 5s²/18 = 5s²/(6a²): 3.3 % for the floor's 0.5 m elements 2.5 m below
/// the source, 2.3 % on the wall 3 m from it.
#[test]
fn the_cosine_and_inverse_square_laws_hold_on_elements_and_grids() {
    let (i, h, s) = (1000.0, 2.5, 0.35);
    let (_dir, scene) = floor_and_wall(i, h, s);
    let source = DVec3::new(0.0, h, 0.0);
    let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
    let mesh = problem.mesh();
    let solver = problem.solver(SolverParams::default()).unwrap();
    let solution = solver.solution();
    let direct = element_lux(mesh, &solution.element_radiosity);
    let mut worst = [0.0_f64; 2];
    for (k, el) in mesh.elements.iter().enumerate() {
        let corners: Vec<DVec3> = mesh.element_corners(k).collect();
        let exact = i * solid_angle(source, &corners) / el.area;
        // Distance from the source to the element's plane: h for the floor, 3 for the wall.
        let a = el.normal.dot(source - el.centre);
        let side = corners
            .iter()
            .zip(corners.iter().cycle().skip(1))
            .map(|(p, q)| p.distance(*q))
            .fold(0.0, f64::max);
        let tolerance = 5.0 * side * side / (6.0 * a * a);
        let err = direct[k] / exact - 1.0;
        assert!(side <= a / 5.0, "element {k}: side {side} too long for the bound at {a}");
        assert!(
            err.abs() <= tolerance,
            "element {k} at {}: {} lx vs {exact}: {err} > {tolerance}",
            el.centre,
            direct[k]
        );
        let wall = usize::from(el.normal.x < -0.5);
        worst[wall] = worst[wall].max(err.abs());
    }
    eprintln!(
        "elements of side {s} against I·Ω/A: floor worst {:.2e}, wall worst {:.2e}",
        worst[0], worst[1]
    );

    let renderer = Renderer::new(mesh.clone());
    for (g, grid) in scene.lighting.grids.iter().enumerate() {
        let got = grid_illuminance(
            &renderer,
            &solution,
            problem.ray_queries().as_ref(),
            &scene.lighting,
            grid,
            &GridParams::default(),
        )
        .unwrap();
        assert_eq!(got.points.len(), [168, 112][g]);
        for (p, e) in got.points.iter().zip(&got.direct_lux) {
            let w = source - *p;
            let d = w.length();
            let expected = if g == 0 {
                // cos θ = (h − 0.8)/d: I·cos³θ / (h − 0.8)².
                let above = h - 0.8;
                let cos = above / d;
                i * cos.powi(3) / (above * above)
            } else {
                // The wall's plane at x = 2.999, a = 2.999 from the source: I·(a/d)/d².
                i * (2.999 / d) / (d * d)
            };
            assert!((e / expected - 1.0).abs() < 1e-6, "grid {g} at {p}: {e} lx, expected {expected}");
        }
    }
}

/// A luminaire whose table is I₀ cos γ and whose opening is a 1 × 0.5 m rectangle is a
/// Lambertian rectangle of luminance L = I₀ / A: at a point c below its plane, offsets x, y
/// from the point to its sides, E = π L F with F the parallel rectangle's configuration
/// factor (Howell B-3, one corner over the point; any point by adding and subtracting the
/// four rectangles that share it).
fn lambertian_rectangle_lux(l: f64, p: DVec3, (x0, x1): (f64, f64), (z0, z1): (f64, f64), c: f64) -> f64 {
    let corner = |x: f64, z: f64| {
        let (a, b) = (x.abs() / c, z.abs() / c);
        let (ra, rb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
        let f = (a / ra * (b / ra).atan() + b / rb * (a / rb).atan()) / (2.0 * std::f64::consts::PI);
        f * x.signum() * z.signum()
    };
    let f = corner(x1 - p.x, z1 - p.z) - corner(x0 - p.x, z1 - p.z) - corner(x1 - p.x, z0 - p.z)
        + corner(x0 - p.x, z0 - p.z);
    std::f64::consts::PI * l * f
}

/// Near a luminaire's opening its light is the opening's, not a point's (CIE 121 near
/// field): a 1 × 0.5 m cosine luminaire 0.5 m over a black floor, on a grid under and beside
/// it, against the Lambertian rectangle's closed form. Tolerance 0.5 %: the cells' midpoint
/// rule is within 0.5 % of B-3 at worst, at grazing incidence (`NEAR_FIELD_RATIO`), the table's 1° steps add
/// 0.004 %. The same fitting taken as a point (`near_field = false`) is off by 10–60 %
/// there, and within 1 % 10 m away (0.8 %: the light there grazes the floor at 3°). The path tracer, which draws
/// points of the opening at random, agrees within 3 standard errors.
#[test]
fn a_luminous_opening_lights_like_a_lambertian_rectangle() {
    let (i0, h, (length, width)) = (800.0, 0.5, (1.0, 0.5));
    let gammas: Vec<f64> = (0..=180).map(f64::from).collect();
    let candela: Vec<f64> = gammas.iter().map(|g| i0 * g.to_radians().cos().max(0.0)).collect();
    // IES: width (along C90) then length (along C0), metres.
    let file = ies(&gammas, &candela).replace("1 1 2 0 0 0\n", &format!("1 1 2 {width} {length} 0\n"));
    let scene = |near: bool| {
        let grids = "[[grid]]\nname = \"under\"\norigin = [-0.9, 0, -0.6]\nu = [1.8, 0, 0]\n\
                     v = [0, 0, 1.2]\ndivisions = [6, 4]\nheight = 0.0001\n\
                     [[grid]]\nname = \"far\"\norigin = [9.5, 0, -0.5]\nu = [1, 0, 0]\n\
                     v = [0, 0, 1]\ndivisions = [2, 2]\nheight = 0.0001\n";
        let text = over_black_plane_with("lambert.ies", h, &format!("near_field = {near}"), grids);
        load(&text, &[("lambert.ies", file.clone())])
    };
    let (_dir, near) = scene(true);
    let o = near.lighting.luminaires[0].opening;
    assert_eq!((o.length, o.width, o.round), (length, width, false), "C0 along +x by default");
    let l = i0 / (length * width);
    let c = h - 0.0001;
    let exact = |p: DVec3| {
        lambertian_rectangle_lux(l, p, (-length / 2.0, length / 2.0), (-width / 2.0, width / 2.0), c)
    };
    let (near_grids, (_far_dir, far_scene)) = (grids_of(&near), scene(false));
    let point_grids = grids_of(&far_scene);
    let mut worst = [0.0_f64; 2];
    for (g, (opening, point)) in near_grids.iter().zip(&point_grids).enumerate() {
        for ((p, e), e_point) in opening.points.iter().zip(&opening.direct_lux).zip(&point.direct_lux) {
            let want = exact(*p);
            let err = e / want - 1.0;
            assert!(err.abs() < 0.005, "grid {g} at {p}: {e} lx, B-3 gives {want}");
            let point_err = e_point / want - 1.0;
            if g == 0 {
                assert!(point_err.abs() > 0.10, "as a point, at {p}: only {point_err} off");
            } else {
                assert!(point_err.abs() < 0.01, "10 m away a point will do: {point_err}");
            }
            worst[g] = worst[g].max(err.abs());
        }
    }
    eprintln!("opening against B-3: under it worst {:.2e}, 10 m away {:.2e}", worst[0], worst[1]);

    use radiosity_reference::{EstimateParams, PathBudget, Reference};
    let reference = Reference::new(&near);
    let points: Vec<(DVec3, DVec3)> = near_grids[0].points.iter().map(|&p| (p, DVec3::Y)).collect();
    let params = EstimateParams { budget: PathBudget::Fixed { paths: 20_000 }, ..EstimateParams::default() };
    for ((p, _), e) in points.iter().zip(reference.estimate_points(&points, &params, &|_| {}, &|| false)) {
        let (lux, se) = (e.luminance * LUMENS_PER_WATT, e.luminance_stderr * LUMENS_PER_WATT);
        let want = exact(*p);
        assert!((lux - want).abs() <= 3.0 * se + 1e-9 * want, "path tracer at {p}: {lux} ± {se}, B-3 {want}");
        assert!(se < 0.02 * want, "{se}");
    }
}
