//! Textures seen: a model's colour texture shows in `render`, while the solve keeps the
//! material's mean reflectance. A floor quad with a 4 × 4 checkerboard (black and white
//! texels) under a small lamp, seen from straight above.

use std::path::Path;

use radiosity_core::Scene;
use radiosity_core::glam::DVec3;
use radiosity_image::{HdrImage, RenderParams, Renderer, Shading, SrgbImage, write_png};
use radiosity_solver::{Problem, Solution, SolverParams};

/// Checker squares per side of the floor.
const SQUARES: u32 = 4;
/// Picture pixels per checker square.
const PIXELS_PER_SQUARE: u32 = 16;

/// A 2 × 2 floor at y = 0 (texture coordinates 0..1 over it) and a 0.5 × 0.5 lamp facing
/// down 1.5 above its centre, with the floor's material `floor_mtl`.
fn write_scene(dir: &Path, floor_mtl: &str) -> std::path::PathBuf {
    let texels = (0..SQUARES * SQUARES)
        .map(|i| if (i % SQUARES + i / SQUARES).is_multiple_of(2) { [255; 3] } else { [0; 3] })
        .collect();
    write_png(&dir.join("checker.png"), &SrgbImage { width: SQUARES, height: SQUARES, pixels: texels })
        .unwrap();
    let mtl = format!("newmtl floor\n{floor_mtl}\nnewmtl lamp\nKd 0 0 0\nKe 10 10 10\n");
    std::fs::write(dir.join("room.mtl"), mtl).unwrap();
    let obj = "mtllib room.mtl\n\
        o floor\nv 0 0 0\nv 0 0 2\nv 2 0 2\nv 2 0 0\n\
        vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\nusemtl floor\nf 1/1 2/2 3/3 4/4\n\
        o lamp\nv 0.75 1.5 0.75\nv 1.25 1.5 0.75\nv 1.25 1.5 1.25\nv 0.75 1.5 1.25\nusemtl lamp\nf 5 6 7 8\n";
    let path = dir.join("room.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

fn load(path: &Path) -> Scene {
    radiosity_io::load_scene(path).unwrap_or_else(|e| panic!("{e}")).scene
}

fn solve(scene: &Scene) -> (Problem, Solution) {
    let problem = Problem::new(scene, &scene.mesh_params()).unwrap();
    let mut solver =
        problem.solver(SolverParams { unshot_threshold: 1e-4, ..SolverParams::default() }).unwrap();
    solver.solve();
    let solution = solver.solution();
    (problem, solution)
}

/// The floor seen from 1 above its centre with a 90° field of view: exactly the floor, each
/// checker square `PIXELS_PER_SQUARE` pixels wide.
fn picture(renderer: &Renderer, solution: &Solution) -> HdrImage {
    let camera =
        radiosity_core::Camera::try_new(DVec3::new(1.0, 1.0, 1.0), DVec3::new(1.0, 0.0, 1.0), DVec3::Z, 90.0)
            .unwrap();
    let side = SQUARES * PIXELS_PER_SQUARE;
    let params = RenderParams {
        width: side,
        height: side,
        samples_per_pixel: 4,
        shading: Shading::Smooth,
        ..RenderParams::default()
    };
    renderer.render(solution, &camera, &params).unwrap().radiance
}

/// Mean red radiance of the middle eighth (per side) of each of `squares` × `squares`
/// checker squares filling the picture, in two lists by the square's parity: there, within
/// 1/16 of a texel of its centre, bilinear filtering takes little of the neighbours.
fn square_means(image: &HdrImage, squares: u32) -> [Vec<f64>; 2] {
    let mut out = [Vec::new(), Vec::new()];
    let n = image.width() / squares;
    let (from, to) = (n / 2 - n / 16, n / 2 + n / 16);
    for sy in 0..squares {
        for sx in 0..squares {
            let mut sum = 0.0;
            for y in sy * n + from..sy * n + to {
                for x in sx * n + from..sx * n + to {
                    sum += image.pixels()[(y * image.width() + x) as usize].to_array()[0];
                }
            }
            out[((sx + sy) % 2) as usize].push(sum / f64::from((to - from).pow(2)));
        }
    }
    out
}

fn mean(image: &HdrImage) -> f64 {
    image.pixels().iter().map(|p| p.to_array()[0]).sum::<f64>() / image.pixels().len() as f64
}

#[test]
fn a_checkered_floor_shows_its_squares_with_the_mean_of_the_flat_render() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load(&write_scene(dir.path(), "Kd 0.9 0.9 0.9\nmap_Kd checker.png"));
    let (problem, solution) = solve(&scene);
    let flat = picture(&Renderer::new(problem.mesh().clone()), &solution);
    let textured = picture(&Renderer::new(problem.mesh().clone()).with_textures(&scene), &solution);
    if std::env::var_os("RADIOSITY_TEXTURE_PICTURE").is_some() {
        let tone = radiosity_image::ToneParams::new(0.0, radiosity_image::ToneOperator::Aces);
        let out = Path::new(env!("CARGO_TARGET_TMPDIR"));
        write_png(&out.join("textured_floor.png"), &radiosity_image::tone_map_image(&textured, &tone))
            .unwrap();
        write_png(&out.join("flat_floor.png"), &radiosity_image::tone_map_image(&flat, &tone)).unwrap();
    }
    checkered(&textured, &flat, SQUARES);
}

/// Black texels reflect nothing and white ones twice the flat floor (albedo 0.9 over the
/// mean 0.45): the middles of the dark squares take under a fifth of the light ones' (the
/// bilinear filter's share of the neighbours there is about 6 %, of twice the light), and
/// the light ones more than 1.5 times the dimmest flat square's. The picture's mean is
/// the flat render's: the texture's mean is the reflectance the solve used, and by the
/// scene's symmetry every light square has a dark twin under the same light. 2 %: the
/// pixels' samples fall differently across the squares' edges.
fn checkered(textured: &HdrImage, flat: &HdrImage, squares: u32) {
    let [a, b] = square_means(textured, squares);
    let (dark, light) = if a.iter().sum::<f64>() < b.iter().sum::<f64>() { (a, b) } else { (b, a) };
    let (darkest_light, lightest_dark) =
        (light.iter().copied().fold(f64::INFINITY, f64::min), dark.iter().copied().fold(0.0, f64::max));
    assert!(lightest_dark < 0.2 * darkest_light, "dark squares {dark:?}, light {light:?}");
    let [fa, fb] = square_means(flat, squares);
    let flat_middles: Vec<f64> = fa.into_iter().chain(fb).collect();
    let dimmest_flat = flat_middles.iter().copied().fold(f64::INFINITY, f64::min);
    for v in &light {
        // Twice a flat square's light, within the floor's spread of it.
        assert!(*v > 1.5 * dimmest_flat, "light squares {light:?}, flat {flat_middles:?}");
    }
    let (m_textured, m_flat) = (mean(textured), mean(flat));
    eprintln!("dark {dark:?}\nlight {light:?}\nflat {flat_middles:?}\nmeans {m_textured} {m_flat}");
    assert!((m_textured / m_flat - 1.0).abs() < 0.02, "textured mean {m_textured}, flat {m_flat}");
}

#[test]
fn the_solve_uses_the_textures_mean_and_is_unchanged_by_keeping_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load(&write_scene(dir.path(), "Kd 0.9 0.9 0.9\nmap_Kd checker.png"));
    let floor = scene.materials.iter().find(|m| m.name == "floor").unwrap();
    // Half the texels white (1.0 linear), half black: the mean is half of Kd.
    for c in floor.reflectance.to_array() {
        assert!((c - 0.45).abs() < 1e-9, "{:?}", floor.reflectance);
    }
    assert!(floor.texture.is_some());
    let mut bare = scene.clone();
    for m in &mut bare.materials {
        m.texture = None;
    }
    let (_, kept) = solve(&scene);
    let (_, dropped) = solve(&bare);
    assert_eq!(kept.element_radiosity, dropped.element_radiosity);
    assert_eq!(kept.vertex_radiosity, dropped.vertex_radiosity);
}

#[test]
fn untextured_scenes_render_the_same_to_the_bit() {
    let scene = radiosity_scenes::cornell_box();
    let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
    let mut solver =
        problem.solver(SolverParams { unshot_threshold: 1e-2, ..SolverParams::default() }).unwrap();
    solver.solve();
    let solution = solver.solution();
    let camera = radiosity_image::camera_or_framing(&scene);
    for gather in [radiosity_image::Gather::None, radiosity_image::Gather::Direct] {
        let params = RenderParams {
            width: 40,
            height: 30,
            samples_per_pixel: 1,
            gather,
            shadow_rays: 4,
            ..RenderParams::default()
        };
        let before = Renderer::new(problem.mesh().clone()).render(&solution, &camera, &params).unwrap();
        let after = Renderer::new(problem.mesh().clone())
            .with_textures(&scene)
            .render(&solution, &camera, &params)
            .unwrap();
        assert_eq!(before, after, "{gather:?}");
    }
}

/// The floor and lamp of [`write_scene`] as glTF: the floor's base colour texture the
/// checkerboard, mapped through `KHR_texture_transform` scale ½ (so the floor shows 2 × 2 of
/// its squares), its sampler repeating along u and clamping along v.
fn write_gltf(dir: &Path) -> std::path::PathBuf {
    write_scene(dir, "Kd 0.9 0.9 0.9");
    let floor = [[0.0f32, 0.0, 0.0], [0.0, 0.0, 2.0], [2.0, 0.0, 2.0], [2.0, 0.0, 0.0]];
    let lamp = [[0.75f32, 1.5, 0.75], [1.25, 1.5, 0.75], [1.25, 1.5, 1.25], [0.75, 1.5, 1.25]];
    let uvs = [[0.0f32, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]];
    let mut bin: Vec<u8> = Vec::new();
    floor.iter().flatten().for_each(|v| bin.extend(v.to_le_bytes()));
    uvs.iter().flatten().for_each(|v| bin.extend(v.to_le_bytes()));
    [0u16, 1, 2, 0, 2, 3].iter().for_each(|v| bin.extend(v.to_le_bytes()));
    lamp.iter().flatten().for_each(|v| bin.extend(v.to_le_bytes()));
    std::fs::write(dir.join("room.bin"), &bin).unwrap();
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_materials_emissive_strength", "KHR_texture_transform"],
  "scene": 0, "scenes": [{{"nodes": [0, 1]}}],
  "nodes": [{{"mesh": 0, "name": "floor"}}, {{"mesh": 1, "name": "lamp"}}],
  "meshes": [
    {{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": 0}}]}},
    {{"primitives": [{{"attributes": {{"POSITION": 3}}, "indices": 2, "material": 1}}]}}
  ],
  "materials": [
    {{"name": "floor", "pbrMetallicRoughness": {{"baseColorFactor": [0.9, 0.9, 0.9, 1], "metallicFactor": 0,
      "baseColorTexture": {{"index": 0, "extensions": {{"KHR_texture_transform": {{"scale": [0.5, 0.5]}}}}}}}}}},
    {{"name": "lamp", "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}},
      "emissiveFactor": [1, 1, 1], "extensions": {{"KHR_materials_emissive_strength": {{"emissiveStrength": 10}}}}}}
  ],
  "textures": [{{"source": 0, "sampler": 0}}],
  "samplers": [{{"wrapS": 10497, "wrapT": 33071}}],
  "images": [{{"uri": "checker.png"}}],
  "buffers": [{{"uri": "room.bin", "byteLength": {len}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 12}},
    {{"buffer": 0, "byteOffset": 92, "byteLength": 48}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [2, 0, 2]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}},
    {{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0.75, 1.5, 0.75], "max": [1.25, 1.5, 1.25]}}
  ]
}}"#,
        len = bin.len()
    );
    let path = dir.join("room.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn a_gltf_base_colour_texture_shows_through_its_transform_and_sampler() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load(&write_gltf(dir.path()));
    let floor = scene.objects.iter().find(|o| o.name == "floor").unwrap();
    let texture = scene.materials[floor.material].texture.clone().expect("the floor keeps its texture");
    use radiosity_core::Wrap;
    assert_eq!(texture.wrap, [Wrap::Repeat, Wrap::ClampToEdge]);
    assert_eq!(texture.factor, [0.9f32 as f64; 3]);
    let radiosity_core::Shape::Mesh(mesh) = &floor.shape else { panic!("the floor is a mesh") };
    // Scaled by ½: the corner at (1, 1) reads the texture's middle.
    assert!(mesh.uvs().iter().flatten().any(|uv| *uv == [0.5, 0.5]), "{:?}", mesh.uvs());
    let (problem, solution) = solve(&scene);
    let flat = picture(&Renderer::new(problem.mesh().clone()), &solution);
    let textured = picture(&Renderer::new(problem.mesh().clone()).with_textures(&scene), &solution);
    checkered(&textured, &flat, SQUARES / 2);
}

#[test]
fn map_kd_options_place_the_texture_and_corners_keep_their_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let scene =
        load(&write_scene(dir.path(), "Kd 0.9 0.9 0.9\nmap_Kd -o 0.25 0 -s 2 2 -clamp on checker.png"));
    let floor = scene.objects.iter().find(|o| o.name == "floor").unwrap();
    let texture = scene.materials[floor.material].texture.clone().expect("the floor keeps its texture");
    assert_eq!(texture.wrap, [radiosity_core::Wrap::ClampToEdge; 2]);
    let radiosity_core::Shape::Mesh(mesh) = &floor.shape else { panic!("the floor is a mesh") };
    // `vt 1 1` at (2, 0, 2): u′ = 1·2 + 0.25, v′ = 1·2 + 0, turned to run down: 1 − 2.
    let corner_of = |mesh: &radiosity_core::PolygonMesh, p: DVec3| {
        let (f, k) = (mesh.faces().iter().enumerate())
            .find_map(|(f, face)| {
                face.iter().position(|&i| mesh.positions()[i as usize] == p).map(|k| (f, k))
            })
            .unwrap();
        mesh.uvs()[f][k]
    };
    let far = DVec3::new(2.0, 0.0, 2.0);
    assert_eq!(corner_of(mesh, far), [2.25, -1.0]);
    // Turned over (as closed models whose light is behind them are), each corner keeps its
    // coordinates.
    let flipped = mesh.flipped();
    assert_eq!(corner_of(&flipped, far), [2.25, -1.0]);
    assert_eq!(corner_of(&flipped, DVec3::ZERO), corner_of(mesh, DVec3::ZERO));
}
