//! Models nobody here made, used as a new user would: no flags, no camera, whatever quirks the
//! files have. McGuire's original Cornell box (OBJ/MTL, two-sided by default, a repeated face,
//! comments after colours) and Khronos' RiggedSimple (glTF, no light of its own: alone it can
//! only be described; in `lit.toml` it stands in a lit room). Sources and licences are in the
//! README beside each model.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn radiosity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).output().expect("run radiosity")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn model(path: &str) -> String {
    let p: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/models").join(path);
    p.to_str().unwrap().to_owned()
}

/// `solve --json -`'s objects as (name, front radiosity, back radiosity if two-sided).
fn objects(o: &Output) -> Vec<(String, [f64; 3], Option<[f64; 3]>)> {
    assert!(o.status.success(), "{}", stderr(o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rgb = |v: &serde_json::Value| -> [f64; 3] { std::array::from_fn(|i| v[i].as_f64().unwrap()) };
    report["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| {
            let back = o.get("radiosity_back").filter(|b| !b.is_null()).map(rgb);
            (o["name"].as_str().unwrap().to_owned(), rgb(&o["radiosity"]), back)
        })
        .collect()
}

/// Luminance-ish mean of an 8-bit picture's channels, and the share of pixels darker than
/// 3/255 in every channel.
fn picture_stats(path: &Path) -> (f64, f64) {
    let img = radiosity_image::read_png(path).unwrap_or_else(|e| panic!("{e}"));
    let n = img.pixels.len() as f64;
    let mean = img.pixels.iter().map(|p| p.iter().map(|&c| f64::from(c)).sum::<f64>() / 3.0).sum::<f64>() / n;
    let black = img.pixels.iter().filter(|p| p.iter().all(|&c| c < 3)).count() as f64 / n;
    (mean, black)
}

/// Every wall, the boxes and the floor of McGuire's box get light on the side that faces into
/// the box, and its repeated "bottom" faces are reported once each and dropped. The outsides
/// of the walls (two-sided, as OBJ loads by default) see nothing lit: their back radiosity is
/// zero, which is why the default camera must not look at them.
#[test]
fn mcguires_cornell_box_obj_lights_every_surface_with_no_flags() {
    let obj = model("cornell-box-mcguire/CornellBox-Original.obj");
    let o = radiosity(&["solve", &obj, "--json", "-"]);
    let err = stderr(&o);
    let objects = objects(&o);
    assert!(err.contains("2 duplicate face(s) dropped"), "the repeated box faces are reported: {err}");
    assert!(!err.contains("no light"), "{err}");
    let luminance = |c: [f64; 3]| (c[0] + c[1] + c[2]) / 3.0;
    let floor = objects.iter().find(|o| o.0 == "floor").expect("a floor object").1;
    for (name, front, back) in &objects {
        if name == "light" {
            continue;
        }
        // Each surface faces the lamp or a lit wall: the dimmest (a box's face towards the
        // back wall) is still well above 5 % of the floor, which is directly under the lamp.
        assert!(luminance(*front) > 0.05 * luminance(floor), "{name} is dark: {front:?} (floor {floor:?})");
        assert!(back.is_some(), "{name}: OBJ faces are two-sided by default");
    }
    // The walls' outsides: nothing outside the box emits or reflects.
    for wall in ["backWall", "leftWall", "rightWall"] {
        // The file's `g` lines follow their faces' vertices, so its parts are named by the
        // group and material in force where their faces are ("leftWall/leftWall").
        let back = objects
            .iter()
            .find(|o| o.0.starts_with(wall))
            .unwrap_or_else(|| panic!("{wall} in {objects:?}"))
            .2;
        assert_eq!(back.map(luminance), Some(0.0), "{wall}");
    }
}

/// `render` with nothing but an output name: the default camera looks into the open box (not
/// at the back of its back wall), the picture is mostly lit, and no warning about a dark view
/// is printed.
#[test]
fn mcguires_cornell_box_renders_from_its_open_side() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("box.png");
    let obj = model("cornell-box-mcguire/CornellBox-Original.obj");
    let o = radiosity(&["render", &obj, "-o", png.to_str().unwrap(), "--width", "96", "--height", "72"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("lit face"), "{}", stderr(&o));
    let (mean, black) = picture_stats(&png);
    // Seen from the open side the box fills most of the frame; around it is the black
    // background. From behind (the old default) the picture was 100 % black.
    assert!(black < 0.4, "{:.0} % black pixels", black * 100.0);
    assert!(mean > 40.0, "mean pixel value {mean:.1}");
}

/// The glTF alone has no light: `info` describes it with a warning instead of refusing it,
/// `solve` refuses it with one line naming the missing light.
#[test]
fn rigged_simple_without_light_is_described_and_refused_to_solve() {
    let gltf = model("rigged-simple/RiggedSimple.gltf");
    let info = radiosity(&["info", &gltf]);
    assert!(info.status.success(), "{}", stderr(&info));
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(text.contains("no light"), "{text}");
    let solve = radiosity(&["solve", &gltf]);
    assert_eq!(solve.status.code(), Some(2), "{}", stderr(&solve));
    assert!(stderr(&solve).contains("light"), "{}", stderr(&solve));
}

/// The cylinder placed in a lit room by a scene file: it receives light in every channel, and
/// the picture from the scene's camera is lit everywhere. (Its smooth shading across facets is
/// measured on a tessellated sphere in `radiosity_image`'s render tests.)
#[test]
fn rigged_simple_in_a_lit_room_is_lit() {
    let scene = model("rigged-simple/lit.toml");
    let o = radiosity(&["solve", &scene, "--json", "-"]);
    let objects = objects(&o);
    let cylinder = objects.iter().find(|o| o.0.starts_with("cylinder")).expect("the model's object");
    assert!(cylinder.1.iter().all(|&c| c > 0.0), "{cylinder:?}");
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("room.png");
    let o = radiosity(&["render", &scene, "-o", png.to_str().unwrap(), "--width", "160", "--height", "120"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (mean, black) = picture_stats(&png);
    assert!(black < 0.01 && mean > 40.0, "{:.1} % black, mean {mean:.1}", black * 100.0);
}
