//! Tests of contacts: footprints found, polygons cut around them, faces pressed flat.

use super::*;
use radiosity_core::{Facing, box_faces};
use radiosity_core::{Material, Object, Rgb};

fn quad(y: f64, size: f64) -> Polygon {
    Polygon::try_new(vec![
        DVec3::new(0.0, y, 0.0),
        DVec3::new(0.0, y, size),
        DVec3::new(size, y, size),
        DVec3::new(size, y, 0.0),
    ])
    .unwrap()
}

fn floor_and(block: Vec<Polygon>) -> Scene {
    let grey = Material::try_new("grey", Rgb::splat(0.5), Rgb::ZERO).unwrap();
    let lamp = Material::try_new("lamp", Rgb::ZERO, Rgb::ONE).unwrap();
    Scene::try_new(
        "floor",
        None,
        vec![grey, lamp],
        vec![
            Object::new("floor", 0, Shape::Polygons(vec![quad(0.0, 4.0)])),
            Object::new("block", 0, Shape::Polygons(block)),
            Object::new("lamp", 1, Shape::Polygons(vec![quad(3.0, 1.0)])),
        ],
    )
    .unwrap()
}

/// A box standing on the floor: the floor is cut into convex pieces around its footprint,
/// whose area is what goes missing; the box's bottom is pressed flat on the floor.
#[test]
fn a_box_on_the_floor_cuts_its_footprint_out() {
    let block =
        box_faces(DVec3::new(1.0, 0.0, 1.5), DVec3::new(2.0, 1.0, 3.0), Facing::Outward, 20.0).unwrap();
    let scene = floor_and(block.clone());
    let contacts = Contacts::new(&scene);
    let Shape::Polygons(floor) = &scene.objects[0].shape else { unreachable!() };
    let cut = contacts
        .cut(&floor[0], Some(PolygonId { object: 0, index: 0 }), false, |q| (q.area() * 100.0) as usize)
        .expect("a cut");
    assert!((cut.hidden - 1.5).abs() < 1e-9, "hidden {}", cut.hidden);
    let kept: f64 = cut.pieces.iter().map(Polygon::area).sum();
    assert!((kept + cut.hidden - 16.0).abs() < 1e-9, "kept {kept}");
    assert!(cut.pieces.len() >= 4 && cut.pieces.iter().all(|p| p.normal().dot(DVec3::Y) > 0.999));
    // No piece overlaps the footprint (the bottom's outline, turned to face up): every
    // piece's centre is outside it.
    let bottom = block.iter().position(|p| p.normal().y < -0.99).unwrap();
    let footprint: Vec<DVec3> = block[bottom].vertices().iter().rev().copied().collect();
    for p in &cut.pieces {
        let c = p.vertices().iter().copied().sum::<DVec3>() / p.vertices().len() as f64;
        assert!(!contains_within(&footprint, DVec3::Y, c, 0.0), "{c}");
    }
    assert!(contacts.is_pressed_flat(PolygonId { object: 1, index: bottom }, &block[bottom]));
    // The floor is not pressed against the (smaller) bottom: only a face lying within
    // the other one is.
    assert!(!contacts.is_pressed_flat(PolygonId { object: 0, index: 0 }, &floor[0]));
    let top = block.iter().position(|p| p.normal().y > 0.99).unwrap();
    assert!(!contacts.is_pressed_flat(PolygonId { object: 1, index: top }, &block[top]));
    // The lamp hangs above: it cuts nothing; the floor's own plane holds nothing else.
    let Shape::Polygons(lamp) = &scene.objects[2].shape else { unreachable!() };
    assert!(
        contacts
            .cut(&lamp[0], Some(PolygonId { object: 2, index: 0 }), false, |q| (q.area() * 100.0) as usize)
            .is_none()
    );
}

/// The floor's hidden area with `block` on it, or `None` when it is not cut.
fn hidden_under(block: Vec<Polygon>) -> Option<f64> {
    let scene = floor_and(block);
    let contacts = Contacts::new(&scene);
    let Shape::Polygons(floor) = &scene.objects[0].shape else { unreachable!() };
    contacts
        .cut(&floor[0], Some(PolygonId { object: 0, index: 0 }), false, |q| (q.area() * 100.0) as usize)
        .map(|c| c.hidden)
}

/// A box floating above the floor, or one sunk through it, or open at the bottom in a way
/// that leaves no closed outline: nothing is cut. One set a little into the floor cuts.
#[test]
fn only_solids_standing_on_the_surface_cut_it() {
    let floating =
        box_faces(DVec3::new(1.0, 0.1, 1.0), DVec3::new(2.0, 1.0, 2.0), Facing::Outward, 0.0).unwrap();
    assert_eq!(hidden_under(floating), None);
    let sunk =
        box_faces(DVec3::new(1.0, -0.5, 1.0), DVec3::new(2.0, 1.0, 2.0), Facing::Outward, 0.0).unwrap();
    assert_eq!(hidden_under(sunk), None);
    // Set a centimetre into the floor, as exported doors and table legs are, turned so that
    // no edge lies along an axis: it stands on its footprint where its sides cross the floor.
    let set_in =
        box_faces(DVec3::new(1.0, -0.01, 1.0), DVec3::new(2.0, 1.0, 2.0), Facing::Outward, 20.0).unwrap();
    let hidden = hidden_under(set_in).expect("the floor cut around it");
    assert!((hidden - 1.0).abs() < 1e-9, "hidden {hidden}");
    // Three sides of a box: the outline does not close.
    let mut open =
        box_faces(DVec3::new(1.0, 0.0, 1.0), DVec3::new(2.0, 1.0, 2.0), Facing::Outward, 0.0).unwrap();
    open.retain(|p| p.normal().x < 0.5 && p.normal().y.abs() < 0.5);
    assert_eq!(hidden_under(open), None);
    // Four sides and no lid: the floor inside is lit from above.
    let mut no_lid =
        box_faces(DVec3::new(1.0, 0.0, 1.0), DVec3::new(2.0, 1.0, 2.0), Facing::Outward, 0.0).unwrap();
    no_lid.retain(|p| p.normal().y.abs() < 0.5);
    assert_eq!(hidden_under(no_lid.clone()), None);
    let standing =
        box_faces(DVec3::new(1.0, 0.0, 1.0), DVec3::new(2.0, 1.0, 2.0), Facing::Outward, 0.0).unwrap();
    assert!((hidden_under(standing).unwrap() - 1.0).abs() < 1e-9);
    // The same sides with a lid and no bottom (how the Cornell box's blocks are given).
    let lid = box_faces(DVec3::new(1.0, 0.0, 1.0), DVec3::new(2.0, 1.0, 2.0), Facing::Outward, 0.0)
        .unwrap()
        .into_iter()
        .filter(|p| p.normal().y > 0.5);
    assert!((hidden_under(no_lid.into_iter().chain(lid).collect()).unwrap() - 1.0).abs() < 1e-9);
}

/// Boxes pressed side by side (a sofa's seat between its arms, in one object) stand on
/// the union of their footprints; a box whose faces are each given twice, once each way
/// round, still stands on its own.
#[test]
fn boxes_side_by_side_stand_on_one_footprint() {
    let cuboid = |x0: f64, x1: f64, top: f64| {
        box_faces(DVec3::new(x0, 0.0, 1.0), DVec3::new(x1, top, 1.8), Facing::Outward, 0.0).unwrap()
    };
    let sofa: Vec<Polygon> =
        [cuboid(0.8, 1.0, 0.62), cuboid(1.0, 3.2, 0.42), cuboid(3.2, 3.4, 0.62)].concat();
    let hidden = hidden_under(sofa).expect("the sofa cuts the floor");
    assert!((hidden - 2.6 * 0.8).abs() < 1e-9, "{hidden}");
    let both_ways: Vec<Polygon> = cuboid(1.0, 2.0, 1.0)
        .into_iter()
        .flat_map(|p| {
            let back = Polygon::try_new(p.vertices().iter().rev().copied().collect()).unwrap();
            [p, back]
        })
        .collect();
    let hidden = hidden_under(both_ways).expect("a box given both ways round cuts the floor");
    assert!((hidden - 0.8).abs() < 1e-9, "{hidden}");
}

/// A table leg under its table top: straight above the leg's footprint, the leg's top
/// and the top's underside meet at one height, and the leg's footprint still cuts (the
/// underside, met first from the front, once made it look open to the light).
#[test]
fn a_leg_under_a_table_top_cuts_its_footprint() {
    let leg = box_faces(DVec3::new(1.0, 0.0, 1.0), DVec3::new(1.2, 1.0, 1.2), Facing::Outward, 0.0).unwrap();
    let top = box_faces(DVec3::new(0.5, 1.0, 0.5), DVec3::new(2.5, 1.1, 2.5), Facing::Outward, 0.0).unwrap();
    let hidden = hidden_under([top, leg].concat()).expect("the leg cuts the floor");
    assert!((hidden - 0.04).abs() < 1e-9, "{hidden}");
}

/// A footprint half off the surface's edge hides only the part on it.
#[test]
fn a_footprint_over_the_edge_hides_its_overlap() {
    let block =
        box_faces(DVec3::new(3.5, 0.0, 1.0), DVec3::new(4.5, 1.0, 2.0), Facing::Outward, 0.0).unwrap();
    let scene = floor_and(block);
    let contacts = Contacts::new(&scene);
    let Shape::Polygons(floor) = &scene.objects[0].shape else { unreachable!() };
    let cut = contacts
        .cut(&floor[0], Some(PolygonId { object: 0, index: 0 }), false, |q| (q.area() * 100.0) as usize)
        .unwrap();
    assert!((cut.hidden - 0.5).abs() < 1e-9, "{}", cut.hidden);
    let kept: f64 = cut.pieces.iter().map(Polygon::area).sum();
    assert!((kept - 15.5).abs() < 1e-9, "{kept}");
}

/// A vertical board standing on the floor 2 cm from its edge, `length` long from x = 0.
fn board(length: f64) -> Vec<Polygon> {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    vec![
        Polygon::try_new(vec![
            p(0.0, 0.0, 0.02),
            p(length, 0.0, 0.02),
            p(length, 0.2, 0.02),
            p(0.0, 0.2, 0.02),
        ])
        .unwrap(),
        // Its top, closing the gap behind it up to the floor's edge.
        Polygon::try_new(vec![
            p(0.0, 0.2, 0.02),
            p(length, 0.2, 0.02),
            p(length, 0.2, 0.0),
            p(0.0, 0.2, 0.0),
        ])
        .unwrap(),
    ]
}

/// A skirting board along the whole of the floor's edge cuts the floor along its foot, so
/// no element lies both in the 2 cm gap behind it and in the lit room; one along a quarter
/// of the edge does not cut the whole floor.
#[test]
fn a_board_along_the_surface_cuts_a_seam_and_a_short_one_does_not() {
    let scene = floor_and(board(4.0));
    let contacts = Contacts::new(&scene);
    let Shape::Polygons(floor) = &scene.objects[0].shape else { unreachable!() };
    let id = Some(PolygonId { object: 0, index: 0 });
    let seams = contacts.seams(std::slice::from_ref(&floor[0].vertices()), DVec3::Y, id, false);
    assert_eq!(seams.len(), 1, "{seams:?}");
    assert!(seams[0].dir.abs().abs_diff_eq(DVec3::X, 1e-12) && (seams[0].at.z - 0.02).abs() < 1e-12);
    let cut = contacts.cut(&floor[0], id, false, |q| (q.area() * 100.0) as usize).expect("a seam");
    assert_eq!(cut.hidden, 0.0);
    let mut areas: Vec<f64> = cut.pieces.iter().map(Polygon::area).collect();
    areas.sort_by(f64::total_cmp);
    assert!((areas[0] - 0.08).abs() < 1e-12 && (areas[1] - 15.92).abs() < 1e-9, "{areas:?}");

    let scene = floor_and(board(1.0));
    let contacts = Contacts::new(&scene);
    let Shape::Polygons(floor) = &scene.objects[0].shape else { unreachable!() };
    assert!(contacts.seams(std::slice::from_ref(&floor[0].vertices()), DVec3::Y, id, false).is_empty());
    assert!(contacts.cut(&floor[0], id, false, |q| (q.area() * 100.0) as usize).is_none());
}

/// A board standing under the floor (against its back): it cuts a seam only when the floor
/// is two-sided, as its back face then takes light that the board shapes.
#[test]
fn a_board_against_the_back_cuts_a_two_sided_surface_only() {
    let under: Vec<Polygon> = board(4.0)
        .iter()
        .map(|p| {
            Polygon::try_new(p.vertices().iter().map(|v| v * DVec3::new(1.0, -1.0, 1.0)).collect()).unwrap()
        })
        .collect();
    let scene = floor_and(under);
    let contacts = Contacts::new(&scene);
    let Shape::Polygons(floor) = &scene.objects[0].shape else { unreachable!() };
    let id = Some(PolygonId { object: 0, index: 0 });
    let corners = floor[0].vertices();
    let region = std::slice::from_ref(&corners);
    assert!(contacts.seams(region, DVec3::Y, id, false).is_empty());
    let seams = contacts.seams(region, DVec3::Y, id, true);
    assert_eq!(seams.len(), 1, "{seams:?}");
    assert!((seams[0].at.z - 0.02).abs() < 1e-12, "{seams:?}");
}

/// A small face passing through a large one (a door handle's stem through the door) is cut
/// along the line where it passes; one only touching it, or standing beside it, stays whole.
#[test]
fn a_small_face_is_cut_where_another_passes_through_it() {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    // The stem: 2 cm wide, from 3 cm behind the floor's plane to 5 cm above it.
    let stem = |from: f64, x: f64| {
        Polygon::try_new(vec![p(x, from, 1.0), p(x, from, 1.02), p(x, 0.05, 1.02), p(x, 0.05, 1.0)]).unwrap()
    };
    let scene = floor_and(vec![stem(-0.03, 1.0), stem(0.0, 2.0), stem(-0.03, 5.0)]);
    let contacts = Contacts::new(&scene);
    let Shape::Polygons(stems) = &scene.objects[1].shape else { unreachable!() };
    let id = |index| Some(PolygonId { object: 1, index });
    let pieces = contacts.small_face_cut(&stems[0], id(0), false).expect("cut where the floor passes");
    assert_eq!(pieces.len(), 2);
    let mut spans: Vec<(f64, f64)> = pieces
        .iter()
        .map(|q| q.vertices().iter().fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v.y), hi.max(v.y))))
        .collect();
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!((spans[0].0 + 0.03).abs() < 1e-12 && spans[0].1.abs() < 1e-12, "{spans:?}");
    assert!(spans[1].0.abs() < 1e-12 && (spans[1].1 - 0.05).abs() < 1e-12, "{spans:?}");
    let total: f64 = pieces.iter().map(Polygon::area).sum();
    assert!((total - stems[0].area()).abs() < 1e-12);
    assert!(contacts.small_face_cut(&stems[1], id(1), true).is_none(), "standing on it");
    assert!(contacts.small_face_cut(&stems[2], id(2), true).is_none(), "beside the floor");
}
