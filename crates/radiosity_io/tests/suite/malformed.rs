//! One test per way a scene file can be wrong: each must give a one-line error naming the
//! file, the line of the offending value, its key path and what was expected — never a panic.

use std::path::Path;

use radiosity_io::{LoadError, load_scene, parse_scene};

/// A valid scene using every object type, a camera, `[mesh]` and `[solver]`. The cases below
/// replace one fragment of it.
const BASE: &str = r#"name = "test"
[camera]
position = [0.5, 0.5, -2]
look_at = [0.5, 0.5, 0.5]
up = [0, 1, 0]
fov_y_deg = 50

[[material]]
name = "white"
reflectance = [0.5, 0.5, 0.5]

[[material]]
name = "light"
reflectance = [0, 0, 0]
emission = [10, 10, 10]

[[object]]
name = "room"
type = "box"
min = [0, 0, 0]
max = [1, 1, 1]
normals = "inward"
material = "white"

[[object]]
name = "lamp"
type = "polygon"
vertices = [[0.4, 0.99, 0.4], [0.6, 0.99, 0.4], [0.6, 0.99, 0.6], [0.4, 0.99, 0.6]]
material = "light"

[[object]]
name = "ball"
type = "sphere"
center = [0.5, 0.3, 0.5]
radius = 0.2
material = "white"

[[object]]
name = "shelves"
type = "polygons"
faces = [
  [[0.1, 0.5, 0.1], [0.1, 0.5, 0.3], [0.3, 0.5, 0.3]],
  [[0.7, 0.5, 0.7], [0.7, 0.5, 0.9], [0.9, 0.5, 0.9]],
]
material = "white"

[mesh]
patch_size = 0.25
element_size = 0.125

[solver]
unshot_threshold = 0.001
max_shots = 1000
time_limit = 60
"#;

/// 1-based line of the first occurrence of `fragment` in BASE.
fn line_in_base(fragment: &str) -> usize {
    let at = BASE.find(fragment).unwrap_or_else(|| panic!("{fragment:?} is not in BASE"));
    BASE[..at].matches('\n').count() + 1
}

/// Parses `text` as `bad.toml`, expecting an error that is one line, starts at `line` and
/// names `key`; returns the message.
fn error_at(text: &str, line: usize, key: &str) -> String {
    let e = parse_scene(text, "bad.toml").expect_err("the scene must be rejected");
    assert_eq!(e.exit_code(), 2);
    let s = e.to_string();
    assert_eq!(s.lines().count(), 1, "not one line: {s}");
    assert!(s.starts_with(&format!("bad.toml:{line}:")), "expected line {line}: {s}");
    assert!(s.contains(&format!(": {key}: ")), "expected key {key}: {s}");
    s
}

/// Replaces the first `from` in BASE by `to` and expects an error on `from`'s line, naming
/// `key`, whose message contains `needle`.
fn check(from: &str, to: &str, key: &str, needle: &str) {
    check_at(from, to, line_in_base(from), key, needle);
}

/// As [`check`], for an error expected on another `line` than `from`'s.
fn check_at(from: &str, to: &str, line: usize, key: &str, needle: &str) {
    let text = BASE.replacen(from, to, 1);
    let s = error_at(&text, line, key);
    assert!(s.contains(needle), "expected {needle:?} in: {s}");
}

#[test]
fn base_scene_is_valid() {
    let scene = parse_scene(BASE, "base.toml").unwrap().scene;
    assert_eq!(scene.name, "test");
    assert_eq!(scene.objects.len(), 4);
    assert_eq!(scene.mesh.unwrap().patch_size, 0.25);
    assert_eq!(scene.solver.max_shots, Some(1000));
    assert_eq!(scene.solver.unshot_threshold, Some(0.001));
    assert_eq!(scene.solver.time_limit, Some(60.0));
    assert!(scene.camera.is_some());
}

// --- TOML itself -------------------------------------------------------------------------

#[test]
fn toml_syntax_error() {
    check(
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [0.5, 0.5 0.5]",
        "material[0].reflectance",
        "expected",
    );
}

#[test]
fn toml_syntax_error_inside_a_multi_line_array() {
    check("[[0.7, 0.5, 0.7]", "[[0.7, 0.5, 0.7 x]", "object[3].faces", "expected");
}

#[test]
fn toml_unterminated_string() {
    check("name = \"test\"", "name = \"test", "name", "string");
}

#[test]
fn toml_duplicate_key() {
    // Reported on the second one.
    let line = line_in_base("fov_y_deg = 50") + 1;
    check_at("fov_y_deg = 50", "fov_y_deg = 50\nfov_y_deg = 60", line, "camera.fov_y_deg", "duplicate key");
}

#[test]
fn unknown_key_lists_the_expected_keys() {
    let text = BASE.replacen("radius = 0.2", "radius = 0.2\nradious = 3", 1);
    let s = error_at(&text, line_in_base("radius = 0.2") + 1, "object[2].radious");
    assert!(s.contains("unknown field `radious`") && s.contains("`radius`"), "{s}");
}

#[test]
fn unknown_key_in_a_material() {
    // `colour` is a key now (the colour of `lumens` light); the American spelling is not.
    check("reflectance = [0.5", "color = 1\nreflectance = [0.5", "material[0].color", "`reflectance`");
}

#[test]
fn unknown_table() {
    check("[solver]", "[solvers]", "solvers", "unknown field `solvers`");
}

#[test]
fn unknown_camera_key() {
    check("fov_y_deg = 50", "fov = 50", "camera.fov", "expected one of");
}

#[test]
fn wrong_type_string_for_number() {
    check("radius = 0.2", "radius = \"big\"", "object[2].radius", "expected f64");
}

#[test]
fn wrong_type_number_for_point() {
    check("center = [0.5, 0.3, 0.5]", "center = 0.5", "object[2].center", "invalid type");
}

#[test]
fn wrong_length_of_a_colour() {
    check(
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [0.5, 0.5]",
        "material[0].reflectance",
        "invalid length 2",
    );
}

#[test]
fn missing_required_field() {
    // The error points at the entry's header, the only place a missing key can be.
    let text = BASE.replacen("type = \"sphere\"\n", "", 1);
    let s = error_at(&text, line_in_base("[[object]]\nname = \"ball\""), "object[2]");
    assert!(s.contains("missing field `type`"), "{s}");
}

// --- materials ---------------------------------------------------------------------------

#[test]
fn missing_material_reference_lists_the_defined_ones() {
    check(
        "material = \"light\"",
        "material = \"lite\"",
        "object[1].material",
        "'lite', which is not defined (defined: white, light)",
    );
}

#[test]
fn duplicate_material() {
    check("name = \"light\"", "name = \"white\"", "material[1].name", "'white' is defined twice");
}

#[test]
fn reflectance_of_one_is_rejected() {
    check(
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [1.0, 0.5, 0.5]",
        "material[0].reflectance",
        "must be in [0, 1) in every channel",
    );
}

#[test]
fn reflectance_above_one_in_one_channel() {
    check(
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [0.5, 0.5, 1.2]",
        "material[0].reflectance",
        "[0.5, 0.5, 1.2]",
    );
}

#[test]
fn negative_reflectance() {
    check(
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [0.5, -0.1, 0.5]",
        "material[0].reflectance",
        "[0, 1)",
    );
}

#[test]
fn nan_reflectance() {
    check(
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [nan, 0.5, 0.5]",
        "material[0].reflectance",
        "[0, 1)",
    );
}

#[test]
fn negative_emission() {
    check("emission = [10, 10, 10]", "emission = [10, -1, 10]", "material[1].emission", "≥ 0");
}

#[test]
fn nan_emission() {
    check("emission = [10, 10, 10]", "emission = [nan, 10, 10]", "material[1].emission", "finite");
}

#[test]
fn infinite_emission() {
    check("emission = [10, 10, 10]", "emission = [10, inf, 10]", "material[1].emission", "finite");
}

#[test]
fn material_name_with_a_newline_stays_one_line() {
    // The first object refers to "white", now undefined; the list of names shows the escape.
    let line = line_in_base("material = \"white\"");
    check_at(
        "name = \"white\"",
        "name = \"wh\\nite\"",
        line,
        "object[0].material",
        "defined: wh\\nite, light",
    );
}

// --- geometry ----------------------------------------------------------------------------

#[test]
fn nan_coordinate_points_at_the_vertex() {
    let text = BASE.replacen("[0.6, 0.99, 0.6]", "[0.6, nan, 0.6]", 1);
    let s = error_at(&text, line_in_base("[0.6, 0.99, 0.6]"), "object[1].vertices[2]");
    assert!(s.contains("finite"), "{s}");
    // Column of the vertex's `[`, counted from 1.
    let column =
        BASE.lines().nth(line_in_base("vertices") - 1).unwrap().find("[0.6, 0.99, 0.6]").unwrap() + 1;
    assert!(s.starts_with(&format!("bad.toml:{}:{column}:", line_in_base("vertices"))), "{s}");
}

#[test]
fn infinite_coordinate_in_a_box() {
    check("max = [1, 1, 1]", "max = [1, inf, 1]", "object[0].max", "finite");
}

#[test]
fn negative_infinite_coordinate_in_a_face() {
    check("[0.9, 0.5, 0.9]", "[0.9, -inf, 0.9]", "object[3].faces[1][2]", "finite");
}

#[test]
fn nan_sphere_center() {
    check("center = [0.5, 0.3, 0.5]", "center = [0.5, nan, 0.5]", "object[2].center", "finite");
}

#[test]
fn collinear_polygon_is_degenerate() {
    check(
        "[[0.4, 0.99, 0.4], [0.6, 0.99, 0.4], [0.6, 0.99, 0.6], [0.4, 0.99, 0.6]]",
        "[[0.4, 0.99, 0.4], [0.5, 0.99, 0.4], [0.6, 0.99, 0.4]]",
        "object[1].vertices",
        "degenerate",
    );
}

#[test]
fn repeated_vertices_are_degenerate() {
    check("[0.6, 0.99, 0.6]", "[0.4, 0.99, 0.4]", "object[1].vertices", "degenerate");
}

#[test]
fn zero_size_face_is_degenerate() {
    check(
        "[[0.7, 0.5, 0.7], [0.7, 0.5, 0.9], [0.9, 0.5, 0.9]]",
        "[[0.7, 0.5, 0.7], [0.7, 0.5, 0.7], [0.7, 0.5, 0.7]]",
        "object[3].faces[1]",
        "degenerate",
    );
}

#[test]
fn non_planar_polygon() {
    check("[0.6, 0.99, 0.6]", "[0.6, 0.8, 0.6]", "object[1].vertices", "not planar");
}

#[test]
fn non_convex_polygon_points_at_the_vertex() {
    check("[0.6, 0.99, 0.6]", "[0.45, 0.99, 0.45]", "object[1].vertices[2]", "not convex");
}

#[test]
fn fewer_than_three_vertices() {
    check(
        "[[0.4, 0.99, 0.4], [0.6, 0.99, 0.4], [0.6, 0.99, 0.6], [0.4, 0.99, 0.6]]",
        "[[0.4, 0.99, 0.4], [0.6, 0.99, 0.4]]",
        "object[1].vertices",
        "at least 3 vertices, got 2",
    );
}

#[test]
fn polygons_without_faces() {
    let from = "faces = [\n  [[0.1, 0.5, 0.1], [0.1, 0.5, 0.3], [0.3, 0.5, 0.3]],\n  [[0.7, 0.5, 0.7], [0.7, 0.5, 0.9], [0.9, 0.5, 0.9]],\n]";
    check(from, "faces = []", "object[3].faces", "at least one face");
}

#[test]
fn zero_sphere_radius() {
    check("radius = 0.2", "radius = 0", "object[2].radius", "radius must be a finite number > 0, got 0");
}

#[test]
fn negative_sphere_radius() {
    check("radius = 0.2", "radius = -0.2", "object[2].radius", "> 0");
}

#[test]
fn infinite_sphere_radius() {
    check("radius = 0.2", "radius = inf", "object[2].radius", "finite");
}

#[test]
fn box_min_equal_to_max_on_one_axis() {
    check("min = [0, 0, 0]", "min = [0, 1, 0]", "object[0].min", "min must be below max");
}

#[test]
fn box_min_above_max() {
    check("min = [0, 0, 0]", "min = [2, 2, 2]", "object[0].min", "min must be below max");
}

#[test]
fn box_bad_normals() {
    check("normals = \"inward\"", "normals = \"inside\"", "object[0].normals", "\"inward\" or \"outward\"");
}

#[test]
fn box_nan_rotation() {
    check("normals = \"inward\"", "rotate_y_deg = nan", "object[0].rotate_y_deg", "finite angle");
}

#[test]
fn field_of_another_type() {
    check("normals = \"inward\"", "radius = 2", "object[0].radius", "does not apply to type 'box'");
}

#[test]
fn unknown_object_type() {
    check(
        "type = \"sphere\"",
        "type = \"ball\"",
        "object[2].type",
        "expected one of polygon, polygons, box, sphere",
    );
}

#[test]
fn mesh_object_with_a_missing_file() {
    let from = "type = \"sphere\"\ncenter = [0.5, 0.3, 0.5]\nradius = 0.2";
    let to = "type = \"mesh\"\nfile = \"statue.obj\"\ntransform = { scale = 2.0 }";
    // The `file` line, just below `type`.
    check_at(from, to, line_in_base(from) + 1, "object[2].file", "cannot read 'statue.obj'");
}

#[test]
fn mesh_object_with_a_bad_transform() {
    let from = "type = \"sphere\"\ncenter = [0.5, 0.3, 0.5]\nradius = 0.2";
    let to = "type = \"mesh\"\nfile = \"statue.obj\"\ntransform = { scale = 0.0 }";
    let line = line_in_base(from);
    check_at(from, to, line + 2, "object[2].transform.scale", "expected a finite number ≠ 0");
    let to = "type = \"mesh\"\nfile = \"statue.obj\"\ntransform = { spin = 1.0 }";
    check_at(from, to, line + 2, "object[2].transform", "unknown field `spin`");
    let to = "type = \"mesh\"\nfile = \"statue.png\"";
    check_at(from, to, line + 1, "object[2].file", "not a model file");
    let to = "type = \"mesh\"\nfile = \"statue.obj\"\nradius = 1.0";
    check_at(from, to, line + 2, "object[2].radius", "'radius' does not apply to type 'mesh'");
}

#[test]
fn missing_geometry_field() {
    let text = BASE.replacen("radius = 0.2\n", "", 1);
    let s = error_at(&text, line_in_base("[[object]]\nname = \"ball\""), "object[2].radius");
    assert!(s.contains("needs 'radius'"), "{s}");
}

// --- the scene as a whole ----------------------------------------------------------------

#[test]
fn no_emitter_at_all() {
    let text = BASE.replacen("emission = [10, 10, 10]", "emission = [0, 0, 0]", 1);
    let s = error_at(&text, 1, "material");
    assert!(s.contains("no light"), "{s}");
}

#[test]
fn no_emitter_because_the_light_is_unused() {
    let text = BASE.replacen("material = \"light\"", "material = \"white\"", 1);
    let s = error_at(&text, line_in_base("emission"), "material[1].emission");
    assert!(s.contains("no light") && s.contains("'light' emits but no object uses it"), "{s}");
}

#[test]
fn no_objects() {
    let text = &BASE[..BASE.find("[[object]]").unwrap()];
    let s = error_at(text, 1, "object");
    assert!(s.contains("no objects"), "{s}");
    let s = error_at("", 1, "object");
    assert!(s.contains("no objects"), "{s}");
}

// --- mesh, camera, solver ----------------------------------------------------------------

#[test]
fn zero_patch_size() {
    check("patch_size = 0.25", "patch_size = 0", "mesh.patch_size", "patch_size must be a finite number > 0");
}

#[test]
fn negative_element_size() {
    check("element_size = 0.125", "element_size = -1", "mesh.element_size", "> 0, got -1");
}

#[test]
fn nan_element_size() {
    check("element_size = 0.125", "element_size = nan", "mesh.element_size", "finite");
}

#[test]
fn missing_mesh_size() {
    let text = BASE.replacen("element_size = 0.125\n", "", 1);
    let s = error_at(&text, line_in_base("[mesh]"), "mesh");
    assert!(s.contains("missing field `element_size`"), "{s}");
}

#[test]
fn camera_looking_at_itself() {
    check("look_at = [0.5, 0.5, 0.5]", "look_at = [0.5, 0.5, -2]", "camera.look_at", "same point");
}

#[test]
fn camera_up_along_the_view() {
    check("up = [0, 1, 0]", "up = [0, 0, 1]", "camera.up", "parallel");
}

#[test]
fn camera_default_up_along_the_view() {
    // No `up` given: the default is blamed at the [camera] table, with a hint.
    let text = BASE.replacen("up = [0, 1, 0]\n", "", 1).replacen(
        "look_at = [0.5, 0.5, 0.5]",
        "look_at = [0.5, 5, -2]",
        1,
    );
    let s = error_at(&text, line_in_base("[camera]"), "camera.up");
    assert!(s.contains("defaults to [0, 1, 0]"), "{s}");
}

#[test]
fn camera_zero_up() {
    check("up = [0, 1, 0]", "up = [0, 0, 0]", "camera.up", "zero");
}

#[test]
fn camera_field_of_view_of_180() {
    check("fov_y_deg = 50", "fov_y_deg = 180", "camera.fov_y_deg", "(0, 180)");
}

#[test]
fn camera_nan_field_of_view() {
    check("fov_y_deg = 50", "fov_y_deg = nan", "camera.fov_y_deg", "not finite");
}

#[test]
fn camera_infinite_position() {
    check("position = [0.5, 0.5, -2]", "position = [0.5, 0.5, -inf]", "camera.position", "not finite");
}

#[test]
fn unshot_threshold_of_zero() {
    check("unshot_threshold = 0.001", "unshot_threshold = 0", "solver.unshot_threshold", "(0, 1)");
}

#[test]
fn unshot_threshold_of_one() {
    check("unshot_threshold = 0.001", "unshot_threshold = 1", "solver.unshot_threshold", "(0, 1)");
}

#[test]
fn nan_unshot_threshold() {
    check("unshot_threshold = 0.001", "unshot_threshold = nan", "solver.unshot_threshold", "got NaN");
}

#[test]
fn zero_max_shots() {
    check("max_shots = 1000", "max_shots = 0", "solver.max_shots", "≥ 1, got 0");
}

#[test]
fn negative_max_shots() {
    check("max_shots = 1000", "max_shots = -5", "solver.max_shots", "≥ 1, got -5");
}

#[test]
fn fractional_max_shots() {
    check("max_shots = 1000", "max_shots = 1.5", "solver.max_shots", "expected i64");
}

#[test]
fn zero_time_limit() {
    check("time_limit = 60", "time_limit = 0", "solver.time_limit", "> 0");
}

#[test]
fn infinite_time_limit() {
    check("time_limit = 60", "time_limit = inf", "solver.time_limit", "finite");
}

// --- files -------------------------------------------------------------------------------

#[test]
fn missing_file_is_named() {
    let e = load_scene(Path::new("no/such/scene.toml")).unwrap_err();
    assert!(matches!(e, LoadError::Unreadable { .. }));
    assert_eq!(e.exit_code(), 2);
    let s = e.to_string();
    assert!(s.starts_with("no/such/scene.toml: cannot read the scene file"), "{s}");
    assert_eq!(s.lines().count(), 1);
}

#[test]
fn directory_is_unreadable() {
    let dir = env!("CARGO_TARGET_TMPDIR");
    let s = load_scene(Path::new(dir)).unwrap_err().to_string();
    assert!(s.starts_with(dir) && s.contains("cannot read"), "{s}");
}

#[test]
fn file_that_is_not_utf8_is_unreadable() {
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("radiosity_io_not_utf8.toml");
    std::fs::write(&path, b"name = \"\xff\xfe\"\n").unwrap();
    let s = load_scene(&path).unwrap_err().to_string();
    assert!(s.contains("radiosity_io_not_utf8.toml: cannot read"), "{s}");
}

#[test]
fn errors_from_a_file_name_the_file() {
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("radiosity_io_bad_rho.toml");
    std::fs::write(&path, BASE.replacen("reflectance = [0.5, 0.5, 0.5]", "reflectance = [1.5, 0.5, 0.5]", 1))
        .unwrap();
    let s = load_scene(&path).unwrap_err().to_string();
    assert!(
        s.starts_with(&format!(
            "{}:{}:15: material[0].reflectance: ",
            path.display(),
            line_in_base("reflectance = [0.5, 0.5, 0.5]")
        )),
        "{s}"
    );
    // The scene name defaults to the file stem.
    std::fs::write(&path, BASE.replacen("name = \"test\"\n", "", 1)).unwrap();
    assert_eq!(load_scene(&path).unwrap().scene.name, "radiosity_io_bad_rho");
}

#[test]
fn a_fourth_number_in_a_colour_is_an_error() {
    check(
        "reflectance = [0.5, 0.5, 0.5]",
        "reflectance = [0.5, 0.5, 0.5, 0.5]",
        "material[0].reflectance",
        "invalid length 4",
    );
}

#[test]
fn a_time_limit_past_a_duration_is_an_error() {
    check("time_limit = 60", "time_limit = 1e308", "solver.time_limit", "≤ 1e9");
}

#[test]
fn a_fourth_coordinate_of_a_vertex_is_an_error() {
    let text = "[[material]]\nname = \"m\"\nreflectance = [0, 0, 0]\nemission = [1, 1, 1]\n\
                [[object]]\nname = \"o\"\ntype = \"polygon\"\nmaterial = \"m\"\n\
                vertices = [[0, 0, 0], [1, 0, 0, 9], [1, 1, 0]]\n";
    let s = error_at(text, 9, "object[0].vertices");
    assert!(s.contains("invalid length 4"), "{s}");
}

#[test]
fn a_huge_key_is_not_echoed_whole() {
    let text = format!("{} = 1\n{BASE}", "k".repeat(1_000_000));
    let e = parse_scene(&text, "bad.toml").unwrap_err().to_string();
    assert!(e.len() < 3000 && e.contains("characters)"), "{} bytes: {}", e.len(), &e[..200]);
}
