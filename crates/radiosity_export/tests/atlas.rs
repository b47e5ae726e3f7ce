//! The lightmap atlas of the model's own faces: every texel whose centre lies on a face holds
//! the solution at that point (checked against a search of the elements by hand, not the
//! bake's own ray lookup), the padding around the charts is filled, irradiance is radiosity
//! over reflectance, both sides of a two-sided object get charts, and the bake is
//! deterministic.

use glam::{DVec2, DVec3};
use radiosity_core::{Rgb, Scene};
use radiosity_export::{Atlas, AtlasMesh, AtlasOptions, AtlasTexels, LightmapQuantity, bake_atlas};
use radiosity_mesh::Mesh;
use radiosity_scenes::{cornell_box, two_sided_plate};
use radiosity_solver::{Problem, Solution, SolverParams};

fn solved(scene: &Scene, shots: u64) -> (Problem, Solution) {
    let problem = Problem::new(scene, &scene.mesh_params()).unwrap();
    let mut solver =
        problem.solver(SolverParams { max_shots: Some(shots), ..SolverParams::default() }).unwrap();
    solver.solve();
    let solution = solver.solution();
    (problem, solution)
}

fn bake(scene: &Scene, mesh: &Mesh, solution: &Solution, quantity: LightmapQuantity) -> Atlas {
    let options = AtlasOptions { size: 256, quantity, ..AtlasOptions::default() };
    bake_atlas(scene, mesh, solution, &options, AtlasTexels::Interpolated).unwrap()
}

/// Every texel `(x, y, point)` whose centre lies in one of `m`'s triangles in lightmap
/// coordinates, found by its own barycentric test.
fn texel_points(m: &AtlasMesh, w: u32, h: u32) -> Vec<(u32, u32, DVec3, DVec3)> {
    let mut out = Vec::new();
    for tri in m.indices.chunks_exact(3) {
        let tri: [u32; 3] = tri.try_into().unwrap();
        let uv = tri.map(|i| DVec2::from(m.uv1[i as usize].map(f64::from)));
        let p = tri.map(|i| m.positions[i as usize]);
        let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        let det = (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]);
        for y in 0..h {
            for x in 0..w {
                let c = DVec2::new((f64::from(x) + 0.5) / f64::from(w), (f64::from(y) + 0.5) / f64::from(h));
                let b1 = (c - uv[0]).perp_dot(uv[2] - uv[0]) / det;
                let b2 = (uv[1] - uv[0]).perp_dot(c - uv[0]) / det;
                if b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 {
                    out.push((x, y, p[0] * (1.0 - b1 - b2) + p[1] * b1 + p[2] * b2, normal));
                }
            }
        }
    }
    out
}

/// The radiosity at `point` on the side of object `object` facing `normal`: the element of
/// that object and side whose polygon holds the point, interpolated from its vertices over
/// the fan triangle that holds it; `None` on no element (a part left out of the solve).
fn by_hand(mesh: &Mesh, solution: &Solution, object: usize, point: DVec3, normal: DVec3) -> Option<Rgb> {
    let (lo, hi) =
        mesh.positions.iter().fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let scale = 1e-6 * (hi - lo).length();
    for (e, el) in mesh.elements.iter().enumerate() {
        if mesh.element_object(e) != object || el.normal.dot(normal) < 0.5 {
            continue;
        }
        let v = el.vertex_indices();
        let q = |k: usize| mesh.positions[v[k] as usize];
        if el.normal.dot(point - q(0)).abs() > scale {
            continue;
        }
        for k in 1..v.len() - 1 {
            let (a, b, c) = (q(0), q(k), q(k + 1));
            let n = (b - a).cross(c - a);
            let area = n.length_squared();
            let wb = (point - a).cross(c - a).dot(n) / area;
            let wc = (b - a).cross(point - a).dot(n) / area;
            let tol = -1e-9;
            if wb >= tol && wc >= tol && wb + wc <= 1.0 - tol {
                let r = |i: u32| solution.vertex_radiosity[i as usize];
                return Some(r(v[0]) * (1.0 - wb - wc) + r(v[k]) * wb + r(v[k + 1]) * wc);
            }
        }
    }
    None
}

fn close(a: Rgb, b: Rgb, tolerance: f64) -> bool {
    let (a, b) = (a.to_array(), b.to_array());
    (0..3).all(|c| (a[c] - b[c]).abs() <= tolerance * a[c].abs().max(b[c].abs()) + 1e-9)
}

/// Radiosity texels of the Cornell box against the elements searched by hand, texel by texel:
/// the same value (up to the single precision of the lightmap coordinates) wherever an
/// element lies under the texel's point, and the texels where none does (the floor under the
/// blocks, left out of the solve) are few.
#[test]
fn every_texel_holds_the_solution_at_its_point() {
    let scene = cornell_box();
    let (problem, solution) = solved(&scene, 200);
    let mesh = problem.mesh();
    let atlas = bake(&scene, mesh, &solution, LightmapQuantity::Radiosity);
    let (w, h) = (atlas.image.width(), atlas.image.height());
    let (mut checked, mut none) = (0usize, 0usize);
    for m in &atlas.meshes {
        for (x, y, p, n) in texel_points(m, w, h) {
            match by_hand(mesh, &solution, m.object, p, n) {
                Some(expected) => {
                    let got = atlas.image.pixel(x, y);
                    assert!(
                        close(got, expected, 1e-3),
                        "object {} texel ({x}, {y}): {got:?} vs {expected:?}",
                        m.object
                    );
                    checked += 1;
                }
                None => none += 1,
            }
        }
    }
    assert!(checked > 20_000, "{checked} texels checked");
    assert!(none * 20 < checked, "{none} texels without an element against {checked}");
    assert_eq!(atlas.covered, checked + none, "the bake and the test find the same texels");
}

/// Around every texel on a face, the padding's texels are filled (dilated from the chart), so
/// bilinear filtering never reads the black between charts; every object is in the atlas.
#[test]
fn the_padding_around_every_chart_is_filled() {
    let scene = cornell_box();
    let (problem, solution) = solved(&scene, 200);
    let atlas = bake(&scene, problem.mesh(), &solution, LightmapQuantity::Radiosity);
    let (w, h) = (atlas.image.width() as i64, atlas.image.height() as i64);
    let pad = AtlasOptions::default().padding as i64;
    let lit = |x: i64, y: i64| atlas.image.pixel(x as u32, y as u32).to_array().iter().all(|&c| c > 0.0);
    for m in &atlas.meshes {
        for (x, y, _, _) in texel_points(m, w as u32, h as u32) {
            for dy in -pad..=pad {
                for dx in -pad..=pad {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if (0..w).contains(&nx) && (0..h).contains(&ny) {
                        assert!(lit(nx, ny), "texel ({nx}, {ny}) next to a chart is black");
                    }
                }
            }
        }
    }
    let mut objects: Vec<usize> = atlas.meshes.iter().map(|m| m.object).collect();
    objects.dedup();
    assert_eq!(objects.len(), scene.objects.len());
    assert!(atlas.meshes.iter().all(|m| m.uv1.iter().flatten().all(|c| (0.0..=1.0).contains(c))));
}

/// No texel of one chart samples another: every texel whose centre lies in a chart belongs
/// to that chart alone, and the texels a bilinear lookup there reads (its 3 × 3
/// neighbourhood), and the padding beyond, hold no other chart's texels.
#[test]
fn no_chart_samples_another() {
    let scene = cornell_box();
    let (problem, solution) = solved(&scene, 50);
    let atlas = bake(&scene, problem.mesh(), &solution, LightmapQuantity::Radiosity);
    let (w, h) = (atlas.image.width(), atlas.image.height());
    let mut owner = vec![u32::MAX; (w * h) as usize];
    for m in &atlas.meshes {
        for tri in m.indices.chunks_exact(3) {
            let chart = m.chart[tri[0] as usize];
            assert!(tri.iter().all(|&v| m.chart[v as usize] == chart), "a triangle spans charts");
            let one = AtlasMesh { indices: tri.to_vec(), ..m.clone() };
            for (x, y, _, _) in texel_points(&one, w, h) {
                let slot = &mut owner[(y * w + x) as usize];
                assert!(*slot == u32::MAX || *slot == chart, "texel ({x}, {y}) in two charts");
                *slot = chart;
            }
        }
    }
    let reach = AtlasOptions::default().padding as i64;
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let chart = owner[(y * w as i64 + x) as usize];
            if chart == u32::MAX {
                continue;
            }
            for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let (nx, ny) = (x + dx, y + dy);
                    if (0..w as i64).contains(&nx) && (0..h as i64).contains(&ny) {
                        let other = owner[(ny * w as i64 + nx) as usize];
                        assert!(
                            other == u32::MAX || other == chart,
                            "({x}, {y}) of chart {chart} beside chart {other}"
                        );
                    }
                }
            }
        }
    }
}

/// Irradiance texels times the reflectance are the radiosity texels, off the light; the
/// bake is the same twice over.
#[test]
fn irradiance_texels_are_radiosity_over_reflectance() {
    let scene = cornell_box();
    let (problem, solution) = solved(&scene, 100);
    let mesh = problem.mesh();
    let b = bake(&scene, mesh, &solution, LightmapQuantity::Radiosity);
    let e = bake(&scene, mesh, &solution, LightmapQuantity::Irradiance);
    assert_eq!(bake(&scene, mesh, &solution, LightmapQuantity::Irradiance).image, e.image);
    let (w, h) = (b.image.width(), b.image.height());
    let mut checked = 0;
    for m in &b.meshes {
        let material = &scene.materials[scene.objects[m.object].material];
        if material.emission != Rgb::ZERO {
            continue;
        }
        let rho = material.reflectance;
        for (x, y, _, _) in texel_points(m, w, h) {
            let (bx, ex) = (b.image.pixel(x, y), e.image.pixel(x, y));
            let product = Rgb::new(ex.r * rho.r, ex.g * rho.g, ex.b * rho.b);
            assert!(close(product, bx, 1e-9), "({x}, {y}): {product:?} vs {bx:?}");
            checked += 1;
        }
    }
    assert!(checked > 10_000);
}

/// A two-sided plate lit from below only: both sides get charts of their own, the lit one
/// bright and the other dark, as the solution has them, the dark one at the dim sides'
/// density.
#[test]
fn both_sides_of_a_two_sided_object_get_charts() {
    let scene = two_sided_plate(0.5, 1.0, 0.0);
    let (problem, solution) = solved(&scene, 400);
    let atlas = bake(&scene, problem.mesh(), &solution, LightmapQuantity::Radiosity);
    let plate = scene.objects.iter().position(|o| o.name == "plate").unwrap();
    let sides: Vec<&AtlasMesh> = atlas.meshes.iter().filter(|m| m.object == plate).collect();
    assert_eq!(sides.len(), 2, "front and back");
    let (w, h) = (atlas.image.width(), atlas.image.height());
    let mean = |m: &AtlasMesh| {
        let texels = texel_points(m, w, h);
        texels.iter().map(|&(x, y, _, _)| atlas.image.pixel(x, y).g).sum::<f64>() / texels.len() as f64
    };
    // The plate's front faces down (its square is wound clockwise seen from above), to the
    // lamp: the front is lit, the back dark.
    let (front, back) = if sides[0].back { (sides[1], sides[0]) } else { (sides[0], sides[1]) };
    assert!(mean(front) > 0.05 && mean(back) < 1e-3 * mean(front), "{} {}", mean(front), mean(back));
    assert!(back.back && !front.back);
    // The dark side is unwrapped at an eighth of the density: a sixty-fourth of the texels.
    let (nf, nb) = (texel_points(front, w, h).len() as f64, texel_points(back, w, h).len() as f64);
    let share = nb / nf;
    let expected = f64::from(radiosity_export::DIM_DENSITY).powi(2);
    assert!((share / expected - 1.0).abs() < 0.5, "{nb} texels against {nf}: {share}");
    assert_eq!(atlas.dim_sides, 1);
}

/// The written glTF reads back (with this program's own loader) as the same faces and the
/// same lamps: its triangles' total area is the scene's, front sides plus each two-sided
/// object's back, and its emitted power the scene's (the back of the lamp does not emit).
#[test]
fn the_written_gltf_reads_back_with_the_same_area_and_emission() {
    let scene = cornell_box();
    let (problem, solution) = solved(&scene, 50);
    let options = AtlasOptions { size: 256, ..AtlasOptions::default() };
    let atlas = bake_atlas(&scene, problem.mesh(), &solution, &options, AtlasTexels::Interpolated).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let tone = radiosity_image::ToneParams::new(0.0, radiosity_image::ToneOperator::Aces);
    let written = radiosity_export::write_atlas(dir.path(), &scene, &atlas, &options, tone).unwrap();
    assert_eq!(written.len(), 3);
    let back = radiosity_io::load_scene(&dir.path().join("lightmapped.gltf")).unwrap().scene;
    let totals = |s: &Scene| {
        let (mut total, mut emitted) = (0.0, 0.0);
        for o in &s.objects {
            let a = match &o.shape {
                radiosity_core::Shape::Polygons(p) => p.iter().map(|p| p.area()).sum::<f64>(),
                radiosity_core::Shape::Mesh(m) => m.polygons().iter().map(|p| p.area()).sum::<f64>(),
                radiosity_core::Shape::Sphere(_) => 0.0,
            };
            total += a;
            emitted += a * s.materials[o.material].emission.g;
        }
        (total, emitted)
    };
    let ((a0, e0), (a1, e1)) = (totals(&scene), totals(&back));
    let backs: f64 = atlas
        .meshes
        .iter()
        .filter(|m| m.back)
        .map(|m| match &scene.objects[m.object].shape {
            radiosity_core::Shape::Polygons(p) => p.iter().map(|p| p.area()).sum::<f64>(),
            _ => 0.0,
        })
        .sum();
    assert!(((a0 + backs) / a1 - 1.0).abs() < 1e-6, "{a0} + {backs} vs {a1}");
    assert!((e1 / e0 - 1.0).abs() < 1e-6, "emitted {e0} vs {e1}");
}

/// A fixed density is kept: the Cornell box (a 556 mm room) at 0.2 texels per millimetre
/// gets charts whose texel area is the faces' area times 0.2², within the rasterisation's
/// edge texels.
#[test]
fn a_fixed_density_sizes_the_charts() {
    let scene = cornell_box();
    let (problem, solution) = solved(&scene, 20);
    let options = AtlasOptions { texels_per_unit: Some(0.2), ..AtlasOptions::default() };
    let atlas = bake_atlas(&scene, problem.mesh(), &solution, &options, AtlasTexels::Interpolated).unwrap();
    assert!((atlas.texels_per_unit - 0.2).abs() < 1e-6, "{}", atlas.texels_per_unit);
    let (w, h) = (atlas.image.width(), atlas.image.height());
    for m in atlas.meshes.iter().filter(|m| !m.back) {
        let area: f64 = m
            .indices
            .chunks_exact(3)
            .map(|t| {
                let p = |k: usize| m.positions[t[k] as usize];
                0.5 * (p(1) - p(0)).cross(p(2) - p(0)).length()
            })
            .sum();
        let texels = texel_points(m, w, h).len() as f64;
        let expected = area * 0.2 * 0.2;
        assert!((texels / expected - 1.0).abs() < 0.1, "object {}: {texels} texels for {expected}", m.object);
    }
}
