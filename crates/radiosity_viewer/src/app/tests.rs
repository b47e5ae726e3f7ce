//! The window driven by egui_kittest: real egui frames, real wgpu (lavapipe on CI), input
//! injected as events. Rendering goes through the P screenshot path (an offscreen target),
//! since the harness's own pass has no depth buffer for the paint callback.

use super::*;
use eframe::egui::Key;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use radiosity_core::MeshParams;
use radiosity_image::Gather;
use radiosity_solver::SolverParams;

const LONG: Duration = Duration::from_secs(60);

fn harness(scene: &str, shots: Option<u64>, dir: &std::path::Path) -> Harness<'static, ViewerApp> {
    let mut options = ViewerOptions::new(radiosity_io::resolve_scene(scene).unwrap().scene, scene);
    options.samples = 1;
    options.threads = Some(1);
    options.screenshot_dir = dir.to_owned();
    options.solver_params = SolverParams { max_shots: shots, ..SolverParams::preview() };
    window(options)
}

/// The app in a 1000 × 640 harness on a wgpu renderer of its own. Driven through
/// [`ViewerApp::frame`] rather than as an eframe app: eframe under the harness turns on the
/// desktop accessibility bridge (a D-Bus stack that was a quarter of a cold test build), which
/// no test here reads.
fn window(options: ViewerOptions) -> Harness<'static, ViewerApp> {
    let render_state = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        egui_wgpu::RendererOptions::PREDICTABLE,
    );
    let app = ViewerApp::with_render_state(render_state.clone(), None, options, Arc::default());
    Harness::builder()
        .with_size(Vec2::new(1000.0, 640.0))
        .renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(render_state))
        .build_ui_state(|ui, app: &mut ViewerApp| app.frame(ui), app)
}

/// Steps frames (sleeping between them, since the worker and loader run in real time)
/// until `done` holds.
fn step_until(h: &mut Harness<'static, ViewerApp>, what: &str, done: impl Fn(&ViewerApp) -> bool) {
    let start = Instant::now();
    while !done(h.state()) {
        assert!(start.elapsed() < LONG, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiosity-viewer-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn keys_drag_and_wheel_fly_the_camera() {
    let dir = temp_dir("keys");
    let mut h = harness("cornell", Some(5), &dir);
    step_until(&mut h, "the first solution", |a| a.shown.is_some());
    let start = h.state().view.camera;
    let centre = Pos2::new(350.0, 320.0);
    h.hover_at(centre);
    h.key_down(Key::W);
    for _ in 0..5 {
        std::thread::sleep(Duration::from_millis(10));
        h.step();
    }
    h.key_up(Key::W);
    h.step();
    let moved = h.state().view.camera.position - start.position;
    assert!(moved.dot(start.forward()) > 0.0 && moved.length() > 0.0, "W flies forward: {moved}");
    assert!(moved.cross(start.forward()).length() < 1e-6 * moved.length().max(1.0), "straight ahead");

    // Drag to the right: look right.
    h.drag_at(centre);
    h.step();
    for k in 1..=5 {
        h.hover_at(centre + Vec2::new(20.0 * k as f32, 0.0));
        h.step();
    }
    h.drop_at(centre + Vec2::new(100.0, 0.0));
    h.step();
    assert!(h.state().view.camera.forward().dot(start.right()) > 0.1, "dragging right looks right");

    // Wheel up: faster.
    h.hover_at(centre);
    h.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: Vec2::new(0.0, 100.0),
        phase: egui::TouchPhase::Move,
        modifiers: egui::Modifiers::NONE,
        source: egui::MouseWheelSource::Wheel,
    });
    h.run_steps(10);
    assert!(h.state().view.camera.speed > start.speed, "the wheel speeds up");

    // R: back to the scene camera; F: frame it all.
    h.key_press(Key::R);
    h.step();
    assert_eq!(h.state().view.camera.position, start.position);
    assert_eq!(h.state().view.camera.forward(), start.forward());
    h.key_press(Key::F);
    h.step();
    assert_ne!(h.state().view.camera.position, start.position, "F frames the whole box");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn panel_buttons_pause_step_and_restart_the_solve() {
    let dir = temp_dir("buttons");
    let mut h = harness("cornell", None, &dir);
    step_until(&mut h, "some shots", |a| a.status.progress.shots >= 3);
    h.get_by_label("Pause").click();
    step_until(&mut h, "the pause", |a| a.status.state == WorkerState::Paused);
    let shots = h.state().status.progress.shots;
    h.get_by_label("Step").click();
    step_until(&mut h, "one more shot", |a| a.status.progress.shots == shots + 1);
    h.get_by_label("Restart").click();
    step_until(&mut h, "the restart", |a| a.status.generation == 2);
    assert_eq!(h.state().status.progress.shots, 0);
    assert_eq!(h.state().status.state, WorkerState::Paused, "restart keeps the pause");
    h.get_by_label("Resume").click();
    step_until(&mut h, "shots again", |a| a.status.progress.shots > 0);
    let _ = std::fs::remove_dir_all(dir);
}

/// The subdivision sliders change sizes and adaptive levels only: the contacts and crease
/// angle the command line chose stay.
#[test]
fn subdivision_sliders_keep_the_other_mesh_settings() {
    let dir = temp_dir("sliders");
    let mut options = ViewerOptions::new(radiosity_io::resolve_scene("cornell").unwrap().scene, "cornell");
    options.threads = Some(1);
    options.screenshot_dir = dir.clone();
    options.solver_params = SolverParams { max_shots: Some(2), ..SolverParams::preview() };
    let chosen = MeshParams::try_new(140.0, 70.0)
        .unwrap()
        .with_contacts(false)
        .with_crease_angle(10.0)
        .and_then(|m| m.with_adaptive_levels(1))
        .unwrap();
    options.mesh_params = Some(chosen);
    let mut h = window(options);
    assert_eq!(h.state().subdivision.adaptive_levels, 1);
    h.state_mut().subdivision.element_size = 35.0;
    h.state_mut().subdivision.adaptive_levels = 0;
    h.state_mut().apply_subdivision();
    let m = h.state().job.mesh_params;
    assert_eq!((m.patch_size, m.element_size, m.adaptive_levels), (140.0, 35.0, 0));
    assert!(!m.contacts && m.crease_angle_deg == 10.0, "{m:?}");
    let _ = std::fs::remove_dir_all(dir);
}

#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &std::path::Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn a_bad_file_shows_its_error_and_the_old_scene_stays_then_a_dropped_one_opens() {
    let dir = temp_dir("open");
    let mut h = harness("cornell", Some(20), &dir);
    step_until(&mut h, "the first solution", |a| a.shown.is_some());
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[[material]]\nname = \"m\"\nreflectance = [2, 0, 0]\n").unwrap();
    h.state_mut().open_text = bad.display().to_string();
    h.get_by_label("Open").click();
    step_until(&mut h, "the load error", |a| a.load_error.is_some());
    let expected = crate::load_scene(&bad.display().to_string()).unwrap_err();
    assert_eq!(h.state().load_error.as_deref(), Some(expected.as_str()));
    h.step();
    assert!(h.query_all_by_label_contains(&expected).next().is_some(), "the panel shows: error: {expected}");
    assert_eq!(h.state().shown.as_ref().unwrap().job.scene.name, "Cornell box", "the old scene stays");

    // Dropping a good file opens it (and the camera moves to it).
    let good = dir.join("furnace.toml");
    std::fs::write(
        &good,
        "name = \"Dropped furnace\"\n[[material]]\nname = \"m\"\nreflectance = [0.5, 0.5, 0.5]\n\
         emission = [1, 1, 1]\n[[object]]\nname = \"box\"\ntype = \"box\"\nmin = [0, 0, 0]\n\
         max = [1, 1, 1]\nnormals = \"inward\"\nmaterial = \"m\"\n",
    )
    .unwrap();
    h.input_mut().dropped_files.push(Arc::new(Dropped(good.clone())));
    step_until(&mut h, "the dropped scene", |a| {
        a.shown.as_ref().is_some_and(|s| s.job.scene.name == "Dropped furnace")
    });
    assert!(h.state().load_error.is_none());
    assert!(h.state().extent.diagonal() < 2.0, "the camera works at the new scene's scale");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn p_writes_the_view_with_red_left_and_green_right() {
    let dir = temp_dir("p");
    let mut h = harness("cornell", Some(100), &dir);
    step_until(&mut h, "100 shots on screen", |a| a.shown.as_ref().is_some_and(|s| s.solution.shots == 100));
    h.key_press(Key::P);
    h.step();
    let path = dir.join("cornell-box-100shots.png");
    let message = h.state().message.clone().unwrap_or_default();
    assert!(path.exists(), "{message}");
    let img = image::open(&path).unwrap().to_rgb8();
    let [w, h_px] = h.state().view_size;
    assert_eq!(img.dimensions(), (w, h_px), "the view's size, without the panel");
    let mean = |x0: f32, x1: f32| {
        let (mut sum, mut n) = ([0.0; 3], 0.0);
        for y in h_px / 3..2 * h_px / 3 {
            for x in (x0 * w as f32) as u32..(x1 * w as f32) as u32 {
                let p = img.get_pixel(x, y);
                for c in 0..3 {
                    sum[c] += f64::from(p[c]);
                }
                n += 1.0;
            }
        }
        sum.map(|s| s / n)
    };
    let (left, right) = (mean(0.12, 0.22), mean(0.78, 0.88));
    assert!(left[0] > 2.0 * left[1], "red on the left: {left:?}");
    assert!(right[1] > 1.5 * right[0], "green on the right: {right:?}");
    // A second P never overwrites the first.
    h.key_press(Key::P);
    h.step();
    assert!(dir.join("cornell-box-100shots-2.png").exists());
    let _ = std::fs::remove_dir_all(dir);
}

/// G renders the view with a gather in the background; the still arrives in its window
/// with the view's aspect, red on the left and green on the right, and Save writes it.
#[test]
fn g_renders_a_still_in_the_background_and_save_writes_it() {
    let dir = temp_dir("still");
    let mut h = harness("cornell", Some(100), &dir);
    step_until(&mut h, "100 shots on screen", |a| a.shown.as_ref().is_some_and(|s| s.solution.shots == 100));
    h.key_press(Key::G);
    h.step();
    assert!(h.state().still_job.is_some(), "G starts a still");
    step_until(&mut h, "the still", |a| a.still.is_some());
    let message = h.state().message.clone().unwrap_or_default();
    assert!(message.starts_with("still rendered"), "{message}");
    let (still, _, srgb) = h.state().still.as_ref().unwrap();
    assert_eq!(still.gather, Gather::Direct);
    let [w, h_px] = h.state().view_size;
    let aspect = f64::from(srgb.width) / f64::from(srgb.height);
    assert!((aspect - f64::from(w) / f64::from(h_px)).abs() < 0.01, "aspect {aspect}");
    let px = |x: u32, y: u32| srgb.pixels[(y * srgb.width + x) as usize];
    let (left, right) =
        (px(srgb.width * 17 / 100, srgb.height / 2), px(srgb.width * 83 / 100, srgb.height / 2));
    assert!(left[0] > 2 * left[1], "red on the left: {left:?}");
    assert!(right[1] > right[0], "green on the right: {right:?}");
    // A new window lays itself out unseen on its first frame.
    h.step();
    h.step();
    h.get_by_label("Save PNG").click();
    h.step();
    assert!(dir.join("still.png").exists(), "{:?}", h.state().message);
    let _ = std::fs::remove_dir_all(dir);
}

/// A 4 × 4 floor tiled twice each way with an 8 × 8 black and white checkerboard, lit by a
/// lamp 2 above its middle, as an OBJ with its MTL and PNG in `dir`; returns the OBJ's path.
fn write_checkered_room(dir: &std::path::Path) -> String {
    let texels =
        (0..64).map(|i: u32| if (i % 8 + i / 8).is_multiple_of(2) { [250; 3] } else { [10; 3] }).collect();
    radiosity_image::write_png(&dir.join("tiles.png"), &SrgbImage { width: 8, height: 8, pixels: texels })
        .unwrap();
    std::fs::write(
        dir.join("tiled.mtl"),
        "newmtl tiles\nKd 0.6 0.6 0.6\nmap_Kd tiles.png\nnewmtl light\nKd 0 0 0\nKe 5 5 5\n",
    )
    .unwrap();
    // The floor's corners run so its normal points up; the lamp's, reversed, so it faces down.
    let corners = [[0.0, 0.0], [0.0, 4.0], [4.0, 4.0], [4.0, 0.0]];
    let mut obj = String::from("mtllib tiled.mtl\no tiles\n");
    for [x, z] in corners {
        obj += &format!("v {x} 0 {z}\nvt {} {}\n", x / 2.0, z / 2.0);
    }
    obj += "usemtl tiles\nf 1/1 2/2 3/3 4/4\no light\n";
    for [x, z] in corners.iter().rev() {
        obj += &format!("v {} 2 {}\n", 1.5 + x / 4.0, 1.5 + z / 4.0);
    }
    obj += "usemtl light\nf 5 6 7 8\n";
    let path = dir.join("tiled.obj");
    std::fs::write(&path, obj).unwrap();
    path.to_string_lossy().into_owned()
}

/// A scene with a texture opens with the textures checkbox on and shows the texture, in the
/// view and in a still; turned off, the view shows the floor's mean colour instead. The Cornell box, which has none,
/// starts with it off.
#[test]
fn the_textures_checkbox_starts_on_for_a_textured_scene_and_turns_them_off() {
    let dir = temp_dir("textures");
    let room = write_checkered_room(&dir);
    let mut h = harness(&room, Some(20), &dir);
    step_until(&mut h, "20 shots on screen", |a| a.shown.as_ref().is_some_and(|s| s.solution.shots == 20));
    assert!(h.state().view.textures, "on for a scene with a texture");
    let textured = {
        let renderer = h.state().render_state.renderer.read();
        renderer.callback_resources.get::<SceneRenderer>().is_some_and(SceneRenderer::has_textures)
    };
    assert!(textured, "the floor is drawn textured");
    // Distinct grey levels in the view: a checkerboard, filtered, has many more than the
    // evenly lit plain floor.
    let levels = |h: &mut Harness<'static, ViewerApp>, name: &str| {
        h.key_press(Key::P);
        h.step();
        let path = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.file_name().is_some_and(|n| n.to_string_lossy().ends_with(&format!("{name}.png"))))
            .unwrap_or_else(|| panic!("no screenshot: {:?}", h.state().message));
        let img = image::open(&path).unwrap().to_rgb8();
        std::fs::remove_file(path).unwrap();
        img.pixels().map(|p| p[0]).collect::<std::collections::BTreeSet<u8>>().len()
    };
    let on = levels(&mut h, "20shots");
    // The still (G) shows the texture too.
    h.key_press(Key::G);
    h.step();
    step_until(&mut h, "the still", |a| a.still.is_some());
    let (_, _, srgb) = h.state().still.as_ref().unwrap();
    let still_levels = srgb.pixels.iter().map(|p| p[0]).collect::<std::collections::BTreeSet<u8>>().len();
    assert!(still_levels > 50, "the still shows the texture: {still_levels} red levels");
    h.get_by_label("textures").click();
    h.step();
    assert!(!h.state().view.textures);
    let off = levels(&mut h, "20shots");
    // The view's count depends on the frame the capture lands on (188 here, 37 once on a
    // loaded machine); a flat floor gives 2, so 25 still tells a texture from none.
    assert!(on > 25 && off < 10, "textures on: {on} red levels in the view; off: {off}");

    let cornell = harness("cornell", Some(5), &dir);
    assert!(!cornell.state().view.textures, "off for a scene without textures");
    let _ = std::fs::remove_dir_all(dir);
}

/// The illuminance mode of a photometric scene (the office, in metres) reads in lux: 683 lx
/// per W/m², and the brightest light arriving after 200 shots is that of the floor and walls
/// under six 3 000 lm downlights (hundreds of lux, not thousands nor tens).
#[test]
fn the_illuminance_mode_reads_lux_in_a_photometric_scene() {
    let dir = temp_dir("lux");
    let office = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/photometry/office.toml");
    let mut h = harness(office, Some(200), &dir);
    h.get_by_label("illuminance").click();
    step_until(&mut h, "200 shots on screen", |a| a.shown.as_ref().is_some_and(|s| s.solution.shots == 200));
    h.step();
    let app = h.state();
    assert_eq!(app.view.mode, DisplayMode::Illuminance);
    assert_eq!(app.lux_per_irradiance, Some(683.0));
    let top = 10f64.powf(app.log_range.1) * 683.0;
    assert!((200.0..2000.0).contains(&top), "brightest {top} lx");
    let mut cornell = harness("cornell", Some(5), &dir);
    step_until(&mut cornell, "the box on screen", |a| a.shown.is_some());
    assert_eq!(cornell.state().lux_per_irradiance, None, "no units: no lux");
    let _ = std::fs::remove_dir_all(dir);
}
