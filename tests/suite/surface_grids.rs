//! Calculation grids on named surfaces (`surface = "floor"` in a `[[grid]]`): the grid takes
//! the polygon's corners and faces out of its front, and what it cannot cover is refused with
//! the key named.

use radiosity_core::glam::DVec3;

/// A 6 × 4 m floor (front up), a box, an isotropic luminaire, and `grid` as the last table.
fn scene(grid: &str) -> String {
    format!(
        r#"
units = "m"
[[material]]
name = "grey"
reflectance = [0.5, 0.5, 0.5]
[[object]]
name = "floor"
type = "polygon"
vertices = [[0, 0, 0], [0, 0, 4], [6, 0, 4], [6, 0, 0]]
material = "grey"
[[object]]
name = "crate"
type = "box"
min = [1, 0, 1]
max = [2, 1, 2]
material = "grey"
[[luminaire]]
file = "iso.ies"
position = [3, 2.5, 2]
[[grid]]
{grid}
"#
    )
}

const ISO: &str = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 180\n0\n100 100\n";

fn load(grid: &str) -> Result<radiosity_core::Scene, String> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("iso.ies"), ISO).unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene(grid)).unwrap();
    radiosity_io::load_scene(&path).map(|l| l.scene).map_err(|e| e.to_string())
}

#[test]
fn a_surface_grid_covers_the_polygon_and_faces_its_front() {
    let scene = load("surface = \"floor\"\ndivisions = [12, 8]").unwrap();
    let g = &scene.lighting.grids[0];
    assert_eq!(g.name, "floor");
    assert_eq!(g.origin, DVec3::ZERO);
    assert_eq!((g.u, g.v), (DVec3::new(0.0, 0.0, 4.0), DVec3::new(6.0, 0.0, 0.0)));
    assert!((g.normal - DVec3::Y).length() < 1e-12, "{:?}", g.normal);
    // 1 mm off the floor, so that the floor does not shadow its own points.
    assert!((g.height - 1e-3).abs() < 1e-12);
    let points = g.points();
    assert_eq!(points.len(), 96);
    assert!(points.iter().all(|p| (0.0..=6.0).contains(&p.x) && (0.0..=4.0).contains(&p.z)));
    // A name and a height given win.
    let scene = load("surface = \"floor\"\nname = \"floor at 5 cm\"\nheight = 0.05").unwrap();
    assert_eq!(scene.lighting.grids[0].name, "floor at 5 cm");
    assert_eq!(scene.lighting.grids[0].height, 0.05);
}

#[test]
fn what_a_surface_grid_cannot_cover_is_refused_by_key() {
    for (grid, says) in [
        ("surface = \"ceiling\"", "no object is named 'ceiling'"),
        ("surface = \"crate\"", "four corners"),
        ("surface = \"floor\"\norigin = [0, 0, 0]", "not both"),
        ("name = \"nothing\"", "a grid needs origin, u and v"),
        ("origin = [0, 0, 0]\nu = [1, 0, 0]", "a grid needs origin, u and v"),
    ] {
        let e = load(grid).expect_err(grid);
        assert!(e.contains("grid[0]") && e.contains(says), "{grid}: {e}");
        assert!(e.contains("scene.toml:"), "{grid}: the file and line: {e}");
    }
}
