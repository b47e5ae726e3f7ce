//! Luminaires inside solids.
//!
//! [`luminaires_in_solids`] finds the luminaires placed inside a closed object whose light
//! stays in it: the generalised winding number of the closed surface about the luminaire
//! (Jacobson, Kavan & Sorkine-Hornung 2013, "Robust inside-outside segmentation using
//! generalized winding numbers"), the sum of its triangles' signed solid angles by Van
//! Oosterom & Strackee's formula (1983, "The solid angle of a plane triangle") over 4π: 1
//! inside a surface wound outwards, −1 inside one wound inwards, 0 outside.
//!
//! A fitting's body modelled as a closed block around the luminaire's photometric centre
//! keeps all of its light inside; the command warns of such luminaires, before sealing. Closed surfaces are found as [`crate::seal_closed_objects`] finds them,
//! small holes capped.

use glam::DVec3;

use crate::sealed::Holes;
use radiosity_core::{Polygon, Scene, Shape, Sides};

/// Triangle solid angles [`luminaires_in_solids`] evaluates at most, over all luminaires and
/// objects together: a fraction of a second, so a scene of a hundred luminaires in a
/// million-triangle building is checked as far as that goes and loads without delay.
pub const MAX_WINDING_TRIANGLES: u64 = 4_000_000;

/// A closed surface as triangles, wound as its faces.
type Triangles = Vec<[DVec3; 3]>;

/// A luminaire inside a closed object, on the back side of its faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EnclosedLuminaire {
    /// Its index in the scene's luminaires.
    pub luminaire: usize,
    /// The object's index in the scene's objects.
    pub object: usize,
}

/// What [`luminaires_in_solids`] found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LuminaireEnclosures {
    /// Each luminaire inside a solid, by luminaire then object.
    pub enclosed: Vec<EnclosedLuminaire>,
    /// Pairs of a luminaire and a closed object around its position that were not tested
    /// because [`MAX_WINDING_TRIANGLES`] was spent.
    pub unchecked: usize,
}

/// The luminaires of `scene` that sit inside a solid: a closed object (faces that close up
/// as [`crate::seal_closed_objects`] asks, holes capped, or a sphere) wound outwards about the
/// luminaire's [`radiosity_core::Luminaire::light_point`], so that its light meets only the
/// back of the faces around it and stays in there. A two-sided object around every other object is a
/// room modelled with its normals out ([`crate::seal_closed_objects`] turns it), not a solid. Call
/// it on the scene as given, before sealing, which may turn such a solid inside out.
///
/// Objects whose bounds do not hold the point cost nothing; the others cost a solid angle
/// per triangle, [`MAX_WINDING_TRIANGLES`] in all (the rest are counted as unchecked).
pub fn luminaires_in_solids(scene: &Scene) -> LuminaireEnclosures {
    let mut found = LuminaireEnclosures::default();
    if scene.lighting.luminaires.is_empty() {
        return found;
    }
    let (lo, hi) = scene.bounds();
    let step = 1e-6 * lo.distance(hi).max(f64::MIN_POSITIVE);
    let points: Vec<DVec3> = scene.lighting.luminaires.iter().map(|l| l.light_point(step)).collect();
    let bounds: Vec<(DVec3, DVec3)> = scene.objects.iter().map(|o| o.bounds()).collect();
    let inside_box = |p: DVec3, (a, b): (DVec3, DVec3)| p.cmpge(a).all() && p.cmple(b).all();
    let mut spent = 0u64;
    // Per object, once a luminaire falls in its bounds: its closed surface's triangles
    // (`None`: not closed).
    let mut surfaces: Vec<Option<Option<Triangles>>> = vec![None; scene.objects.len()];
    for (l, &p) in points.iter().enumerate() {
        for (i, o) in scene.objects.iter().enumerate() {
            if !inside_box(p, bounds[i]) {
                continue;
            }
            let two_sided = matches!(o.sides, Sides::Two { .. });
            let winding = match &o.shape {
                Shape::Sphere(s) if p.distance(s.center) < s.radius => match s.facing {
                    radiosity_core::Facing::Outward => 1.0,
                    radiosity_core::Facing::Inward => -1.0,
                },
                Shape::Sphere(_) => 0.0,
                Shape::Polygons(ps) => winding_of(&mut surfaces[i], ps, p, &mut spent, &mut found.unchecked),
                Shape::Mesh(m) => {
                    winding_of(&mut surfaces[i], m.polygons(), p, &mut spent, &mut found.unchecked)
                }
            };
            if winding <= 0.5 {
                continue;
            }
            // A two-sided surface around every other object is the scene's room.
            let room = two_sided
                && bounds
                    .iter()
                    .enumerate()
                    .all(|(j, &(a, b))| j == i || (inside_box(a, bounds[i]) && inside_box(b, bounds[i])));
            if !room {
                found.enclosed.push(EnclosedLuminaire { luminaire: l, object: i });
            }
        }
    }
    found
}

/// The winding number about `p` of the closed surface of `polygons` (cached in `surface`),
/// or 0 when it is not closed or the budget is spent (then counted in `unchecked`).
fn winding_of(
    surface: &mut Option<Option<Triangles>>,
    polygons: &[Polygon],
    p: DVec3,
    spent: &mut u64,
    unchecked: &mut usize,
) -> f64 {
    // Over budget before its edges are even matched up: a building modelled as one mesh
    // holds every luminaire in its bounds.
    if surface.is_none() {
        let fans: u64 = polygons.iter().map(|q| q.vertices().len() as u64 - 2).sum();
        if *spent + fans > MAX_WINDING_TRIANGLES {
            *unchecked += 1;
            return 0.0;
        }
    }
    let triangles = surface.get_or_insert_with(|| {
        Holes::of(polygons).map(|holes| {
            let fans = polygons.iter().flat_map(|q| {
                let v = q.vertices();
                (1..v.len() - 1).map(move |k| [v[0], v[k], v[k + 1]])
            });
            fans.chain(holes.caps).collect()
        })
    });
    let Some(triangles) = triangles else { return 0.0 };
    let cost = triangles.len() as u64;
    if *spent + cost > MAX_WINDING_TRIANGLES {
        *unchecked += 1;
        return 0.0;
    }
    *spent += cost;
    winding_number(triangles, p)
}

/// The generalised winding number of `triangles` about `p`: Σ Ω / 4π, each triangle's signed
/// solid angle by Van Oosterom & Strackee (1983), tan(Ω/2) = a·(b × c) / (|a||b||c| +
/// (a·b)|c| + (b·c)|a| + (c·a)|b|) with a, b, c its corners less `p`; positive where the
/// triangle is counter-clockwise seen from `p`'s far side (its front faces away from `p`).
fn winding_number(triangles: &[[DVec3; 3]], p: DVec3) -> f64 {
    let total: f64 = triangles
        .iter()
        .map(|t| {
            let (a, b, c) = (t[0] - p, t[1] - p, t[2] - p);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let det = a.dot(b.cross(c));
            let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * det.atan2(den)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sealed::tests::{boxed, downlight, gridded_box, lit_by};
    use radiosity_core::{Facing, Object, Sphere, box_faces};

    fn one_sided(mut o: Object) -> Object {
        o.sides = Sides::One;
        o
    }

    /// A fitting's body modelled as a closed block with the luminaire's centre inside it is
    /// found, whether a box of polygons, a mesh or a ball; a room around the luminaire (wound
    /// inwards, or two-sided around everything else), a luminaire outside, and one in the
    /// bounds of an open box are not.
    #[test]
    fn a_luminaire_inside_a_solid_is_found() {
        let inside = DVec3::new(0.5, 0.5, 0.5);
        let room = {
            let faces = box_faces(DVec3::splat(-5.0), DVec3::splat(5.0), Facing::Inward, 0.0).unwrap();
            Object::new("room", 1, Shape::Polygons(faces))
        };
        for as_mesh in [false, true] {
            let body = one_sided(boxed(Facing::Outward, as_mesh));
            let s = lit_by(
                vec![room.clone(), body],
                vec![downlight(DVec3::new(2.0, 3.0, 2.0)), downlight(inside)],
            );
            let got = luminaires_in_solids(&s);
            assert_eq!(got.enclosed, vec![EnclosedLuminaire { luminaire: 1, object: 1 }], "mesh {as_mesh}");
            assert_eq!(got.unchecked, 0);
            // Two-sided, it is still a solid: something (the room) lies outside it.
            let s = lit_by(vec![room.clone(), boxed(Facing::Outward, as_mesh)], vec![downlight(inside)]);
            assert_eq!(luminaires_in_solids(&s).enclosed.len(), 1);
            // Two-sided around everything: the room, its normals out.
            let s = lit_by(vec![boxed(Facing::Outward, as_mesh)], vec![downlight(inside)]);
            assert!(luminaires_in_solids(&s).enclosed.is_empty());
            // Wound inwards: a room.
            let s = lit_by(
                vec![room.clone(), one_sided(boxed(Facing::Inward, as_mesh))],
                vec![downlight(inside)],
            );
            assert!(luminaires_in_solids(&s).enclosed.is_empty());
        }
        let ball =
            Object::new("ball", 1, Shape::Sphere(Sphere::try_new(inside, 0.3, Facing::Outward).unwrap()));
        let s = lit_by(vec![room.clone(), ball], vec![downlight(inside)]);
        assert_eq!(luminaires_in_solids(&s).enclosed, vec![EnclosedLuminaire { luminaire: 0, object: 1 }]);
        // A box without its lid is not closed.
        let mut faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Outward, 0.0).unwrap();
        faces.remove(1);
        let cup = Object::new("cup", 1, Shape::Polygons(faces));
        assert!(luminaires_in_solids(&lit_by(vec![room, cup], vec![downlight(inside)])).enclosed.is_empty());
    }

    /// The winding number is ±1 inside and 0 outside a closed surface, with small holes
    /// capped; past the budget a pair is counted unchecked, not guessed.
    #[test]
    fn winding_numbers_and_the_budget() {
        let o = gridded_box(&[(0, 5)]);
        let Shape::Mesh(m) = &o.shape else { unreachable!() };
        let (mut spent, mut unchecked) = (0, 0);
        let mut cache = None;
        let w = winding_of(&mut cache, m.polygons(), DVec3::splat(0.4), &mut spent, &mut unchecked);
        assert!((w - 1.0).abs() < 1e-9, "{w}");
        let w = winding_of(&mut cache, m.polygons(), DVec3::splat(1.4), &mut spent, &mut unchecked);
        assert!(w.abs() < 1e-9, "{w}");
        assert_eq!((spent, unchecked), (2 * (95 * 2 + 4), 0));
        let mut spent = MAX_WINDING_TRIANGLES - 10;
        let w = winding_of(&mut cache, m.polygons(), DVec3::splat(0.4), &mut spent, &mut unchecked);
        assert_eq!((w, unchecked), (0.0, 1));
    }
}
