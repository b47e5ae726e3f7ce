//! `radiosity export` end to end: model files in, lit glTF / GLB / PLY and lightmaps out; the
//! Khronos glTF validator finds no error in what we write; bad input is one line, exit code 2.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn radiosity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).output().expect("run radiosity")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the Khronos glTF validator (`scripts/gltf-validator/validate.mjs`) on `files`.
///
/// Never a silent skip: without node or the npm package the test fails under CI (`CI` set,
/// where `setup.sh` installs both), and elsewhere says loudly what it did not check and how
/// to install it.
fn validate(files: &[&Path]) {
    let script = root().join("scripts/gltf-validator/validate.mjs");
    let Some(node) = node_package("gltf-validator", "gltf-validator") else { return };
    let mut cmd = Command::new(node);
    cmd.arg(&script).args(files);
    let o = cmd.output().expect("run node");
    let out = String::from_utf8_lossy(&o.stdout);
    eprintln!("{out}{}", stderr(&o));
    assert!(o.status.success(), "the glTF validator reports errors:\n{out}{}", stderr(&o));
    assert_eq!(out.matches(": 0 errors").count(), files.len(), "{out}");
}

/// The GLB's JSON chunk.
fn glb_json(bytes: &[u8]) -> serde_json::Value {
    assert_eq!(&bytes[..4], b"glTF");
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(&bytes[16..20], b"JSON");
    serde_json::from_slice(&bytes[20..20 + len]).unwrap()
}

/// Vertices written: the sum of the POSITION accessors' counts.
fn vertex_count(doc: &serde_json::Value) -> u64 {
    doc["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            let a = m["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap();
            doc["accessors"][a as usize]["count"].as_u64().unwrap()
        })
        .sum()
}

#[test]
fn obj_round_trip_to_glb_gltf_and_ply_passes_the_validator() {
    let dir = tempfile::tempdir().unwrap();
    let obj = root().join("scenes/cornell.obj");
    let (glb, gltf, ply) =
        (dir.path().join("lit.glb"), dir.path().join("lit.gltf"), dir.path().join("lit.ply"));
    let quick = ["--max-shots", "150"];
    let run = |out: &Path, extra: &[&str]| {
        let mut args = vec!["export", obj.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend_from_slice(&quick);
        args.extend_from_slice(extra);
        let o = radiosity(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    let said = run(&glb, &[]);
    assert!(said.contains("wrote") && said.contains("lit.glb"), "{said}");
    run(&gltf, &["--tonemapped", "--tonemap", "reinhard"]);
    run(&ply, &[]);

    // The info command counts the same mesh the export wrote.
    let info = radiosity(&["info", obj.to_str().unwrap()]);
    let info = String::from_utf8_lossy(&info.stdout).into_owned();
    let doc = glb_json(&std::fs::read(&glb).unwrap());
    assert_eq!(doc["meshes"].as_array().unwrap().len(), 16, "one mesh per object");
    assert_eq!(doc["meshes"][0]["name"], "floor");
    assert!(said.contains(&format!("({} vertices", vertex_count(&doc))), "{said}");
    let elements: u64 =
        info.lines().find_map(|l| l.strip_prefix("elements")).unwrap().trim().parse().unwrap();
    assert!(elements > 0);
    let gltf_doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    assert_eq!(vertex_count(&gltf_doc), vertex_count(&doc));
    assert!(gltf_doc["asset"]["extras"]["COLOR_0"].as_str().unwrap().contains("reinhard"));
    let ply_bytes = std::fs::read(&ply).unwrap();
    assert!(ply_bytes.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
    assert!(
        String::from_utf8_lossy(&ply_bytes[..600])
            .contains(&format!("element vertex {}\n", vertex_count(&doc)))
    );

    validate(&[&glb, &gltf]);
}

#[test]
fn gltf_scene_exports_with_lightmaps() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lit.glb");
    let maps = dir.path().join("maps");
    let gltf = root().join("scenes/cornell.gltf");
    let args =
        ["export", gltf.to_str().unwrap(), "-o", out.to_str().unwrap(), "--lightmap", maps.to_str().unwrap()];
    let o = radiosity(&[&args[..], &["--max-shots", "100"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    for f in ["floor.exr", "light.exr", "lightmapped.obj", "lightmapped.mtl"] {
        assert!(maps.join(f).is_file(), "{f} written");
    }
    // Nothing is overwritten without --force: neither the mesh nor the lightmaps.
    std::fs::remove_file(&out).unwrap();
    let o = radiosity(&[&args[..], &["--max-shots", "100"]].concat());
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("pass --force"), "{}", stderr(&o));
    let o = radiosity(&[&args[..], &["--max-shots", "100", "--force"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    validate(&[&out]);
}

#[test]
fn existing_output_and_bad_input_are_one_line_errors_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lit.glb");
    std::fs::write(&out, "precious").unwrap();
    let o = radiosity(&["export", "cornell", "-o", out.to_str().unwrap(), "--max-shots", "5"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "precious");
    let o = radiosity(&["export", "cornell", "-o", out.to_str().unwrap(), "--max-shots", "5", "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));

    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n").unwrap();
    let fbx = dir.path().join("lit.fbx");
    let x = dir.path().join("x.glb");
    let cases: [(&[&str], &str); 3] = [
        (
            &["export", bad.to_str().unwrap(), "-o", x.to_str().unwrap()],
            "bad.obj:5: face 2: vertex index 9 out of range (file has 3 vertices)",
        ),
        (&["solve", bad.to_str().unwrap()], "bad.obj:5: face 2"),
        (
            &["export", "cornell", "-o", fbx.to_str().unwrap()],
            "unknown output format; expected .glb, .gltf or .ply",
        ),
    ];
    for (args, needle) in cases {
        let o = radiosity(args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    let o = radiosity(&["solve", dir.path().join("missing.gltf").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("missing.gltf: cannot read the model file"), "{}", stderr(&o));
}

/// The textured room's faces for an engine: `--lightmap-atlas` writes the glTF, the EXR and
/// the PNG; every primitive has the lightmap's `TEXCOORD_1` in [0, 1] and its material points
/// at the lightmap texture on set 1; the floor keeps its own `vt` as `TEXCOORD_0` under its
/// texture (clamped as loaded); the validator finds no error; a second run without --force
/// refuses to overwrite; the atlas alone needs no `-o`.
#[test]
fn the_lightmap_atlas_keeps_the_models_faces_and_texture() {
    let dir = tempfile::tempdir().unwrap();
    let model = textured_room(dir.path());
    let (out, atlas) = (dir.path().join("lit.glb"), dir.path().join("atlas"));
    let args = [
        "export",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--lightmap-atlas",
        atlas.to_str().unwrap(),
        "--atlas-size",
        "128",
        "--max-shots",
        "50",
    ];
    let o = radiosity(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("128x"), "{}", stderr(&o));
    for f in ["lightmapped.gltf", "lightmap.exr", "lightmap.png"] {
        assert!(atlas.join(f).is_file(), "{f} written");
    }
    let gltf = atlas.join("lightmapped.gltf");
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    assert_eq!(doc["asset"]["extras"]["radiosity_lightmap"]["quantity"], "irradiance");
    let lightmap = doc["asset"]["extras"]["radiosity_lightmap"]["texture"].as_u64().unwrap();
    for mesh in doc["meshes"].as_array().unwrap() {
        let prim = &mesh["primitives"][0];
        let uv1 = &doc["accessors"][prim["attributes"]["TEXCOORD_1"].as_u64().unwrap() as usize];
        assert_eq!(uv1["type"], "VEC2");
        let material = &doc["materials"][prim["material"].as_u64().unwrap() as usize];
        assert_eq!(material["extras"]["lightmap"]["index"].as_u64(), Some(lightmap), "{material}");
        assert_eq!(material["extras"]["lightmap"]["texCoord"], 1);
    }
    let floor = doc["meshes"].as_array().unwrap().iter().find(|m| m["name"] == "floor").unwrap();
    let prim = &floor["primitives"][0];
    assert_ne!(prim["attributes"]["TEXCOORD_0"], prim["attributes"]["TEXCOORD_1"], "the model's own set");
    let material = &doc["materials"][prim["material"].as_u64().unwrap() as usize];
    let base = &material["pbrMetallicRoughness"]["baseColorTexture"];
    assert_eq!(base["texCoord"], 0);
    let sampler = &doc["samplers"]
        [doc["textures"][base["index"].as_u64().unwrap() as usize]["sampler"].as_u64().unwrap() as usize];
    assert_eq!(sampler["wrapS"].as_u64(), Some(33071), "clamped as loaded");
    validate(&[&gltf]);
    std::fs::remove_file(&out).unwrap();
    let o = radiosity(&args);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("pass --force"), "{}", stderr(&o));
    let alone = dir.path().join("alone");
    let o = radiosity(&[
        "export",
        model.to_str().unwrap(),
        "--lightmap-atlas",
        alone.to_str().unwrap(),
        "--max-shots",
        "5",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(alone.join("lightmapped.gltf").is_file());
    // A density needs an atlas, and a positive one.
    let model = model.to_str().unwrap();
    let lone = ["export", model, "-o", out.to_str().unwrap(), "--texels-per-unit", "10"];
    let zero =
        ["export", model, "-o", out.to_str().unwrap(), "--lightmap-atlas", "a", "--texels-per-unit", "0"];
    let nothing = ["export", model, "--max-shots", "5"];
    for (args, needle) in [
        (&lone[..], "give --lightmap-atlas DIR too"),
        (&zero[..], "must be in (0, 1e6]"),
        (&nothing[..], "nothing to write: give -o FILE"),
    ] {
        let o = radiosity(args);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(needle), "{}", stderr(&o));
    }
}

/// The lightmap read as an engine reads it gives the solve's per-object means: the Cornell
/// box's atlas (radiosity texels, no contact cuts so every face is solved whole), written
/// from the scene (the built-in box) and from a glTF kept as it is (`scenes/cornell.gltf`),
/// read by `scripts/lightmap-view/means.mjs` (glTF-Transform for the glTF, three.js's
/// EXRLoader for the texels, sampled bilinearly at the lightmap's coordinates over every
/// triangle), against `solve --json` with the same settings: every object within 2 % (vertex
/// interpolation and the texel grid aside; measured within 0.93 %).
#[test]
fn the_lightmap_read_through_its_coordinates_by_another_reader_gives_the_solves_means() {
    let Some(node) = node_package("lightmap-view", "@gltf-transform/core") else { return };
    let gltf_model = root().join("scenes/cornell.gltf");
    for scene in ["cornell", gltf_model.to_str().unwrap()] {
        let dir = tempfile::tempdir().unwrap();
        let (atlas, report) = (dir.path().join("atlas"), dir.path().join("s.json"));
        let common = ["--contacts", "false", "--max-shots", "400", "-q"];
        let o = radiosity(
            &[
                &["export", scene, "--lightmap-atlas", atlas.to_str().unwrap()][..],
                &["--lightmap-quantity", "radiosity", "--atlas-size", "512"],
                &common,
            ]
            .concat(),
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let o = radiosity(&[&["solve", scene, "--json", report.to_str().unwrap()][..], &common].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        let means = Command::new(node)
            .arg(root().join("scripts/lightmap-view/means.mjs"))
            .arg(atlas.join("lightmapped.gltf"))
            .output()
            .expect("run node");
        assert!(means.status.success(), "{}", stderr(&means));
        let means: serde_json::Value = serde_json::from_slice(&means.stdout).unwrap();
        let solved: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
        let objects = solved["objects"].as_array().unwrap();
        assert_eq!(objects.len(), 16);
        for object in objects {
            let name = object["name"].as_str().unwrap();
            let lightmap = &means[name];
            for c in 0..3 {
                let (got, want) = (lightmap[c].as_f64().unwrap(), object["radiosity"][c].as_f64().unwrap());
                assert!(
                    (got - want).abs() <= 0.02 * want + 1e-9,
                    "{scene} {name} channel {c}: lightmap {got}, solve {want}"
                );
            }
        }
    }
}

/// A glTF model comes out as it went in, with the lightmap added: the same nodes with the same
/// names, the same materials (each pointing at the lightmap), every primitive given the
/// lightmap's coordinates and its other attributes kept; the validator finds no error.
#[test]
fn a_gltf_model_keeps_its_nodes_and_materials_in_the_atlas() {
    let dir = tempfile::tempdir().unwrap();
    let atlas = dir.path().join("atlas");
    let model = root().join("scenes/cornell.gltf");
    let o = radiosity(&[
        "export",
        model.to_str().unwrap(),
        "--lightmap-atlas",
        atlas.to_str().unwrap(),
        "--max-shots",
        "20",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before: serde_json::Value = serde_json::from_slice(&std::fs::read(&model).unwrap()).unwrap();
    let gltf = atlas.join("lightmapped.gltf");
    let after: serde_json::Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    let names = |doc: &serde_json::Value, key: &str| -> Vec<String> {
        doc[key].as_array().unwrap().iter().map(|n| n["name"].as_str().unwrap_or("").to_owned()).collect()
    };
    assert_eq!(names(&before, "nodes"), names(&after, "nodes"));
    assert_eq!(names(&before, "materials"), names(&after, "materials"));
    let set = after["asset"]["extras"]["radiosity_lightmap"]["texCoord"].as_u64().unwrap();
    for (b, a) in before["nodes"].as_array().unwrap().iter().zip(after["nodes"].as_array().unwrap()) {
        let (Some(mb), Some(ma)) = (b["mesh"].as_u64(), a["mesh"].as_u64()) else { continue };
        let (pb, pa) =
            (&before["meshes"][mb as usize]["primitives"][0], &after["meshes"][ma as usize]["primitives"][0]);
        assert_eq!(pb["material"], pa["material"]);
        for key in pb["attributes"].as_object().unwrap().keys() {
            assert!(pa["attributes"].get(key).is_some(), "{key} kept");
        }
        assert!(pa["attributes"].get(format!("TEXCOORD_{set}")).is_some());
    }
    for m in after["materials"].as_array().unwrap() {
        assert_eq!(m["extras"]["lightmap"]["texCoord"].as_u64(), Some(set), "{m}");
    }
    validate(&[&gltf]);
}

/// `node` when the npm package `package` is installed in `scripts/<folder>`; `None` with a
/// loud message otherwise, and a failure under CI (where `setup.sh` installs both).
fn node_package(folder: &str, package: &str) -> Option<&'static str> {
    let installed = root().join("scripts").join(folder).join("node_modules").join(package).is_dir();
    let why = match (Command::new("node").arg("--version").output(), installed) {
        (Err(e), _) => format!("node cannot be run ({e})"),
        (Ok(_), false) => format!("the npm package {package} is not installed in scripts/{folder}"),
        (Ok(_), true) => return Some("node"),
    };
    let msg = format!("NOT RUN: {why}; install it with ./setup.sh (or: npm ci --prefix scripts/{folder})");
    assert!(std::env::var_os("CI").is_none(), "{msg} — required in CI");
    eprintln!("{msg}");
    None
}

/// A textured OBJ floor (a 4 × 4 PNG, clamped) under an untextured lamp, in `dir`; the OBJ's path.
fn textured_room(d: &Path) -> PathBuf {
    let pixels = (0..16u8).map(|i| [i * 16, 255 - i * 16, 128]).collect();
    radiosity_image::write_png(
        &d.join("tiles.png"),
        &radiosity_image::SrgbImage { width: 4, height: 4, pixels },
    )
    .unwrap();
    std::fs::write(
        d.join("room.mtl"),
        "newmtl floor\nKd 1 1 1\nmap_Kd -clamp on tiles.png\nnewmtl lamp\nKe 10 10 10\n",
    )
    .unwrap();
    let obj = "mtllib room.mtl\no floor\nv 0 0 0\nv 0 0 2\nv 2 0 2\nv 2 0 0\n\
        vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\nusemtl floor\nf 1/1 2/2 3/3 4/4\n\
        o lamp\nv 0.75 1.5 0.75\nv 1.25 1.5 0.75\nv 1.25 1.5 1.25\nv 0.75 1.5 1.25\nusemtl lamp\nf 5 6 7 8\n";
    let model = d.join("room.obj");
    std::fs::write(&model, obj).unwrap();
    model
}

/// A textured OBJ floor under a lamp, exported to GLB and glTF: the floor's primitive has
/// `TEXCOORD_0` and a material whose base colour texture is the PNG embedded in the buffer,
/// sampled as loaded (`-clamp on`); the lamp keeps the untextured material; the count of
/// vertices said is the count written; the validator finds no error.
#[test]
fn a_textured_model_exports_its_texture_and_passes_the_validator() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = textured_room(d);
    let (glb, gltf) = (d.join("lit.glb"), d.join("lit.gltf"));
    for out in [&glb, &gltf] {
        let o =
            radiosity(&["export", model.to_str().unwrap(), "-o", out.to_str().unwrap(), "--max-shots", "50"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let doc = if out == &glb {
            glb_json(&std::fs::read(out).unwrap())
        } else {
            serde_json::from_slice(&std::fs::read(out).unwrap()).unwrap()
        };
        assert!(stderr(&o).contains(&format!("({} vertices", vertex_count(&doc))), "{}", stderr(&o));
        let floor = doc["meshes"].as_array().unwrap().iter().find(|m| m["name"] == "floor").unwrap();
        let prim = &floor["primitives"][0];
        assert!(prim["attributes"]["TEXCOORD_0"].is_u64(), "{prim}");
        let material = &doc["materials"][prim["material"].as_u64().unwrap() as usize];
        let texture = &doc["textures"]
            [material["pbrMetallicRoughness"]["baseColorTexture"]["index"].as_u64().unwrap() as usize];
        let image = &doc["images"][texture["source"].as_u64().unwrap() as usize];
        assert_eq!(image["mimeType"], "image/png");
        assert!(image["bufferView"].is_u64(), "embedded: {image}");
        let sampler = &doc["samplers"][texture["sampler"].as_u64().unwrap() as usize];
        assert_eq!((sampler["wrapS"].as_u64(), sampler["wrapT"].as_u64()), (Some(33071), Some(33071)));
        let lamp = doc["meshes"].as_array().unwrap().iter().find(|m| m["name"] == "lamp").unwrap();
        assert!(lamp["primitives"][0]["attributes"].get("TEXCOORD_0").is_none());
        assert_eq!(lamp["primitives"][0]["material"], 0);
    }
    validate(&[&glb, &gltf]);
}
