//! GPU tests on whatever adapter there is (on CI: Mesa's lavapipe, a CPU Vulkan driver that
//! setup.sh installs). They fail, never skip, when no adapter can be had: the viewer cannot
//! work without one either.

use std::path::PathBuf;

use eframe::wgpu;
use radiosity_core::{MeshParams, Rgb, srgb_encode};
use radiosity_image::{ToneOperator, ToneParams, tone_map};
use radiosity_scenes::cornell_box;
use radiosity_solver::{Problem, Solution, SolverParams, StepBudget};
use radiosity_viewer::render::{false_colour, shader_operator};
use radiosity_viewer::{
    COLOR_FORMAT, DisplayMode, FlyCamera, FrameParams, RenderTarget, SceneExtent, SceneRenderer,
    TONEMAP_WGSL, Wireframe, headless_gpu,
};

fn gpu() -> (wgpu::Device, wgpu::Queue) {
    let (device, queue, info) = headless_gpu().unwrap_or_else(|e| panic!("{e:#}"));
    eprintln!("GPU tests on {} ({:?}, {:?})", info.name, info.backend, info.device_type);
    (device, queue)
}

fn out_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("viewer");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `tone_map` and `false_colour` of tonemap.wgsl on the GPU over `cases`
/// (radiance, exposure scale, operator id, false-colour t) and returns both results.
fn run_wgsl(device: &wgpu::Device, queue: &wgpu::Queue, cases: &[[f32; 8]]) -> Vec<[f32; 8]> {
    use wgpu::util::DeviceExt;
    let source = format!(
        "{TONEMAP_WGSL}\n{}",
        r#"
struct Case { radiance: vec4<f32>, params: vec4<f32> };
@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> results: array<Case>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&cases) { return; }
    let c = cases[id.x];
    results[id.x].radiance = vec4<f32>(tone_map(c.radiance.xyz, c.params.x, u32(c.params.y)), 1.0);
    results[id.x].params = vec4<f32>(false_colour(c.params.z), 1.0);
}
"#
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("tone map test"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("tone map test"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(cases),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = std::mem::size_of_val(cases) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((cases.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
    queue.submit([encoder.finish()]);
    readback.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("map the results"));
    device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let data = readback.slice(..).get_mapped_range().unwrap();
    bytemuck::cast_slice(&data).to_vec()
}

/// The shader's tone map is the CPU's (radiosity_image::tone_map + radiosity_core::srgb_encode, what
/// `render` writes to PNG): every operator, exposures from −8 to +8 EV, radiance from black
/// through mid-tones to far over white, greys and saturated colours. Tolerance 2e-4 on [0, 1]
/// display values: f32 against f64 arithmetic and the GPU's pow/exp approximations, well under
/// half an 8-bit step (2e-3), which is also checked: the 8-bit codes agree within one.
#[test]
fn gpu_tone_map_agrees_with_the_cpu_on_a_table_of_values() {
    let (device, queue) = gpu();
    let colours = [
        Rgb::ZERO,
        Rgb::splat(1e-4),
        Rgb::splat(0.01),
        Rgb::splat(0.18),
        Rgb::splat(0.5),
        Rgb::splat(1.0),
        Rgb::splat(4.0),
        Rgb::splat(100.0),
        Rgb::new(0.8, 0.05, 0.02),
        Rgb::new(0.02, 0.6, 0.05),
        Rgb::new(0.1, 0.2, 3.0),
        Rgb::new(-1.0, 0.3, 0.0),
        Rgb::new(20.8, 10.8, 2.77),
    ];
    let mut table = Vec::new();
    for op in ToneOperator::ALL {
        for ev in [-8.0, -2.5, 0.0, 1.0, 3.0, 8.0] {
            for (k, c) in colours.iter().enumerate() {
                table.push((op, ev, *c, k as f64 / (colours.len() - 1) as f64));
            }
        }
    }
    let cases: Vec<[f32; 8]> = table
        .iter()
        .map(|(op, ev, c, t)| {
            [
                c.r as f32,
                c.g as f32,
                c.b as f32,
                0.0,
                2f64.powf(*ev) as f32,
                shader_operator(*op) as f32,
                *t as f32,
                0.0,
            ]
        })
        .collect();
    let gpu = run_wgsl(&device, &queue, &cases);
    let mut worst = 0.0f64;
    for ((op, ev, c, t), out) in table.iter().zip(&gpu) {
        let cpu = tone_map(*c, &ToneParams::new(*ev, *op)).to_array().map(srgb_encode);
        for ch in 0..3 {
            let d = (f64::from(out[ch]) - cpu[ch]).abs();
            worst = worst.max(d);
            assert!(d < 2e-4, "{op} EV {ev} {c:?} channel {ch}: GPU {} CPU {}", out[ch], cpu[ch]);
            let (g8, c8) = ((f64::from(out[ch]) * 255.0).round(), (cpu[ch] * 255.0).round());
            assert!((g8 - c8).abs() <= 1.0);
        }
        let ramp = false_colour(*t);
        for ch in 0..3 {
            assert!(
                (f64::from(out[4 + ch]) - ramp[ch]).abs() < 1e-4,
                "false colour at {t}: {out:?} vs {ramp:?}"
            );
        }
    }
    eprintln!("{} cases, largest difference {worst:.2e}", table.len());
}

/// Mean sRGB colour of the pixels in the column range `[x0, x1)` of the middle rows.
fn mean_rgb(img: &image::RgbaImage, x0: f64, x1: f64) -> [f64; 3] {
    let (w, h) = img.dimensions();
    let mut sum = [0.0; 3];
    let mut n = 0.0;
    for y in h / 3..2 * h / 3 {
        for x in (x0 * f64::from(w)) as u32..(x1 * f64::from(w)) as u32 {
            let p = img.get_pixel(x, y);
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

/// The Cornell box meshed with `element`-sized elements, its solutions after each of `shots`
/// shots in all (increasing), and its camera.
fn solved_cornell(element: f64, shots: &[u64]) -> (Problem, Vec<Solution>, FlyCamera) {
    let scene = cornell_box();
    let problem = Problem::new(&scene, &MeshParams::try_new(120.0, element).unwrap()).unwrap();
    let mut solver = problem.solver(SolverParams::preview()).unwrap();
    let mut done = 0;
    let solutions = shots
        .iter()
        .map(|&n| {
            solver.step(StepBudget::Shots(n - done));
            done = n;
            solver.solution()
        })
        .collect();
    let (lo, hi) = problem.mesh().bounds();
    let camera = FlyCamera::from_scene_camera(&scene.camera.unwrap(), &SceneExtent::new(lo, hi));
    (problem, solutions, camera)
}

/// The renderer draws the lit box into a headless target: red wall on the left, green on the
/// right, lit but not blown out. The picture is kept in the test's temporary folder.
#[test]
fn offscreen_cornell_shows_red_left_and_green_right() {
    let (device, queue) = gpu();
    let (problem, solutions, camera) = solved_cornell(40.0, &[300]);
    let (mesh, solution) = (problem.mesh(), &solutions[0]);

    let (w, h) = (320u32, 240u32);
    let aspect = f64::from(w) / f64::from(h);
    let ev = 0.0;
    for (mode, wireframe, name) in [
        (DisplayMode::Smooth, Wireframe::Off, "smooth"),
        (DisplayMode::FlatElements, Wireframe::Off, "flat"),
        (DisplayMode::FlatElements, Wireframe::Elements, "flat_wire"),
        (DisplayMode::FalseColour, Wireframe::Patches, "false_colour"),
    ] {
        let mut renderer = SceneRenderer::new(&device, COLOR_FORMAT, 1);
        let target = RenderTarget::new(&device, [w, h], COLOR_FORMAT, 1);
        renderer.set_mesh(&device, mesh);
        renderer.set_solution(&queue, solution, mode);
        let frame = FrameParams {
            clip_from_world: camera.clip_from_view(aspect) * camera.view_from_world(),
            exposure_ev: ev,
            operator: ToneOperator::Aces,
            mode,
            wireframe,
            log_range: radiosity_viewer::render::false_colour_range(solution, mesh, mode),
            background: [0.1, 0.1, 0.1, 1.0],
            textures: true,
        };
        renderer.draw(&device, &queue, &target, &frame);
        let img = target.read_rgba8(&device, &queue).unwrap();
        let path = out_dir().join(format!("offscreen_cornell_{name}.png"));
        img.save(&path).unwrap();
        eprintln!("wrote {}", path.display());
        if wireframe != Wireframe::Off || mode.is_false_colour() {
            continue; // Kept to look at; the statistics are for the lit colours.
        }
        let left = mean_rgb(&img, 0.05, 0.2);
        let right = mean_rgb(&img, 0.8, 0.95);
        let all = mean_rgb(&img, 0.0, 1.0);
        assert!(left[0] > 1.5 * left[1] && left[0] > 40.0, "{name}: red wall on the left: {left:?}");
        assert!(right[1] > 1.5 * right[0] && right[1] > 40.0, "{name}: green wall on the right: {right:?}");
        assert!(all.iter().sum::<f64>() / 3.0 > 30.0, "{name}: not blank: {all:?}");
        let saturated = img.pixels().filter(|p| p[0] == 255 && p[1] == 255 && p[2] == 255).count();
        assert!(saturated < (w * h / 10) as usize, "{name}: {saturated} white pixels");
    }
}

/// The same frame drawn into another kind of target — BGRA, sRGB (the shader then writes
/// linear values and the hardware encodes), 4× multisampled, as a window may be — gives the
/// same picture: the renderer draws into the target it is given.
#[test]
fn any_target_format_gives_the_same_picture() {
    let (device, queue) = gpu();
    let (problem, solutions, camera) = solved_cornell(40.0, &[100]);
    let (mesh, solution) = (problem.mesh(), &solutions[0]);
    let (w, h) = (160u32, 120u32);
    let frame = FrameParams {
        clip_from_world: camera.clip_from_view(f64::from(w) / f64::from(h)) * camera.view_from_world(),
        exposure_ev: 1.0,
        operator: ToneOperator::Reinhard,
        mode: DisplayMode::Smooth,
        wireframe: Wireframe::Off,
        log_range: (0.0, 1.0),
        background: [0.2, 0.3, 0.4, 1.0],
        textures: true,
    };
    let picture = |format, samples| {
        let mut renderer = SceneRenderer::new(&device, format, samples);
        renderer.set_mesh(&device, mesh);
        renderer.set_solution(&queue, solution, DisplayMode::Smooth);
        let target = RenderTarget::new(&device, [w, h], format, samples);
        renderer.draw(&device, &queue, &target, &frame);
        target.read_rgba8(&device, &queue).unwrap()
    };
    let reference = picture(COLOR_FORMAT, 1);
    for (format, samples) in [(wgpu::TextureFormat::Bgra8UnormSrgb, 1), (wgpu::TextureFormat::Bgra8Unorm, 4)]
    {
        let other = picture(format, samples);
        other.save(out_dir().join(format!("format_{format:?}_{samples}.png"))).unwrap();
        // Interior pixels agree within rounding (sRGB round trip); multisampling changes only
        // edge pixels, so compare the mean difference and the share of differing pixels.
        let mut differing = 0;
        let mut total = 0i64;
        for (a, b) in reference.pixels().zip(other.pixels()) {
            let d: i64 = (0..3).map(|c| (i64::from(a[c]) - i64::from(b[c])).abs()).max().unwrap();
            total += d;
            if d > 2 {
                differing += 1;
            }
        }
        let n = i64::from(w * h);
        assert!(differing * 20 < n, "{format:?}×{samples}: {differing} of {n} pixels differ");
        assert!(total < n * 2, "{format:?}×{samples}: mean difference {}", total as f64 / n as f64);
        let (a, b) = (other.get_pixel(0, 0), reference.get_pixel(0, 0));
        assert!((0..3).all(|c| a[c].abs_diff(b[c]) <= 1), "background {a:?} vs {b:?}");
    }
}

/// A mesh over twice the coarse budget gets a coarse copy: drawn, it shows the same walls as
/// the full mesh (region means within a few sRGB levels: it loses only detail smaller than its
/// cells); drawn meanwhile, it leaves the full mesh's colours stale until they are uploaded
/// again, and the full picture then equals a fresh renderer's to the bit.
#[test]
fn the_coarse_copy_shows_the_same_walls_and_full_detail_catches_up() {
    let (device, queue) = gpu();
    let (problem, solutions, camera) = solved_cornell(15.0, &[100, 300]);
    let (mesh, early, late) = (problem.mesh(), &solutions[0], &solutions[1]);

    let (w, h) = (320u32, 240u32);
    let aspect = f64::from(w) / f64::from(h);
    let frame = FrameParams {
        clip_from_world: camera.clip_from_view(aspect) * camera.view_from_world(),
        exposure_ev: 0.0,
        operator: ToneOperator::Aces,
        mode: DisplayMode::Smooth,
        wireframe: Wireframe::Off,
        log_range: (-1.0, 0.0),
        background: [0.1, 0.1, 0.1, 1.0],
        textures: true,
    };
    let target = RenderTarget::new(&device, [w, h], COLOR_FORMAT, 1);
    let draw = |renderer: &SceneRenderer| {
        renderer.draw(&device, &queue, &target, &frame);
        target.read_rgba8(&device, &queue).unwrap()
    };

    let mut fresh = SceneRenderer::new(&device, COLOR_FORMAT, 1);
    fresh.set_mesh(&device, mesh);
    let (full_triangles, none) = fresh.triangle_counts();
    assert_eq!(none, None, "{full_triangles} triangles: under the default budget, no coarse copy");
    fresh.set_solution(&queue, late, DisplayMode::Smooth);
    let full = draw(&fresh);
    full.save(out_dir().join("coarse_cornell_full.png")).unwrap();

    let mut renderer = SceneRenderer::new(&device, COLOR_FORMAT, 1);
    renderer.set_coarse_budget(full_triangles / 8);
    renderer.set_mesh(&device, mesh);
    let coarse_triangles = renderer.triangle_counts().1.expect("a coarse copy");
    assert!(coarse_triangles <= full_triangles / 8, "{coarse_triangles} of {full_triangles}");
    renderer.set_solution(&queue, early, DisplayMode::Smooth);
    renderer.set_coarse(true);
    renderer.set_solution(&queue, late, DisplayMode::Smooth);
    assert!(renderer.full_colours_stale(), "only the coarse copy's colours were uploaded");
    let coarse = draw(&renderer);
    coarse.save(out_dir().join("coarse_cornell.png")).unwrap();
    for (x0, x1, wall) in [(0.05, 0.2, "red wall"), (0.8, 0.95, "green wall"), (0.0, 1.0, "whole view")] {
        let (a, b) = (mean_rgb(&full, x0, x1), mean_rgb(&coarse, x0, x1));
        let worst = (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max);
        assert!(worst < 4.0, "{wall}: full {a:?}, coarse {b:?}");
    }

    renderer.set_coarse(false);
    assert!(renderer.full_colours_stale());
    renderer.set_solution(&queue, late, DisplayMode::Smooth);
    assert!(!renderer.full_colours_stale());
    assert!(draw(&renderer) == full, "full detail after the coarse copy equals a fresh renderer's picture");
}

/// The linear value of an 8-bit sRGB code.
fn linear(code: u8) -> f64 {
    radiosity_core::srgb_decode(f64::from(code) / 255.0)
}

/// Where world point `p` lands in a `size`-pixel picture drawn with `clip_from_world`.
fn pixel_of(clip_from_world: glam::DMat4, p: glam::DVec3, size: u32) -> (f64, f64) {
    let ndc = clip_from_world.project_point3(p);
    ((ndc.x + 1.0) * 0.5 * f64::from(size), (1.0 - ndc.y) * 0.5 * f64::from(size))
}

/// Mean linear colour of the pixels within `radius` of `(x, y)`.
fn mean_linear_around(img: &image::RgbaImage, (x, y): (f64, f64), radius: i64) -> [f64; 3] {
    let mut sum = [0.0; 3];
    let mut n = 0.0;
    for py in y as i64 - radius..=y as i64 + radius {
        for px in x as i64 - radius..=x as i64 + radius {
            let p = img.get_pixel(px as u32, py as u32);
            for c in 0..3 {
                sum[c] += linear(p[c]);
            }
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

/// Two 2 × 2 floor quads side by side at y = 0, facing up: x in [0, 2] with a 2 × 2 texture
/// of red and blue texels (red at u, v < ½ and u, v > ½, factor 0.8, clamped), its mean
/// reflectance their mean, (0.4, 0, 0.4); x in [2, 4] untextured with the same reflectance.
/// Texture coordinates u = x/2, v = z/2 on the textured quad.
fn checker_floor() -> radiosity_core::Scene {
    use radiosity_core::glam::DVec3;
    use radiosity_core::{Material, Object, PolygonMesh, Shape, Sides, Texture, Wrap};
    let (red, blue) = ([255, 0, 0], [0, 0, 255]);
    let texture = Texture {
        width: 2,
        height: 2,
        texels: vec![red, blue, blue, red],
        factor: [0.8; 3],
        wrap: [Wrap::ClampToEdge; 2],
        mask: None,
    };
    let mean = Rgb::new(0.4, 0.0, 0.4);
    let mut textured = Material::try_new("checker", mean, Rgb::ZERO).unwrap();
    textured.texture = Some(std::sync::Arc::new(texture));
    let plain = Material::try_new("plain", mean, Rgb::ZERO).unwrap();
    let quad = |x0: f64, uvs: bool| {
        // Counter-clockwise seen from above: the normal points up, to the camera.
        let corners = [[0.0, 0.0], [0.0, 2.0], [2.0, 2.0], [2.0, 0.0]];
        let positions = corners.iter().map(|&[x, z]| DVec3::new(x0 + x, 0.0, z)).collect();
        let mesh = PolygonMesh::try_new(positions, vec![vec![0, 1, 2, 3]]).unwrap();
        if uvs {
            mesh.with_uvs(vec![corners.iter().map(|&[x, z]| [x / 2.0, z / 2.0]).collect()])
        } else {
            mesh
        }
    };
    let objects = vec![
        Object {
            name: "checker".into(),
            material: 0,
            shape: Shape::Mesh(quad(0.0, true)),
            sides: Sides::One,
        },
        Object { name: "plain".into(), material: 1, shape: Shape::Mesh(quad(2.0, false)), sides: Sides::One },
    ];
    radiosity_core::Scene::try_new_unlit("checker floor", None, vec![textured, plain], objects).unwrap()
}

/// The checker floor drawn with uniform radiosity B = 0.5 everywhere (a made-up solution: the
/// texture's rule is what is tested, not the solve), Linear tone map at 0 EV, so a pixel's
/// linear value is B·ratio/π; with textures on and off.
fn draw_checker_floor(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
) -> (image::RgbaImage, image::RgbaImage, glam::DMat4, u32) {
    let scene = checker_floor();
    let mesh = std::sync::Arc::new(
        radiosity_mesh::Mesh::build(&scene, &MeshParams::try_new(0.5, 0.25).unwrap()).unwrap(),
    );
    let uvs = radiosity_image::element_uvs(&scene, &mesh);
    let b = Rgb::splat(0.5);
    let solution = Solution {
        element_radiosity: vec![b; mesh.elements.len()],
        vertex_radiosity: vec![b; mesh.positions.len()],
        element_direct: Vec::new(),
        vertex_direct: Vec::new(),
        element_unshot: vec![Rgb::ZERO; mesh.elements.len()],
        shots: 0,
        unshot_fraction: 0.0,
    };
    // From 2 above the middle of both quads, 90°: x in [0, 4] fills the square picture.
    let camera = radiosity_core::Camera::try_new(
        glam::DVec3::new(2.0, 2.0, 1.0),
        glam::DVec3::new(2.0, 0.0, 1.0),
        glam::DVec3::Z,
        90.0,
    )
    .unwrap();
    let (lo, hi) = mesh.bounds();
    let camera = FlyCamera::from_scene_camera(&camera, &SceneExtent::new(lo, hi));
    let size = 128;
    let clip_from_world = camera.clip_from_view(1.0) * camera.view_from_world();
    let mut renderer = SceneRenderer::new(device, COLOR_FORMAT, 1);
    renderer.set_textured_mesh(device, queue, &mesh, &uvs);
    assert!(renderer.has_textures());
    renderer.set_solution(queue, &solution, DisplayMode::Smooth);
    let target = RenderTarget::new(device, [size, size], COLOR_FORMAT, 1);
    let draw = |textures| {
        let frame = FrameParams {
            clip_from_world,
            exposure_ev: 0.0,
            operator: ToneOperator::Linear,
            mode: DisplayMode::Smooth,
            wireframe: Wireframe::Off,
            log_range: (-1.0, 0.0),
            background: [0.0, 0.0, 0.0, 1.0],
            textures,
        };
        renderer.draw(device, queue, &target, &frame);
        target.read_rgba8(device, queue).unwrap()
    };
    let (on, off) = (draw(true), draw(false));
    on.save(out_dir().join("checker_floor_textured.png")).unwrap();
    off.save(out_dir().join("checker_floor_plain.png")).unwrap();
    (on, off, clip_from_world, size)
}

/// A textured quad shows its texture: at each quadrant's centre (a texel centre, where
/// bilinear filtering takes nothing of the neighbours) the red texels show B·(0.8/0.4)/π in
/// red and nothing in blue, the blue ones the reverse, and green, whose mean reflectance is 0,
/// B/π unscaled. Tolerance 0.01 in linear value: the 8-bit code's rounding (≤ 0.004 at these
/// levels) plus what the few pixels around the centre take of the next texel.
///
/// Over the whole quad the texture only redistributes the light: the mean of the textured
/// pixels is the untextured colour B/π within 0.01 (filtering is symmetric across the
/// pattern; the margin drops the quad's partly covered edge pixels evenly from every
/// quadrant).
#[test]
fn a_textured_quad_shows_its_texels_and_keeps_its_mean() {
    let (device, queue) = gpu();
    let (on, off, clip_from_world, size) = draw_checker_floor(&device, &queue);
    let shown = 0.5 / std::f64::consts::PI;
    let at = |x: f64, z: f64| pixel_of(clip_from_world, glam::DVec3::new(x, 0.0, z), size);
    for (x, z, red) in [(0.5, 0.5, true), (1.5, 0.5, false), (0.5, 1.5, false), (1.5, 1.5, true)] {
        let got = mean_linear_around(&on, at(x, z), 1);
        let want = if red { [2.0 * shown, shown, 0.0] } else { [0.0, shown, 2.0 * shown] };
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() < 0.01, "quadrant at ({x}, {z}): {got:?}, expected {want:?}");
        }
        let plain = mean_linear_around(&off, at(x, z), 1);
        assert!(plain.iter().all(|v| (v - shown).abs() < 0.01), "textures off at ({x}, {z}): {plain:?}");
    }
    // Every pixel of the textured quad but a 2-pixel margin.
    let (a, b) = (at(0.0, 0.0), at(2.0, 2.0));
    let (x0, x1) = (a.0.min(b.0).ceil() as u32 + 2, a.0.max(b.0).floor() as u32 - 2);
    let (y0, y1) = (a.1.min(b.1).ceil() as u32 + 2, a.1.max(b.1).floor() as u32 - 2);
    let mut sum = [0.0; 3];
    for y in y0..y1 {
        for x in x0..x1 {
            let p = on.get_pixel(x, y);
            for c in 0..3 {
                sum[c] += linear(p[c]);
            }
        }
    }
    let mean = sum.map(|s| s / f64::from((x1 - x0) * (y1 - y0)));
    assert!(mean.iter().all(|v| (v - shown).abs() < 0.01), "mean over the quad {mean:?}, expected {shown}");
}

/// Untextured objects look exactly as before: the untextured quad beside the textured one is
/// the same to the bit with textures on and off, while the textured one changes.
#[test]
fn untextured_objects_are_the_same_with_textures_on_or_off() {
    let (device, queue) = gpu();
    let (on, off, clip_from_world, size) = draw_checker_floor(&device, &queue);
    let at = |x: f64, z: f64| pixel_of(clip_from_world, glam::DVec3::new(x, 0.0, z), size);
    let (mut same, mut differing) = (0, 0);
    for y in 0..size {
        for x in 0..size {
            let (a, b) = (on.get_pixel(x, y), off.get_pixel(x, y));
            let (left, right) = (at(0.0, 1.0).0.min(at(2.0, 1.0).0), at(0.0, 1.0).0.max(at(2.0, 1.0).0));
            let on_checker = f64::from(x) + 1.0 > left && f64::from(x) < right + 1.0;
            if on_checker {
                differing += usize::from(a != b);
            } else {
                assert_eq!(a, b, "pixel ({x}, {y}) off the textured quad");
                same += 1;
            }
        }
    }
    assert!(same > (size * size / 3) as usize, "{same} pixels off the textured quad");
    assert!(differing > (size * size / 8) as usize, "only {differing} pixels of the textured quad changed");
}

/// A scene without textures draws byte-identically with the checkbox on and off, and as a
/// mesh uploaded without texture coordinates at all.
#[test]
fn an_untextured_scene_is_the_same_with_textures_on_or_off() {
    let (device, queue) = gpu();
    let scene = cornell_box();
    let (problem, solutions, camera) = solved_cornell(40.0, &[100]);
    let (mesh, solution) = (problem.mesh(), &solutions[0]);
    let uvs = radiosity_image::element_uvs(&scene, mesh);
    let (w, h) = (160u32, 120u32);
    let target = RenderTarget::new(&device, [w, h], COLOR_FORMAT, 1);
    let picture = |textured_mesh: bool, textures: bool| {
        let mut renderer = SceneRenderer::new(&device, COLOR_FORMAT, 1);
        if textured_mesh {
            renderer.set_textured_mesh(&device, &queue, mesh, &uvs);
        } else {
            renderer.set_mesh(&device, mesh);
        }
        assert!(!renderer.has_textures());
        renderer.set_solution(&queue, solution, DisplayMode::Smooth);
        let frame = FrameParams {
            clip_from_world: camera.clip_from_view(f64::from(w) / f64::from(h)) * camera.view_from_world(),
            exposure_ev: 0.0,
            operator: ToneOperator::Aces,
            mode: DisplayMode::Smooth,
            wireframe: Wireframe::Patches,
            log_range: (-1.0, 0.0),
            background: [0.1, 0.1, 0.1, 1.0],
            textures,
        };
        renderer.draw(&device, &queue, &target, &frame);
        target.read_rgba8(&device, &queue).unwrap()
    };
    let reference = picture(false, false);
    assert!(picture(true, true) == reference, "textures on");
    assert!(picture(true, false) == reference, "textures off");
}

/// The Cornell box with a tiled 8 × 8 checkerboard on its floor (twice over each way), solved, drawn as the window
/// draws it (kept in the test's temporary folder to look at): the floor shows dark and light
/// squares where the plain floor is even, and the walls and the ceiling are the same to the
/// bit with textures on and off.
#[test]
fn the_cornell_box_with_a_checkered_floor() {
    use radiosity_core::{PolygonMesh, Shape, Texture, Wrap};
    let (device, queue) = gpu();
    let mut scene = cornell_box();
    let floor = scene.objects.iter().position(|o| o.name == "floor").expect("a floor");
    let Shape::Polygons(polygons) = &scene.objects[floor].shape else { panic!("the floor is a polygon") };
    let corners = polygons[0].vertices().to_vec();
    // Two repeats of the pattern over the floor: u, v run 0..2.
    let uvs = vec![corners.iter().map(|p| [p.x / 552.8 * 2.0, p.z / 559.2 * 2.0]).collect()];
    let mesh = PolygonMesh::try_new(corners.clone(), vec![(0..corners.len() as u32).collect()]).unwrap();
    scene.objects[floor].shape = Shape::Mesh(mesh.with_uvs(uvs));
    let mut material = scene.materials[scene.objects[floor].material].clone();
    let (light, dark) = ([230, 225, 210], [40, 45, 60]);
    // 8 × 8 squares of 4 × 4 texels each: bilinear filtering blurs only their edges.
    let texels = (0..32 * 32)
        .map(|i: u32| if (i % 32 / 4 + i / 32 / 4).is_multiple_of(2) { light } else { dark })
        .collect();
    material.texture = Some(std::sync::Arc::new(Texture {
        width: 32,
        height: 32,
        texels,
        factor: [1.0; 3],
        wrap: [Wrap::Repeat; 2],
        mask: None,
    }));
    material.name = "checkered floor".into();
    scene.materials.push(material);
    scene.objects[floor].material = scene.materials.len() - 1;

    let problem = Problem::new(&scene, &MeshParams::try_new(120.0, 40.0).unwrap()).unwrap();
    let mut solver = problem.solver(SolverParams::preview()).unwrap();
    solver.step(StepBudget::Shots(300));
    let solution = solver.solution();
    let mesh = problem.mesh();
    let uvs = radiosity_image::element_uvs(&scene, mesh);
    let (lo, hi) = mesh.bounds();
    let camera = FlyCamera::from_scene_camera(&scene.camera.unwrap(), &SceneExtent::new(lo, hi));
    let (w, h) = (480u32, 360u32);
    let mut renderer = SceneRenderer::new(&device, COLOR_FORMAT, 4);
    renderer.set_textured_mesh(&device, &queue, mesh, &uvs);
    assert!(renderer.has_textures());
    renderer.set_solution(&queue, &solution, DisplayMode::Smooth);
    let target = RenderTarget::new(&device, [w, h], COLOR_FORMAT, 4);
    let clip_from_world = camera.clip_from_view(f64::from(w) / f64::from(h)) * camera.view_from_world();
    let draw = |textures| {
        let frame = FrameParams {
            clip_from_world,
            exposure_ev: 0.0,
            operator: ToneOperator::Aces,
            mode: DisplayMode::Smooth,
            wireframe: Wireframe::Off,
            log_range: (-1.0, 0.0),
            background: [0.1, 0.1, 0.1, 1.0],
            textures,
        };
        renderer.draw(&device, &queue, &target, &frame);
        target.read_rgba8(&device, &queue).unwrap()
    };
    let (on, off) = (draw(true), draw(false));
    on.save(out_dir().join("cornell_checkered_floor.png")).unwrap();
    off.save(out_dir().join("cornell_checkered_floor_off.png")).unwrap();
    eprintln!("wrote {}", out_dir().join("cornell_checkered_floor.png").display());
    // Near the bottom, left of the short box, is floor; the top rows are ceiling and walls.
    let luma = |p: &image::Rgba<u8>| f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2]);
    let spread = |img: &image::RgbaImage| {
        let row: Vec<f64> =
            (w * 3 / 10..w * 45 / 100).map(|x| luma(img.get_pixel(x, h * 94 / 100))).collect();
        row.iter().copied().fold(0.0, f64::max) - row.iter().copied().fold(f64::MAX, f64::min)
    };
    eprintln!("spread along a row of floor: {} textured, {} plain", spread(&on), spread(&off));
    // Sums of three sRGB codes: the squares differ by over 80 where the plain floor's light
    // varies by under 40 (measured 114 and 19).
    assert!(spread(&on) > 80.0, "a row of floor textured: spread {}", spread(&on));
    assert!(spread(&off) < 40.0, "a row of plain floor: spread {}", spread(&off));
    for y in 0..h / 4 {
        for x in 0..w {
            assert_eq!(on.get_pixel(x, y), off.get_pixel(x, y), "ceiling pixel ({x}, {y})");
        }
    }
}
