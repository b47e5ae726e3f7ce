//! The mesher's own tests: lattices, model faces, smoothing, grading, refinement, contacts.

use glam::DVec3;
use radiosity_core::{
    Facing, Material, MeshParams, Object, Polygon, PolygonMesh, Rgb, Scene, SceneError, Shape, Sphere,
    box_faces,
};
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use crate::{Element, Mesh, MeshError, Refinement, Smoothing};

mod triangulation;

fn scene_of(shape: Shape) -> Scene {
    let m = Material::try_new("m", Rgb::splat(0.5), Rgb::ONE).unwrap();
    Scene::try_new(
        "t",
        None,
        vec![m],
        vec![Object { name: "o".into(), material: 0, shape, sides: radiosity_core::Sides::One }],
    )
    .unwrap()
}

fn check_mesh(mesh: &Mesh, expected_area: f64, params: &MeshParams) {
    let area: f64 = mesh.elements.iter().map(|e| e.area).sum();
    assert!((area - expected_area).abs() < 1e-9 * expected_area, "area {area} vs {expected_area}");
    for p in &mesh.patches {
        let sum: f64 =
            mesh.elements[p.elements.start as usize..p.elements.end as usize].iter().map(|e| e.area).sum();
        assert!((sum - p.area).abs() < 1e-9 * p.area);
        for e in p.elements.clone() {
            let el = &mesh.elements[e as usize];
            assert!(el.normal.dot(p.normal) > 0.999);
            let pts: Vec<DVec3> = mesh.element_corners(e as usize).collect();
            // A quad's sides are at most the element size; a triangle's longest edge at most
            // the diagonal of that square (a model's triangles are cut by bisection to it).
            let limit = if pts.len() == 3 { std::f64::consts::SQRT_2 } else { 1.0 } * params.element_size;
            for k in 0..pts.len() {
                assert!(pts[k].distance(pts[(k + 1) % pts.len()]) <= limit * (1.0 + 1e-9));
            }
        }
    }
}

#[test]
fn quad_is_cut_into_patches_and_elements_with_shared_vertices() {
    let q = Polygon::try_new(vec![DVec3::ZERO, DVec3::X * 4.0, DVec3::new(4.0, 2.0, 0.0), DVec3::Y * 2.0])
        .unwrap();
    let params = MeshParams::try_new(2.0, 0.5).unwrap();
    let mesh = Mesh::build(&scene_of(Shape::Polygons(vec![q])), &params).unwrap();
    assert_eq!(mesh.patches.len(), 2);
    assert_eq!(mesh.elements.len(), 32);
    assert_eq!(mesh.positions.len(), 9 * 5);
    check_mesh(&mesh, 8.0, &params);
}

#[test]
fn triangles_and_pentagons_are_cut_with_exact_shared_vertices() {
    let pent: Vec<DVec3> = (0..5)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 5.0;
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    let poly = Polygon::try_new(pent).unwrap();
    let area = poly.area();
    let params = MeshParams::try_new(0.7, 0.2).unwrap();
    let mesh = Mesh::build(&scene_of(Shape::Polygons(vec![poly])), &params).unwrap();
    check_mesh(&mesh, area, &params);
    // Euler: a triangulated disc has V - E + F = 1 only when shared points merged exactly.
    assert_eq!(euler_characteristic(&mesh), 1);
}

#[test]
fn box_surfaces_do_not_share_vertices() {
    let faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Inward, 0.0).unwrap();
    // Ungraded: a 4 × 4 lattice of 25 vertices per face.
    let params = MeshParams::try_new(0.5, 0.25).unwrap().with_corner_refinement(0).unwrap();
    let mesh = Mesh::build(&scene_of(Shape::Polygons(faces)), &params).unwrap();
    assert_eq!(mesh.surfaces.len(), 6);
    assert_eq!(mesh.positions.len(), 6 * 25);
    assert_eq!(mesh.occluders.len(), 12);
}

#[test]
fn sphere_facets_face_the_right_way() {
    for facing in [Facing::Outward, Facing::Inward] {
        let s = Sphere::try_new(DVec3::new(1.0, 2.0, 3.0), 2.0, facing).unwrap();
        let mesh = Mesh::build(&scene_of(Shape::Sphere(s)), &MeshParams::try_new(1.0, 0.5).unwrap()).unwrap();
        let sign = if facing == Facing::Inward { -1.0 } else { 1.0 };
        for e in &mesh.elements {
            assert!(e.normal.dot(e.centre - s.center) * sign > 0.0);
        }
        for (p, n) in mesh.positions.iter().zip(&mesh.shading_normals) {
            assert!(((*p - s.center).normalize() * sign - *n).length() < 1e-9);
        }
        // Closed: every edge is shared by exactly two facets.
        let mut count = HashMap::default();
        for e in &mesh.elements {
            let v = e.vertex_indices();
            for k in 0..v.len() {
                let (a, b) = (v[k], v[(k + 1) % v.len()]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert!(count.values().all(|&c| c == 2));
    }
}

/// An emitting sphere meshed with elements as large as its radius keeps its power: its facets
/// hold within 0.6 % of the sphere's area (a lamp's power is its area times its exitance),
/// where a grey one at the same size keeps the coarse mesh and falls short by more.
#[test]
fn an_emitting_sphere_keeps_its_area() {
    let s = Sphere::try_new(DVec3::ZERO, 1.0, Facing::Outward).unwrap();
    let exact = 4.0 * std::f64::consts::PI;
    let params = MeshParams::try_new(1.0, 1.0).unwrap();
    let area = |emission: Rgb| {
        let m = Material::try_new("m", Rgb::splat(0.5), emission).unwrap();
        let lamp = Material::try_new("lamp", Rgb::ZERO, Rgb::ONE).unwrap();
        let quad = vec![
            DVec3::new(5.0, 0.0, 0.0),
            DVec3::new(5.0, 0.0, 1.0),
            DVec3::new(5.0, 1.0, 1.0),
            DVec3::new(5.0, 1.0, 0.0),
        ];
        let objects = vec![
            Object {
                name: "ball".into(),
                material: 0,
                shape: Shape::Sphere(s),
                sides: radiosity_core::Sides::One,
            },
            Object {
                name: "lamp".into(),
                material: 1,
                shape: Shape::Polygons(vec![Polygon::try_new(quad).unwrap()]),
                sides: radiosity_core::Sides::One,
            },
        ];
        let mesh = Mesh::build(&Scene::try_new("t", None, vec![m, lamp], objects).unwrap(), &params).unwrap();
        let of_ball: Vec<_> = mesh
            .elements
            .iter()
            .filter(|e| mesh.surfaces[mesh.patches[e.patch as usize].surface as usize].object == 0)
            .collect();
        (of_ball.iter().map(|e| e.area).sum::<f64>(), of_ball.len())
    };
    let (lamp, lamp_facets) = area(Rgb::ONE);
    let (grey, grey_facets) = area(Rgb::ZERO);
    assert!((exact - lamp) / exact < 0.006, "emitting: {lamp} of {exact}");
    assert!((exact - grey) / exact > 0.02 && grey_facets < lamp_facets, "grey: {grey} of {exact}");
}

/// A flat n×n grid of unit squares in z = 0, each cut into two triangles.
fn triangle_grid(n: u32) -> PolygonMesh {
    let positions = (0..=n).flat_map(|j| (0..=n).map(move |i| DVec3::new(i as f64, j as f64, 0.0))).collect();
    let at = |i: u32, j: u32| j * (n + 1) + i;
    let faces = (0..n)
        .flat_map(|j| {
            (0..n).flat_map(move |i| {
                [
                    vec![at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                    vec![at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                ]
            })
        })
        .collect();
    PolygonMesh::try_new(positions, faces).unwrap()
}

#[test]
fn coplanar_connected_triangles_form_one_surface_with_shared_vertices() {
    let grid = triangle_grid(4);
    let params = MeshParams::try_new(2.0, 0.5).unwrap();
    let mesh = Mesh::build(&scene_of(Shape::Mesh(grid)), &params).unwrap();
    assert_eq!(mesh.surfaces.len(), 1);
    // Its outline is the 4 × 4 square (the grid's points on its sides dropped): meshed as
    // that quad, 2 × 2 patches of 4 × 4 square elements.
    assert_eq!(mesh.patches.len(), 4);
    assert_eq!(mesh.elements.len(), 64);
    assert_eq!(mesh.positions.len(), 81);
    // Shared exactly: every lattice point of the 9×9 grid once, none doubled along an edge.
    let mut distinct: Vec<[u64; 3]> =
        mesh.positions.iter().map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]).collect();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(distinct.len(), mesh.positions.len());
    // A disc: V − E + F = 1 only when every shared edge's points merged.
    assert_eq!(euler_characteristic(&mesh), 1);
    check_mesh(&mesh, 16.0, &params);
}

/// V − E + F of the element mesh, counting each undirected edge once.
fn euler_characteristic(mesh: &Mesh) -> i64 {
    let mut edges = std::collections::HashSet::new();
    for e in &mesh.elements {
        let v = e.vertex_indices();
        for k in 0..v.len() {
            let (a, b) = (v[k], v[(k + 1) % v.len()]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    mesh.positions.len() as i64 - edges.len() as i64 + mesh.elements.len() as i64
}

#[test]
fn an_exporters_split_of_an_l_shaped_face_is_one_surface() {
    // An L fanned into four triangles as an exporter splits an n-gon, long thin ones among
    // them: one surface, each triangle bisected where it is long.
    let positions = [(0.0, 0.0), (3.0, 0.0), (3.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)]
        .map(|(x, y)| DVec3::new(x, y, 0.0))
        .to_vec();
    let faces = vec![vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 4], vec![0, 4, 5]];
    let l = PolygonMesh::try_new(positions, faces).unwrap();
    let params = MeshParams::try_new(1.0, 0.5).unwrap();
    let mesh = Mesh::build(&scene_of(Shape::Mesh(l)), &params).unwrap();
    assert_eq!(mesh.surfaces.len(), 1);
    // Its outline, triangulated afresh and bisected to √2 · 0.5, gives pieces of about
    // 0.125 (half a square of the element size): a lattice of 8 steps per edge, set by the
    // longest diagonal, gave 4 · 8 · 8 = 256 for the same area of 4.
    let n = mesh.elements.len();
    assert!((32..=80).contains(&n), "{n} elements");
    check_mesh(&mesh, 4.0, &params);
    // A disc (V − E + F = 1) only when the fan's shared diagonals merged exactly.
    assert_eq!(euler_characteristic(&mesh), 1);
}

#[test]
fn a_triangle_pair_making_a_quad_is_meshed_as_that_quad() {
    let params = MeshParams::try_new(2.0, 0.5).unwrap();
    let quad = Polygon::try_new(vec![DVec3::ZERO, DVec3::X * 4.0, DVec3::new(4.0, 2.0, 0.0), DVec3::Y * 2.0])
        .unwrap();
    let as_polygon = Mesh::build(&scene_of(Shape::Polygons(vec![quad])), &params).unwrap();
    let pair = PolygonMesh::try_new(
        vec![DVec3::ZERO, DVec3::X * 4.0, DVec3::new(4.0, 2.0, 0.0), DVec3::Y * 2.0],
        vec![vec![0, 1, 2], vec![0, 2, 3]],
    )
    .unwrap();
    let as_pair = Mesh::build(&scene_of(Shape::Mesh(pair)), &params).unwrap();
    assert_eq!(as_pair.elements.len(), as_polygon.elements.len());
    assert_eq!(as_pair.patches.len(), as_polygon.patches.len());
    let mut a: Vec<f64> = as_pair.elements.iter().map(|e| e.area).collect();
    let mut b: Vec<f64> = as_polygon.elements.iter().map(|e| e.area).collect();
    a.sort_by(f64::total_cmp);
    b.sort_by(f64::total_cmp);
    assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-9));
    assert_eq!(as_pair.occluders.len(), 2);
}

#[test]
fn folded_or_differently_sized_triangles_stay_apart() {
    // A cube as 12 triangles: six quads, never one surface across a fold.
    let c = |x: u32, y: u32, z: u32| x + 2 * y + 4 * z;
    let positions = (0..8).map(|k| DVec3::new((k & 1) as f64, ((k >> 1) & 1) as f64, (k >> 2) as f64));
    let quads = [
        [c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)],
        [c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)],
        [c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)],
        [c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)],
        [c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)],
        [c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)],
    ];
    let faces = quads.iter().flat_map(|q| [vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]]).collect();
    let cube = PolygonMesh::try_new(positions.collect(), faces).unwrap();
    let mesh = Mesh::build(&scene_of(Shape::Mesh(cube)), &MeshParams::try_new(0.5, 0.25).unwrap()).unwrap();
    assert_eq!(mesh.surfaces.len(), 6);
    assert_eq!(mesh.positions.len(), 6 * 25, "each face the 5×5 lattice of a quad");
    assert!((mesh.total_area() - 6.0).abs() < 1e-9);
}

#[test]
fn bad_mesh_faces_name_the_face() {
    let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
    let e = PolygonMesh::try_new(p.clone(), vec![vec![0, 1, 2], vec![0, 1, 7]]).unwrap_err();
    assert_eq!(e, SceneError::VertexIndexOutOfRange { face: 1, index: 7, count: 3 });
    let e = PolygonMesh::try_new(p.clone(), vec![vec![0, 1, 1]]).unwrap_err();
    assert!(e.to_string().starts_with("face 0: polygon is degenerate"), "{e}");
    assert_eq!(PolygonMesh::try_new(p, vec![]).unwrap_err(), SceneError::EmptyMesh);
}

#[test]
fn absurd_subdivision_is_an_error_not_a_hang() {
    let faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Inward, 0.0).unwrap();
    let r = Mesh::build(&scene_of(Shape::Polygons(faces)), &MeshParams::try_new(1.0, 1e-5).unwrap());
    assert!(matches!(r, Err(MeshError::TooManyElements { .. })));
}

/// A tessellated sphere pools every vertex with the facets around it; a box pools none
/// (its 90° edges are creases); a crease angle of 0 pools nothing.
#[test]
fn smoothing_joins_facets_below_the_crease_angle_only() {
    let params = MeshParams::try_new(10.0, 10.0).unwrap();
    let sphere =
        Mesh::build(&scene_of(Shape::Mesh(radiosity_scenes::uv_sphere_mesh(DVec3::ZERO, 1.0, 24))), &params)
            .unwrap();
    assert!(sphere.surfaces.len() > 100, "one surface per facet");
    // Every facet corner meets 3 or 4 other facets of the sphere (the poles 23).
    for v in 0..sphere.positions.len() {
        let partners: Vec<(u32, f64)> = sphere
            .smoothing
            .partners_of(v)
            .filter(|&(u, _)| sphere.positions[u as usize] == sphere.positions[v])
            .collect();
        assert!(partners.len() >= 3, "vertex {v}: {partners:?}");
    }
    let faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Outward, 0.0).unwrap();
    let cube = Mesh::build(&scene_of(Shape::Polygons(faces)), &params).unwrap();
    assert_eq!(cube.smoothing, Smoothing::default(), "a box's edges stay sharp");
    let flat = Mesh::build(
        &scene_of(Shape::Mesh(radiosity_scenes::uv_sphere_mesh(DVec3::ZERO, 1.0, 24))),
        &params.with_crease_angle(0.0).unwrap(),
    )
    .unwrap();
    assert_eq!(flat.smoothing, Smoothing::default());
    // 4 segments make an octahedron: 70.5° between neighbouring facets, above 40°.
    let coarse =
        Mesh::build(&scene_of(Shape::Mesh(radiosity_scenes::uv_sphere_mesh(DVec3::ZERO, 1.0, 4))), &params)
            .unwrap();
    assert_eq!(coarse.smoothing, Smoothing::default());
    assert!(params.with_crease_angle(180.0).is_err() && params.with_crease_angle(f64::NAN).is_err());
}

/// Graded towards its inside corners (every wall edge, the blocks' bottoms, the floor
/// around them), each surface of the Cornell box is still a disc without T-vertices:
/// V − E + F = 1 (a vertex inside a neighbour's side would add two sides and one vertex),
/// keeps its area, and has elements a quarter as wide as the rest along its corners.
/// Every surface of `mesh` is a disc (Euler characteristic 1 over its elements): no
/// element overlaps another and no side is left with a T-vertex.
fn assert_discs(mesh: &Mesh) {
    for (s, surface) in mesh.surfaces.iter().enumerate() {
        let patches = surface.patches.start as usize..surface.patches.end as usize;
        let elements = mesh.patches[patches.start].elements.start as usize
            ..mesh.patches[patches.end - 1].elements.end as usize;
        let mut vertices = std::collections::HashSet::new();
        let mut sides = std::collections::HashSet::new();
        for e in elements.clone() {
            let v = mesh.elements[e].vertex_indices();
            for k in 0..v.len() {
                vertices.insert(v[k]);
                sides.insert((v[k].min(v[(k + 1) % v.len()]), v[k].max(v[(k + 1) % v.len()])));
            }
        }
        let euler = vertices.len() as i64 - sides.len() as i64 + elements.len() as i64;
        assert_eq!(euler, 1, "surface {s} of '{}'", mesh.object_names[surface.object as usize]);
    }
}

/// A board 5 cm over a 4 × 4 floor of 25 cm elements: with `proximity_refinement` 0, or
/// with a board that emits, the floor is the plain lattice; one level halves the elements
/// near the board once; two quarter those under it twice (a quarter of the element size,
/// no finer), leave the floor far from it as it was, keep the area, and every surface
/// stays conforming.
#[test]
fn elements_under_a_board_are_quartered_down_to_the_distance() {
    let at = |y: f64, lo: f64, hi: f64| {
        vec![DVec3::new(lo, y, lo), DVec3::new(lo, y, hi), DVec3::new(hi, y, hi), DVec3::new(hi, y, lo)]
    };
    let floor = Polygon::try_new(at(0.0, 0.0, 4.0)).unwrap();
    let board = radiosity_core::box_faces(
        DVec3::new(1.5, 0.05, 1.5),
        DVec3::new(2.5, 0.1, 2.5),
        radiosity_core::Facing::Outward,
        0.0,
    )
    .unwrap();
    let lit = Material::try_new("lit", Rgb::splat(0.5), Rgb::ONE).unwrap();
    let wood = Material::try_new("wood", Rgb::splat(0.5), Rgb::ZERO).unwrap();
    let object = |name: &str, material, ps| Object {
        name: name.into(),
        material,
        shape: Shape::Polygons(ps),
        sides: radiosity_core::Sides::One,
    };
    let scene_with_board = |board_material| {
        let objects =
            vec![object("floor", 0, vec![floor.clone()]), object("board", board_material, board.clone())];
        Scene::try_new("board", None, vec![lit.clone(), wood.clone()], objects).unwrap()
    };
    let scene = scene_with_board(1);
    let params = MeshParams::try_new(1.0, 0.25).unwrap();
    let longest = |mesh: &Mesh, e: usize| {
        let pts: Vec<DVec3> = mesh.element_corners(e).collect();
        (0..pts.len()).map(|k| pts[k].distance(pts[(k + 1) % pts.len()])).fold(0.0, f64::max)
    };
    let floor_elements =
        |mesh: &Mesh| (0..mesh.elements.len()).filter(|&e| mesh.element_object(e) == 0).collect::<Vec<_>>();
    let plain = Mesh::build(&scene, &params.with_proximity_refinement(0).unwrap()).unwrap();
    assert_eq!(floor_elements(&plain).len(), 256);
    // A board that emits (a lamp hung low) refines nothing.
    let lamp = Mesh::build(&scene_with_board(0), &params.with_proximity_refinement(2).unwrap()).unwrap();
    assert_eq!(floor_elements(&lamp).len(), 256);
    // One level halves the floor's elements near the board once.
    let once = Mesh::build(&scene, &params.with_proximity_refinement(1).unwrap()).unwrap();
    let sizes = floor_elements(&once).into_iter().map(|e| longest(&once, e));
    assert!(sizes.fold(f64::MAX, f64::min) > 0.125 - 1e-9);
    assert!(floor_elements(&once).len() > 256);
    let refined = Mesh::build(&scene, &params.with_proximity_refinement(2).unwrap()).unwrap();
    assert_discs(&refined);
    assert!((refined.total_area() - plain.total_area()).abs() < 1e-9 * plain.total_area());
    // Horizontal distance of an element's centre from the board's footprint.
    let outside = |c: DVec3| {
        let d = |x: f64| (1.5 - x).max(x - 2.5).max(0.0);
        d(c.x).hypot(d(c.z))
    };
    let (mut under, mut far) = (0, 0);
    for e in floor_elements(&refined) {
        let c = refined.elements[e].centre;
        let size = longest(&refined, e);
        assert!(size >= 0.0625 - 1e-9, "element {e} at {c}: {size}");
        if (1.75..2.25).contains(&c.x) && (1.75..2.25).contains(&c.z) {
            assert!(size <= 0.0625 + 1e-9, "under the board at {c}: {size}");
            under += 1;
        }
        if outside(c) > 0.6 {
            assert!((size - 0.25).abs() < 1e-9, "far from the board at {c}: {size}");
            far += 1;
        }
    }
    assert_eq!(under, 64, "the middle 0.5 × 0.5 in 6.25 cm squares");
    assert!(far > 150, "{far}");
}

#[test]
fn graded_cornell_surfaces_stay_conforming() {
    let scene = radiosity_scenes::cornell_box();
    let params = scene.mesh_params();
    // Graded corners and one level near other geometry (the blocks near the walls).
    let graded = Mesh::build(&scene, &params.with_proximity_refinement(1).unwrap()).unwrap();
    let plain = params.with_corner_refinement(0).and_then(|p| p.with_proximity_refinement(0)).unwrap();
    let plain = Mesh::build(&scene, &plain).unwrap();
    assert!(graded.elements.len() > plain.elements.len() * 5 / 4, "{}", graded.elements.len());
    assert_eq!(graded.patches.len(), plain.patches.len());
    assert_discs(&graded);
    assert!((graded.total_area() - plain.total_area()).abs() < 1e-9 * plain.total_area());
    let thinnest = |m: &Mesh| m.elements.iter().map(|e| e.area).fold(f64::INFINITY, f64::min);
    assert!(thinnest(&graded) < 0.3 * thinnest(&plain));
}

/// A refinement names elements by surface and centre: meshing again quarters exactly
/// those (the floor's, here: about four times as many elements, the rest unchanged but for
/// the fans that take the floor pieces' split sides), keeps the area, and every surface
/// stays a disc without T-vertices. A second level quarters the first level's elements.
#[test]
fn a_refinement_quarters_the_elements_it_names() {
    let scene = radiosity_scenes::cornell_box();
    let params = scene.mesh_params();
    let mesh = Mesh::build(&scene, &params).unwrap();
    let floor = mesh.object_names.iter().position(|n| n == "floor").unwrap();
    let on_floor =
        |m: &Mesh| (0..m.elements.len()).filter(|&e| m.element_object(e) == floor).collect::<Vec<_>>();
    let mut refinement = Refinement::default();
    let named = refinement.add_level(&mesh, on_floor(&mesh));
    assert_eq!(named, on_floor(&mesh).len());
    let refined = Mesh::build_refined(&scene, &params, &refinement).unwrap();
    let (before, after) = (on_floor(&mesh).len(), on_floor(&refined).len());
    assert!(after >= 4 * before && after < 5 * before, "{before} → {after}");
    assert_eq!(refined.elements.len() - after, mesh.elements.len() - before, "only the floor changes");
    assert!((refined.total_area() - mesh.total_area()).abs() < 1e-9 * mesh.total_area());
    let euler = |m: &Mesh, s: usize| {
        let surface = &m.surfaces[s];
        let patches = surface.patches.start as usize..surface.patches.end as usize;
        let elements = m.patches[patches.start].elements.start as usize
            ..m.patches[patches.end - 1].elements.end as usize;
        let mut vertices = HashSet::default();
        let mut sides = HashSet::default();
        for e in elements.clone() {
            let v = m.elements[e].vertex_indices();
            for k in 0..v.len() {
                vertices.insert(v[k]);
                let w = v[(k + 1) % v.len()];
                sides.insert((v[k].min(w), v[k].max(w)));
            }
        }
        vertices.len() as i64 - sides.len() as i64 + elements.len() as i64
    };
    for s in 0..refined.surfaces.len() {
        assert_eq!(euler(&refined, s), 1, "surface {s}");
    }
    let again = refinement.add_level(&refined, on_floor(&refined).into_iter().take(10));
    assert_eq!(again, 10);
    let twice = Mesh::build_refined(&scene, &params, &refinement).unwrap();
    assert!(on_floor(&twice).len() >= after + 30);
}

/// The Cornell box's blocks stand on its floor: the floor's mesh leaves out exactly their
/// footprints (no element of the floor lies under a block, and mesh area plus hidden
/// area is the floor's), and nothing else is cut. Without contacts the floor is whole.
#[test]
fn the_cornell_floor_is_cut_around_the_blocks() {
    let scene = radiosity_scenes::cornell_box();
    let params = scene.mesh_params();
    let floor_of = |mesh: &Mesh| {
        let o = mesh.object_names.iter().position(|n| n == "floor").unwrap();
        let elements: Vec<Element> = mesh
            .elements
            .iter()
            .enumerate()
            .filter(|(e, _)| mesh.element_object(*e) == o)
            .map(|x| *x.1)
            .collect();
        (o, elements)
    };
    let cut = Mesh::build(&scene, &params).unwrap();
    let whole = Mesh::build(&scene, &params.with_contacts(false)).unwrap();
    let (o, elements) = floor_of(&cut);
    let input_area = match &scene.objects[o].shape {
        Shape::Polygons(ps) => ps.iter().map(Polygon::area).sum::<f64>(),
        _ => unreachable!(),
    };
    let meshed: f64 = elements.iter().map(|e| e.area).sum();
    assert!(
        (meshed + cut.hidden_area[o] - input_area).abs() < 1e-6 * input_area,
        "{meshed} + {}",
        cut.hidden_area[o]
    );
    // The two footprints: the blocks' side faces' bottom corners, about 165 mm square.
    assert!((cut.hidden_area[o] / (2.0 * 165.0 * 165.0) - 1.0).abs() < 0.05, "{}", cut.hidden_area[o]);
    assert_eq!(cut.hidden_area.iter().filter(|&&a| a > 0.0).count(), 1, "only the floor is cut");
    // The blocks' own corners on the floor, and every floor element's centre outside both.
    let blocks: Vec<Vec<DVec3>> = ["short_block", "tall_block"]
        .iter()
        .map(|b| {
            scene
                .objects
                .iter()
                .filter(|ob| ob.name.starts_with(b) && !ob.name.ends_with("top"))
                .flat_map(|ob| match &ob.shape {
                    Shape::Polygons(ps) => ps.iter().flat_map(|p| p.vertices().to_vec()).collect::<Vec<_>>(),
                    _ => vec![],
                })
                .filter(|v| v.y.abs() < 1e-6)
                .collect()
        })
        .collect();
    for corners in &blocks {
        let (lo, hi) = corners.iter().fold((corners[0], corners[0]), |(l, h), &c| (l.min(c), h.max(c)));
        let centre = (lo + hi) * 0.5;
        // A point well inside the block's footprint (its corners' centre) has no element.
        let covered = elements.iter().any(|e| (e.centre - centre).length() < 40.0);
        assert!(!covered, "a floor element under the block at {centre}");
    }
    let (_, whole_elements) = floor_of(&whole);
    assert!(whole.hidden_area.iter().all(|&a| a == 0.0));
    assert!((whole_elements.iter().map(|e| e.area).sum::<f64>() - input_area).abs() < 1e-6 * input_area);
}

/// The furnace's walls face each other: none faces away from the light. Turned inside out
/// (outward walls, lit by one of them), every wall but the lamp's faces away from it.
#[test]
fn walls_facing_away_from_every_emitter_are_found() {
    let params = MeshParams::try_new(0.5, 0.5).unwrap();
    let inward = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Inward, 0.0).unwrap();
    let room = Mesh::build(&scene_of(Shape::Polygons(inward)), &params).unwrap();
    assert_eq!(room.area_facing_away_from_light(&[]), vec![0.0; 6]);
    let outward = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Outward, 0.0).unwrap();
    let lamp = Material::try_new("lamp", Rgb::ZERO, Rgb::ONE).unwrap();
    let grey = Material::try_new("grey", Rgb::splat(0.5), Rgb::ZERO).unwrap();
    let floor = Polygon::try_new(vec![
        DVec3::new(0.2, 0.1, 0.2),
        DVec3::new(0.8, 0.1, 0.2),
        DVec3::new(0.8, 0.1, 0.8),
        DVec3::new(0.2, 0.1, 0.8),
    ])
    .unwrap();
    let scene = Scene::try_new(
        "inside out",
        None,
        vec![lamp, grey],
        vec![
            Object::new("walls", 1, Shape::Polygons(outward)),
            Object::new("lamp", 0, Shape::Polygons(vec![floor])),
        ],
    )
    .unwrap();
    let mesh = Mesh::build(&scene, &params).unwrap();
    let away = mesh.area_facing_away_from_light(&[]);
    // The lamp faces down (counter-clockwise from below is clockwise from above): the
    // walls' outward faces, one surface each, all have it behind them.
    assert_eq!(away.len(), 7);
    assert!(away[..6].iter().all(|a| (a - 1.0).abs() < 1e-9), "{away:?}");
    assert_eq!(away[6], 0.0, "emitters are not counted");
    // A luminaire outside the box counts as a light too: in front of three walls.
    let away = mesh.area_facing_away_from_light(&[DVec3::new(2.0, 2.0, 2.0)]);
    let facing_it = away[..6].iter().filter(|&&a| a == 0.0).count();
    assert_eq!(facing_it, 3, "{away:?}");
    // Inside, lit by a luminaire alone: the room's inward walls all face it.
    let unlit = Material::try_new("unused", Rgb::ZERO, Rgb::ZERO).unwrap();
    let grey = Material::try_new("grey", Rgb::splat(0.5), Rgb::ZERO).unwrap();
    let faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Inward, 0.0).unwrap();
    let objects = vec![Object::new("walls", 1, Shape::Polygons(faces))];
    let room = Scene::try_new_unlit("luminaire", None, vec![unlit, grey], objects).unwrap();
    let room = Mesh::build(&room, &params).unwrap();
    assert_eq!(room.area_facing_away_from_light(&[DVec3::splat(0.5)]), vec![0.0; 6]);
    let outside = room.area_facing_away_from_light(&[DVec3::new(0.5, 0.5, 3.0)]);
    assert_eq!(outside.iter().filter(|&&a| a > 0.0).count(), 1, "the +z wall's back faces it: {outside:?}");
}

#[test]
fn a_face_with_a_hole_is_one_surface_around_it() {
    // A 3 × 3 square with a 1 × 1 window in the middle, triangulated by hand around it.
    let ring =
        |s: f64, o: f64| [(o, o), (o + s, o), (o + s, o + s), (o, o + s)].map(|(x, y)| DVec3::new(x, y, 0.0));
    let positions: Vec<DVec3> = ring(3.0, 0.0).into_iter().chain(ring(1.0, 1.0)).collect();
    let mut faces = Vec::new();
    for k in 0..4u32 {
        let (o0, o1, i0, i1) = (k, (k + 1) % 4, 4 + k, 4 + (k + 1) % 4);
        faces.push(vec![o0, o1, i1]);
        faces.push(vec![o0, i1, i0]);
    }
    let wall = PolygonMesh::try_new(positions, faces).unwrap();
    let params = MeshParams::try_new(1.0, 0.25).unwrap();
    let mesh = Mesh::build(&scene_of(Shape::Mesh(wall)), &params).unwrap();
    assert_eq!(mesh.surfaces.len(), 1);
    check_mesh(&mesh, 8.0, &params);
    // An annulus: V − E + F = 0 only when every piece's points merged and none covers the hole.
    assert_eq!(euler_characteristic(&mesh), 0);
    for e in &mesh.elements {
        let c = e.centre;
        assert!(!(c.x > 1.0 && c.x < 2.0 && c.y > 1.0 && c.y < 2.0), "an element in the hole at {c}");
    }
}

/// A wall (4 × 2.5, a 1 × 1 window in it when `window`) with a skirting board 1.5 cm in
/// front of it along its whole width, 0.2 high, whose top closes the gap: one model. No
/// element of the wall lies across the line where the board's top meets it (the light above
/// the line and the dark gap below would be averaged and shot into the gap), the wall keeps
/// its area, and its elements still meet corner to corner.
#[test]
fn a_wall_is_cut_where_a_skirting_boards_top_meets_it() {
    for window in [false, true] {
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let mut positions = vec![p(0.0, 0.0, 0.0), p(4.0, 0.0, 0.0), p(4.0, 2.5, 0.0), p(0.0, 2.5, 0.0)];
        let mut faces: Vec<Vec<u32>> = Vec::new();
        if window {
            positions.extend([p(1.5, 1.0, 0.0), p(2.5, 1.0, 0.0), p(2.5, 2.0, 0.0), p(1.5, 2.0, 0.0)]);
            for k in 0..4u32 {
                let (o0, o1, i0, i1) = (k, (k + 1) % 4, 4 + k, 4 + (k + 1) % 4);
                faces.push(vec![o0, o1, i1]);
                faces.push(vec![o0, i1, i0]);
            }
        } else {
            faces.extend([vec![0, 1, 2], vec![0, 2, 3]]);
        }
        let b = positions.len() as u32;
        // The board's front (facing +z) and its top (facing +y), down to the wall.
        positions.extend([p(0.0, 0.0, 0.015), p(4.0, 0.0, 0.015), p(4.0, 0.2, 0.015), p(0.0, 0.2, 0.015)]);
        positions.extend([p(0.0, 0.2, 0.0), p(4.0, 0.2, 0.0)]);
        faces.extend([vec![b, b + 1, b + 2], vec![b, b + 2, b + 3]]);
        faces.extend([vec![b + 3, b + 2, b + 5], vec![b + 3, b + 5, b + 4]]);
        let model = PolygonMesh::try_new(positions, faces).unwrap();
        let params = MeshParams::try_new(1.0, 0.25).unwrap();
        let mesh = Mesh::build(&scene_of(Shape::Mesh(model)), &params).unwrap();
        let wall: Vec<&Element> =
            mesh.elements.iter().filter(|e| e.normal.z > 0.999 && e.centre.z.abs() < 1e-9).collect();
        let area: f64 = wall.iter().map(|e| e.area).sum();
        let expected = if window { 9.0 } else { 10.0 };
        assert!((area - expected).abs() < 1e-9, "window {window}: wall area {area}");
        for e in &wall {
            let ys: Vec<f64> = e.vertex_indices().iter().map(|&v| mesh.positions[v as usize].y).collect();
            let across = ys.iter().any(|&y| y < 0.2 - 1e-9) && ys.iter().any(|&y| y > 0.2 + 1e-9);
            assert!(!across, "window {window}: an element across the board's top: {ys:?}");
        }
        if window {
            // One surface around a hole: V − E + F = 0 when every element meets its
            // neighbours corner to corner.
            let mut edges = HashSet::default();
            let mut vertices = HashSet::default();
            for e in &wall {
                let v = e.vertex_indices();
                for k in 0..v.len() {
                    let (a, b) = (v[k], v[(k + 1) % v.len()]);
                    edges.insert((a.min(b), a.max(b)));
                    vertices.insert(a);
                }
            }
            assert_eq!(vertices.len() as i64 - edges.len() as i64 + wall.len() as i64, 0);
        }
    }
}
