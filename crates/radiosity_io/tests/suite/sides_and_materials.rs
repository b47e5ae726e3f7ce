//! Which faces of an object exchange light (`sides` keys, OBJ's two-sided default, glTF's
//! `doubleSided`, the model override), and what the model loaders make of materials that a
//! diffuse solver cannot show as written: reflectance ≥ 1, mirrors and glass, textures.

use std::path::Path;

use radiosity_core::{Rgb, Sides, srgb_decode};
use radiosity_io::{
    CLAMPED_REFLECTANCE, LoadOptions, ModelFormat, Transform, load_model, load_scene, load_scene_with,
    parse_model, parse_scene,
};

const ONE: Sides = Sides::One;
const TWO: Sides = Sides::Two { emits_back: false };
const TWO_EMITTING: Sides = Sides::Two { emits_back: true };

/// A lamp and a plate; `lamp` and `plate` are extra keys of the materials, `object` of the
/// plate object.
fn scene(lamp: &str, plate: &str, object: &str) -> String {
    format!(
        r#"[[material]]
name = "lamp"
reflectance = [0, 0, 0]
emission = [1, 1, 1]
{lamp}
[[material]]
name = "grey"
reflectance = [0.5, 0.5, 0.5]
{plate}
[[object]]
name = "lamp"
type = "polygon"
material = "lamp"
vertices = [[0, 1, 0], [1, 1, 0], [1, 1, 1]]

[[object]]
name = "plate"
type = "box"
material = "grey"
min = [0, 0, 0]
max = [1, 0.1, 1]
{object}
"#
    )
}

fn sides_of(text: &str) -> Vec<Sides> {
    parse_scene(text, "s.toml").unwrap().scene.objects.iter().map(|o| o.sides).collect()
}

fn error_of(text: &str) -> String {
    parse_scene(text, "s.toml").unwrap_err().to_string()
}

#[test]
fn scene_file_sides_come_from_the_material_and_the_object_overrides_them() {
    assert_eq!(sides_of(&scene("", "", "")), [ONE, ONE]);
    assert_eq!(sides_of(&scene("sides = 2", "sides = 2", "")), [TWO, TWO]);
    assert_eq!(sides_of(&scene("sides = 2\nemission_sides = 2", "sides = 1", "")), [TWO_EMITTING, ONE]);
    // `emission_sides = 1` alone says nothing new.
    assert_eq!(sides_of(&scene("emission_sides = 1", "", "")), [ONE, ONE]);
    assert_eq!(sides_of(&scene("", "sides = 2", "sides = 1")), [ONE, ONE]);
    assert_eq!(sides_of(&scene("", "", "sides = 2")), [ONE, TWO]);
}

#[test]
fn bad_sides_values_are_errors_at_their_line_and_key() {
    // The lamp's extra keys are on line 5, the plate material's on line 8, the object's on 22.
    assert_eq!(
        error_of(&scene("sides = 3", "", "")),
        "s.toml:5:9: material[0].sides: expected 1 (the front face only) or 2 (both faces), got 3"
    );
    assert_eq!(
        error_of(&scene("", "", "sides = 0")),
        "s.toml:22:9: object[1].sides: expected 1 (the front face only) or 2 (both faces), got 0"
    );
    assert_eq!(
        error_of(&scene("emission_sides = 2", "", "")),
        "s.toml:5:18: material[0].emission_sides: emission_sides = 2 needs sides = 2: a one-sided material has no back face to emit from"
    );
    assert_eq!(
        error_of(&scene("sides = 1\nemission_sides = 2", "", "")),
        "s.toml:6:18: material[0].emission_sides: emission_sides = 2 needs sides = 2: a one-sided material has no back face to emit from"
    );
    let e = error_of(&scene("", "emission_sides = -1", ""));
    assert!(e.starts_with("s.toml:9:18: material[1].emission_sides: expected 1"), "{e}");
    let e = error_of(&scene("", "", "sides = \"two\""));
    assert!(e.starts_with("s.toml:22:9: object[1].sides: "), "{e}");
    // A misplaced key names every type's common keys, `sides` among them.
    let e = error_of(&scene("", "", "radius = 1"));
    assert!(e.contains("every type takes name, type, material, sides"), "{e}");
}

const TRIANGLE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) {
    std::fs::write(dir.join(name), bytes).unwrap();
}

#[test]
fn obj_parts_are_two_sided_with_a_front_only_emission() {
    let m =
        parse_model(TRIANGLE_OBJ.as_bytes(), "m.obj", None, ModelFormat::Obj, &Transform::default()).unwrap();
    assert_eq!(m.parts[0].sides, TWO);
}

#[test]
fn mesh_objects_take_the_file_sides_unless_the_scene_or_the_options_say_otherwise() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "m.mtl", "newmtl lamp\nKd 0 0 0\nKe 4 4 4\n");
    write(dir.path(), "m.obj", format!("mtllib m.mtl\nusemtl lamp\n{TRIANGLE_OBJ}"));
    let text = |object: &str| {
        format!(
            "[[material]]\nname = \"emitting\"\nreflectance = [0, 0, 0]\nemission = [1, 1, 1]\nsides = 2\nemission_sides = 2\n\
             [[object]]\nname = \"model\"\ntype = \"mesh\"\nfile = \"m.obj\"\n{object}\n"
        )
    };
    let load = |object: &str, opts: &LoadOptions| {
        let path = dir.path().join("s.toml");
        std::fs::write(&path, text(object)).unwrap();
        load_scene_with(&path, opts).unwrap().scene.objects[0].sides
    };
    let strict = LoadOptions::default();
    assert_eq!(load("", &strict), TWO);
    assert_eq!(load("sides = 1", &strict), ONE);
    // An overriding material that says its sides gives them; the object's key comes after.
    assert_eq!(load("material = \"emitting\"", &strict), TWO_EMITTING);
    assert_eq!(load("material = \"emitting\"\nsides = 1", &strict), ONE);
    // The command line's override comes last.
    let one = LoadOptions { model_sides: Some(ONE), ..LoadOptions::default() };
    let two = LoadOptions { model_sides: Some(TWO), ..LoadOptions::default() };
    assert_eq!(load("", &one), ONE);
    assert_eq!(load("sides = 1", &two), TWO);
    // A back face that already emits keeps emitting.
    assert_eq!(load("material = \"emitting\"", &two), TWO_EMITTING);
    assert_eq!(load("material = \"emitting\"\nsides = 1", &two), TWO);
    // A model as the whole scene too.
    let obj = dir.path().join("m.obj");
    assert_eq!(load_scene(&obj).unwrap().scene.objects[0].sides, TWO);
    assert_eq!(load_scene_with(&obj, &one).unwrap().scene.objects[0].sides, ONE);
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// A glTF of one triangle with `material` as its only material.
fn gltf(material: &str) -> String {
    let positions: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let blob: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"name":"tri","mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}}],
"materials":[{material}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}}],
"buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{}"}}]}}"#,
        base64(&blob)
    )
}

fn gltf_model(material: &str) -> radiosity_io::Model {
    parse_model(gltf(material).as_bytes(), "m.gltf", None, ModelFormat::Gltf, &Transform::default()).unwrap()
}

#[test]
fn gltf_double_sided_materials_emit_from_both_faces() {
    let pbr = r#""pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1],"metallicFactor":0}"#;
    let m = gltf_model(&format!(r#"{{"name":"a",{pbr},"doubleSided":true}}"#));
    assert_eq!(m.parts[0].sides, TWO_EMITTING);
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    let m = gltf_model(&format!(r#"{{"name":"a",{pbr}}}"#));
    assert_eq!(m.parts[0].sides, ONE);
}

#[test]
fn reflectance_of_one_or_more_in_a_model_is_clamped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "m.mtl", "newmtl snow\nKd 1.0 0.9 1.2\n");
    write(dir.path(), "m.obj", format!("mtllib m.mtl\nusemtl snow\n{TRIANGLE_OBJ}"));
    let m = load_model(&dir.path().join("m.obj"), &Transform::default()).unwrap();
    assert_eq!(m.materials[0].reflectance, Rgb::new(CLAMPED_REFLECTANCE, 0.9, CLAMPED_REFLECTANCE));
    let mtl = dir.path().join("m.mtl").display().to_string();
    assert_eq!(
        m.warnings,
        [format!(
            "{mtl}: material 'snow': reflectance [1.0, 0.9, 1.2] has a channel ≥ 1 (light would never stop bouncing); clamped to 0.95"
        )]
    );
    // glTF's default base colour is white.
    let m = gltf_model(r#"{"name":"white","pbrMetallicRoughness":{"metallicFactor":0}}"#);
    assert_eq!(m.materials[0].reflectance, Rgb::splat(CLAMPED_REFLECTANCE));
    assert!(m.warnings.len() == 1 && m.warnings[0].contains("material 'white'"), "{:?}", m.warnings);
    // A scene file keeps its strict rule.
    let e =
        parse_scene(&scene("", "", "").replace("[0.5, 0.5, 0.5]", "[1, 0.5, 0.5]"), "s.toml").unwrap_err();
    assert!(e.to_string().starts_with("s.toml:8:15: material[1].reflectance"), "{e}");
}

#[test]
fn specular_and_transmissive_materials_are_diffuse_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let mtl = "newmtl mirror\nKd 0.5 0.5 0.5\nillum 5\n\
               newmtl chrome\nKd 0.5 0.5 0.5\nKs 0.9 0.9 0.9\nNs 500\n\
               newmtl glass\nKd 0.5 0.5 0.5\nd 0.3\n\
               newmtl paint\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs 250\nd 1\nillum 2\n";
    write(dir.path(), "m.mtl", mtl);
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
               usemtl mirror\nf 1 2 3\nusemtl chrome\nf 2 4 3\nusemtl glass\nf 1 3 2\nusemtl paint\nf 2 3 4\n";
    write(dir.path(), "m.obj", obj);
    let m = load_model(&dir.path().join("m.obj"), &Transform::default()).unwrap();
    let path = dir.path().join("m.mtl").display().to_string();
    assert_eq!(
        m.warnings,
        [
            format!("material 'mirror' ({path}) is specular/transmissive (illum 5); treated as diffuse"),
            format!(
                "material 'chrome' ({path}) is specular/transmissive (Ks 0.9 with Ns 500); treated as diffuse"
            ),
            format!("material 'glass' ({path}) is specular/transmissive (d 0.3); treated as diffuse"),
        ]
    );
    assert!(m.materials.iter().all(|mat| mat.reflectance == Rgb::splat(0.5)));
    let m = gltf_model(r#"{"name":"steel","pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1]}}"#);
    assert_eq!(
        m.warnings,
        ["material 'steel' (m.gltf) is specular/transmissive (metallicFactor 1); treated as diffuse"]
    );
    let m = gltf_model(
        r#"{"name":"pane","pbrMetallicRoughness":{"metallicFactor":0,"baseColorFactor":[0.5,0.5,0.5,1]},"extensions":{"KHR_materials_transmission":{"transmissionFactor":0.9}}}"#,
    );
    assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
    assert!(m.warnings[0].contains("KHR_materials_transmission 0.9"), "{:?}", m.warnings);
}

/// Alpha masks load as the material texture's mask: an MTL `map_d` as its grey value cut at
/// one half (a missing one is a warning and the faces stay solid); glTF's `alphaMode` MASK by
/// `alphaCutoff` (the factor's alpha alone when there is no texture), BLEND as a mask at one
/// half with a warning; an opaque glTF material says nothing and has no mask.
#[test]
fn alpha_masks_load_as_the_textures_mask() {
    let dir = tempfile::tempdir().unwrap();
    image::GrayImage::from_raw(2, 1, vec![255, 20]).unwrap().save(dir.path().join("mask.png")).unwrap();
    write(
        dir.path(),
        "m.mtl",
        "newmtl leaves\nKd 0.3 0.5 0.2\nmap_d mask.png\nnewmtl lost\nKd 0.3 0.5 0.2\nmap_d gone.png\n",
    );
    write(
        dir.path(),
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl leaves\nf 1 2 3\nusemtl lost\nf 1 3 2\n",
    );
    let m = load_model(&dir.path().join("m.obj"), &Transform::default()).unwrap();
    let path = dir.path().join("m.mtl").display().to_string();
    assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
    assert!(
        m.warnings[0].starts_with(&format!("{path}: material 'lost': map_d 'gone.png' not read"))
            && m.warnings[0].ends_with("its faces are solid"),
        "{:?}",
        m.warnings
    );
    let leaves = m.materials.iter().find(|x| x.name == "leaves").unwrap();
    let texture = leaves.texture.as_ref().expect("a mask is carried by a texture");
    assert_eq!(texture.mask.as_deref(), Some(&[true, false][..]));
    // A white carrier: the reflectance is Kd, the texels show Kd.
    assert_eq!(leaves.reflectance, Rgb::new(0.3, 0.5, 0.2));
    assert!(m.materials.iter().find(|x| x.name == "lost").unwrap().texture.is_none());
    // A colour texture and a mask of other sizes meet at the finer, nearest texel.
    image::RgbImage::from_raw(1, 1, vec![200, 100, 50]).unwrap().save(dir.path().join("one.png")).unwrap();
    image::RgbImage::from_raw(4, 2, vec![90; 24]).unwrap().save(dir.path().join("four.png")).unwrap();
    write(
        dir.path(),
        "m.mtl",
        "newmtl coarse\nKd 1 1 1\nmap_Kd one.png\nmap_d mask.png\nnewmtl fine\nKd 1 1 1\nmap_Kd four.png\nmap_d mask.png\n",
    );
    write(
        dir.path(),
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl coarse\nf 1 2 3\nusemtl fine\nf 1 3 2\n",
    );
    let m = load_model(&dir.path().join("m.obj"), &Transform::default()).unwrap();
    let texture = |name: &str| m.materials.iter().find(|x| x.name == name).unwrap().texture.clone().unwrap();
    let coarse = texture("coarse");
    assert_eq!((coarse.width, coarse.height, coarse.mask.as_deref()), (2, 1, Some(&[true, false][..])));
    assert_eq!(coarse.texels, [[200, 100, 50]; 2]);
    let fine = texture("fine");
    let halves = [true, true, false, false, true, true, false, false];
    assert_eq!((fine.width, fine.height, fine.mask.as_deref()), (4, 2, Some(&halves[..])));
    let chain = |alpha: f64| {
        gltf_model(&format!(
            r#"{{"name":"chain","alphaMode":"MASK","alphaCutoff":0.3,"pbrMetallicRoughness":{{"metallicFactor":0,"baseColorFactor":[0.5,0.5,0.5,{alpha}]}}}}"#
        ))
    };
    let m = chain(1.0);
    assert!(m.warnings.is_empty() && m.materials[0].texture.is_none(), "{:?}", m.warnings);
    let m = chain(0.2);
    assert!(m.warnings.is_empty(), "{:?}", m.warnings);
    let mask = m.materials[0].texture.as_ref().and_then(|t| t.mask.clone());
    assert_eq!(mask, Some(vec![false]), "the factor's alpha under the cutoff: nothing there");
    let m = gltf_model(
        r#"{"name":"veil","alphaMode":"BLEND","pbrMetallicRoughness":{"metallicFactor":0,"baseColorFactor":[0.5,0.5,0.5,1]}}"#,
    );
    assert_eq!(
        m.warnings,
        [
            "material 'veil' (m.gltf) is alpha-blended (alphaMode BLEND): treated as a mask (MASK) with alphaCutoff 0.5"
        ]
    );
    let m = gltf_model(
        r#"{"name":"wall","alphaMode":"OPAQUE","pbrMetallicRoughness":{"metallicFactor":0,"baseColorFactor":[0.5,0.5,0.5,1]}}"#,
    );
    assert!(m.warnings.is_empty() && m.materials[0].texture.is_none(), "{:?}", m.warnings);
}

#[test]
fn an_obj_texture_scales_kd_by_its_mean_and_a_missing_one_is_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("maps")).unwrap();
    // sRGB 255 and 0 in red, 188 in green (linear ≈ 0.5029), 0 in blue.
    let pixels = image::RgbImage::from_raw(2, 1, vec![255, 188, 0, 0, 188, 0]).unwrap();
    pixels.save(dir.path().join("maps/t.png")).unwrap();
    write(dir.path(), "maps/broken.png", "not a png");
    // The MTL is in `maps/`: textures are found next to it, not next to the OBJ.
    write(
        dir.path(),
        "maps/m.mtl",
        "newmtl painted\nKd 0.8 0.8 0.8\nmap_Kd t.png\n\
         newmtl lost\nKd 0.4 0.4 0.4\nmap_Kd gone.png\n\
         newmtl broken\nKd 0.3 0.3 0.3\nmap_Kd broken.png\n",
    );
    write(
        dir.path(),
        "m.obj",
        "mtllib maps/m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
         usemtl painted\nf 1 2 3\nusemtl lost\nf 2 4 3\nusemtl broken\nf 1 3 2\n",
    );
    let m = load_model(&dir.path().join("m.obj"), &Transform::default()).unwrap();
    let green = srgb_decode(188.0 / 255.0);
    let rho = m.materials[0].reflectance;
    assert!((rho - Rgb::new(0.8 * 0.5, 0.8 * green, 0.0)).max_channel().abs() < 1e-9, "{rho:?}");
    assert_eq!(m.materials[1].reflectance, Rgb::splat(0.4));
    assert_eq!(m.materials[2].reflectance, Rgb::splat(0.3));
    let mtl = dir.path().join("maps/m.mtl").display().to_string();
    assert_eq!(m.warnings.len(), 2, "{:?}", m.warnings);
    assert!(
        m.warnings[0].starts_with(&format!("{mtl}: material 'lost': texture 'gone.png' not read (")),
        "{:?}",
        m.warnings
    );
    assert!(m.warnings[0].ends_with("); Kd alone used"), "{:?}", m.warnings);
    assert!(
        m.warnings[1].starts_with(&format!("{mtl}: material 'broken': texture 'broken.png' not read (")),
        "{:?}",
        m.warnings
    );
}

#[test]
fn a_scene_without_light_loads_only_when_allowed() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "m.obj", format!("mtllib gone.mtl\n{TRIANGLE_OBJ}"));
    let path = dir.path().join("m.obj");
    let strict = load_scene(&path).unwrap_err().to_string();
    assert!(strict.contains("the scene has no light") && strict.contains("(warning: "), "{strict}");
    let allowed = LoadOptions { allow_no_light: true, ..LoadOptions::default() };
    let loaded = load_scene_with(&path, &allowed).unwrap();
    assert_eq!(loaded.scene.objects.len(), 1);
    assert!(loaded.warnings.iter().any(|w| w.contains("gone.mtl")), "{:?}", loaded.warnings);
    // The same error, without the warnings that the caller prints first.
    let e = loaded.no_light.unwrap().to_string();
    assert!(e.contains("the scene has no light") && !e.contains("(warning: "), "{e}");
    // A scene file: the error at its place, as a strict load gives it.
    let text = scene("", "", "").replace("emission = [1, 1, 1]", "");
    let loaded = radiosity_io::parse_scene_with(&text, "s.toml", &allowed).unwrap();
    assert_eq!(loaded.no_light.unwrap(), parse_scene(&text, "s.toml").unwrap_err());
    // A lit scene has nothing to say.
    assert!(
        radiosity_io::parse_scene_with(&scene("", "", ""), "s.toml", &allowed).unwrap().no_light.is_none()
    );
}

/// A face repeated in another group (as McGuire's Cornell boxes repeat a block side as its
/// "bottom face") is dropped with a warning, from any starting corner; the same corners
/// facing the other way (a thin sheet modelled back to back) are kept.
#[test]
fn duplicate_faces_are_dropped_with_a_warning() {
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
               o block\nf 1 2 3 4\n\
               o bottom\nf 3 4 1 2\n\
               o sheet_back\nf 4 3 2 1\n";
    let model =
        parse_model(obj.as_bytes(), "dup.obj", None, ModelFormat::Obj, &Transform::default()).unwrap();
    let names: Vec<&str> = model.parts.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["block", "sheet_back"], "the repeated face's part is emptied and removed");
    let warning = model.warnings.iter().find(|w| w.contains("duplicate")).expect("a warning");
    assert!(warning.starts_with("dup.obj: 1 duplicate face"), "{warning}");
    let single = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    let clean =
        parse_model(single.as_bytes(), "one.obj", None, ModelFormat::Obj, &Transform::default()).unwrap();
    assert!(clean.warnings.iter().all(|w| !w.contains("duplicate")), "{:?}", clean.warnings);
}

/// A lit sphere and a `[mesh]` table that ends on line 13, for keys appended on line 14.
const SPHERE_WITH_MESH: &str = "[[material]]\nname = \"l\"\nreflectance = [0, 0, 0]\nemission = [1, 1, 1]\n\
    [[object]]\nname = \"o\"\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"l\"\n\
    [mesh]\npatch_size = 1\nelement_size = 0.5\n";

/// `[mesh] crease_angle` sets the smoothing limit; outside [0, 180) it is an error at its line.
#[test]
fn the_crease_angle_comes_from_the_mesh_table() {
    let base = SPHERE_WITH_MESH;
    let scene = parse_scene(&format!("{base}crease_angle = 15\n"), "c.toml").unwrap().scene;
    assert_eq!(scene.mesh.unwrap().crease_angle_deg, 15.0);
    let default = parse_scene(base, "d.toml").unwrap().scene;
    assert_eq!(default.mesh.unwrap().crease_angle_deg, radiosity_core::DEFAULT_CREASE_ANGLE_DEG);
    let err = parse_scene(&format!("{base}crease_angle = 180\n"), "e.toml").unwrap_err().to_string();
    assert!(err.starts_with("e.toml:14:") && err.contains("mesh.crease_angle"), "{err}");
}

/// `[mesh] corner_refinement` sets the grading towards inside corners,
/// `proximity_refinement` the refinement near other geometry, `adaptive_levels` the adaptive
/// subdivision; past 6, 4 and 4 they are errors at their lines. `shadow_outlines` turns
/// the shadow outlines off (on by default) and takes only a boolean.
#[test]
fn the_corner_refinement_comes_from_the_mesh_table() {
    let base = SPHERE_WITH_MESH;
    let scene = parse_scene(&format!("{base}corner_refinement = 0\n"), "c.toml").unwrap().scene;
    assert_eq!(scene.mesh.unwrap().corner_refinement, 0);
    let default = parse_scene(base, "d.toml").unwrap().scene;
    assert_eq!(default.mesh.unwrap().corner_refinement, radiosity_core::DEFAULT_CORNER_REFINEMENT);
    let err = parse_scene(&format!("{base}corner_refinement = 7\n"), "e.toml").unwrap_err().to_string();
    assert!(err.starts_with("e.toml:14:") && err.contains("mesh.corner_refinement"), "{err}");
    let err = parse_scene(&format!("{base}corner_refinement = -1\n"), "n.toml").unwrap_err().to_string();
    assert!(err.starts_with("n.toml:14:"), "{err}");
    let scene = parse_scene(&format!("{base}adaptive_levels = 1\n"), "a.toml").unwrap().scene;
    assert_eq!(scene.mesh.unwrap().adaptive_levels, 1);
    assert_eq!(default.mesh.unwrap().adaptive_levels, radiosity_core::DEFAULT_ADAPTIVE_LEVELS);
    let scene = parse_scene(&format!("{base}proximity_refinement = 2\n"), "p.toml").unwrap().scene;
    assert_eq!(scene.mesh.unwrap().proximity_refinement, 2);
    assert_eq!(default.mesh.unwrap().proximity_refinement, radiosity_core::DEFAULT_PROXIMITY_REFINEMENT);
    let err = parse_scene(&format!("{base}proximity_refinement = 5\n"), "q.toml").unwrap_err().to_string();
    assert!(err.starts_with("q.toml:14:") && err.contains("mesh.proximity_refinement"), "{err}");
    let err = parse_scene(&format!("{base}adaptive_levels = 5\n"), "b.toml").unwrap_err().to_string();
    assert!(err.starts_with("b.toml:14:") && err.contains("mesh.adaptive_levels"), "{err}");
    assert!(default.mesh.unwrap().shadow_outlines);
    let scene = parse_scene(&format!("{base}shadow_outlines = false\n"), "s.toml").unwrap().scene;
    assert!(!scene.mesh.unwrap().shadow_outlines);
    let err = parse_scene(&format!("{base}shadow_outlines = 2\n"), "t.toml").unwrap_err().to_string();
    assert!(err.starts_with("t.toml:") && err.contains("shadow_outlines"), "{err}");
}
