//! Guessing which way is up in a model that does not say: building models are mostly wider
//! than they are tall, and their lights face down. The loader notes the guess to the user;
//! the scene is turned only as the user asks ([`Scene::rotate_to_y_up`]).

use radiosity_core::glam::DVec3;
use radiosity_core::{Material, Polygon, Scene, Shape, UpAxis};

/// Why a scene looks as if another axis than +y were up ([`likely_up`]).
#[derive(Clone, Debug, PartialEq)]
pub struct UpGuess {
    /// The axis that looks up.
    pub up: UpAxis,
    /// What gave it away, for a note to the user ("its lights face −z").
    pub reason: String,
}

/// Share of the emitting area that must face one way for the lights to say where down is:
/// most ceiling lights face straight down, a few wall or desk lights need not.
const LIGHT_SHARE: f64 = 0.6;
/// A face counts as facing an axis direction within this cosine (about 25°).
const FACING_COS: f64 = 0.9;
/// A face counts as horizontal-looking (a floor, a ceiling, a table top) within this cosine
/// of an axis (about 11°).
const LEVEL_COS: f64 = 0.98;
/// Without lights to tell, the faces perpendicular to a candidate axis must have this many
/// times the area of those perpendicular to y (floors against walls).
const LEVEL_RATIO: f64 = 2.0;

/// Faces as (front normal, area).
type Facings = Vec<(DVec3, f64)>;

/// Area-weighted facing of the scene's planar faces: `(emitting faces, other faces)`.
fn faces(scene: &Scene) -> (Facings, Facings) {
    let (mut lights, mut others) = (Vec::new(), Vec::new());
    for o in &scene.objects {
        let emits = scene.materials.get(o.material).is_some_and(Material::is_emitter);
        let list = if emits { &mut lights } else { &mut others };
        let polygons: &[Polygon] = match &o.shape {
            Shape::Polygons(ps) => ps,
            Shape::Mesh(m) => m.polygons(),
            // A sphere faces every way: it says nothing about up.
            Shape::Sphere(_) => &[],
        };
        list.extend(polygons.iter().map(|p| (p.normal(), p.area())));
    }
    (lights, others)
}

/// The share of `faces`' area whose normal is within [`FACING_COS`] of `d`.
fn share_facing(faces: &[(DVec3, f64)], d: DVec3) -> f64 {
    let total: f64 = faces.iter().map(|f| f.1).sum();
    let facing: f64 = faces.iter().filter(|f| f.0.dot(d) >= FACING_COS).map(|f| f.1).sum();
    if total > 0.0 { facing / total } else { 0.0 }
}

/// The area of `faces` perpendicular (within [`LEVEL_COS`]) to axis `d`, either way.
fn level_area(faces: &[(DVec3, f64)], d: DVec3) -> f64 {
    faces.iter().filter(|f| f.0.dot(d).abs() >= LEVEL_COS).map(|f| f.1).sum()
}

/// An axis other than +y that the scene seems to have up, when the signs agree: building
/// models are mostly wider than they are tall, and their lights face down. `None` when
/// the scene looks +y up or nothing says.
///
/// A candidate axis k (±x, ±z) must span less than y does (a room 2.8 high and 5 deep
/// written z-up spans 2.8 in z), and either most of the emitting area faces −k (ceiling
/// lights), or, when the lights face no one way, the faces perpendicular to k (floors,
/// ceilings, table tops) have [`LEVEL_RATIO`] times the area of those perpendicular to y.
/// Lights that mostly face −y settle it for +y.
pub fn likely_up(scene: &Scene) -> Option<UpGuess> {
    let (lights, others) = faces(scene);
    if share_facing(&lights, DVec3::NEG_Y) >= LIGHT_SHARE {
        return None;
    }
    let (lo, hi) = scene.bounds();
    let extent = hi - lo;
    let level_y = level_area(&others, DVec3::Y);
    for (up, axis, span) in [(UpAxis::Z, DVec3::Z, extent.z), (UpAxis::X, DVec3::X, extent.x)] {
        if span >= extent.y {
            continue;
        }
        for (up, down, name) in [(up, -axis, "−"), (flip(up), axis, "+")] {
            if share_facing(&lights, down) >= LIGHT_SHARE {
                let letter = up.as_str().trim_start_matches('-');
                return Some(UpGuess { up, reason: format!("its lights face {name}{letter}") });
            }
        }
        let lights_say_nothing = ALL_DIRECTIONS.iter().all(|&d| share_facing(&lights, d) < LIGHT_SHARE);
        if lights_say_nothing && level_area(&others, axis) >= LEVEL_RATIO * level_y.max(f64::MIN_POSITIVE) {
            let letter = up.as_str();
            return Some(UpGuess {
                up,
                reason: format!(
                    "its level faces (floors, ceilings) are perpendicular to {letter}, and it is lower in {letter} than in y"
                ),
            });
        }
    }
    None
}

/// The six axis directions.
const ALL_DIRECTIONS: [DVec3; 6] = [DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z];

/// The opposite axis.
fn flip(up: UpAxis) -> UpAxis {
    match up {
        UpAxis::X => UpAxis::NegX,
        UpAxis::NegX => UpAxis::X,
        UpAxis::Y => UpAxis::NegY,
        UpAxis::NegY => UpAxis::Y,
        UpAxis::Z => UpAxis::NegZ,
        UpAxis::NegZ => UpAxis::Z,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Cornell box (its lamp faces −y) looks +y up; turned to stand on z (as a z-up file
    /// would hold it), it looks z up, for its lamp.
    #[test]
    fn a_room_turned_on_z_looks_z_up() {
        let cornell = radiosity_scenes::cornell_box();
        assert_eq!(likely_up(&cornell), None);
        let mut z_up = cornell.clone();
        // What a z-up file holds: the y-up scene turned back from +y to +z.
        z_up.rotate_from_y_up(UpAxis::Z);
        let guess = likely_up(&z_up).expect("looks z up");
        assert_eq!(guess.up, UpAxis::Z, "{guess:?}");
        assert!(guess.reason.contains("−z"), "{guess:?}");
        // Turned to +y up again, it is the same scene bit for bit.
        z_up.rotate_to_y_up(UpAxis::Z);
        assert_eq!(z_up, cornell);
    }

    /// Two plates facing each other along z, the emitter facing +z: nothing says up.
    #[test]
    fn two_plates_say_nothing() {
        assert_eq!(likely_up(&radiosity_scenes::two_plates(1.0, 1.0, 0.5, 1.0)), None);
    }
}
