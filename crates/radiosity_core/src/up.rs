//! Which way is up in a model: the renderer works in a frame with +y up (glTF's, and the
//! frame of the automatic camera and the viewer's walking controls), while building models
//! from architectural tools (Radiance, DIALux, Revit, SketchUp, most CAD exports) have +z up.
//!
//! A scene declared with another up axis is turned into the +y-up frame once, when it is
//! loaded ([`Scene::rotate_to_y_up`]); every consumer then sees an upright scene. The turns
//! are quarter or half turns, so they only swap coordinates and change signs: exact in
//! floating point, the same scene bit for bit whichever frame it was written in, and
//! reversible ([`UpAxis::from_y_up`]) for the outputs that go back to the user's tools.

use glam::DVec3;

use crate::{Material, Polygon, Scene, Shape};

/// The axis of a model file that points up, in the file's own coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum UpAxis {
    /// +x up.
    X,
    /// −x up.
    NegX,
    /// +y up: glTF's convention, and the renderer's own frame (no turn).
    #[default]
    Y,
    /// −y up (a model upside down).
    NegY,
    /// +z up: Radiance, DIALux, Revit, SketchUp, most CAD and GIS exports.
    Z,
    /// −z up.
    NegZ,
}

impl UpAxis {
    /// Every axis, in the order of [`UpAxis::NAMES`].
    pub const ALL: [UpAxis; 6] = [UpAxis::X, UpAxis::Y, UpAxis::Z, UpAxis::NegX, UpAxis::NegY, UpAxis::NegZ];

    /// The names accepted by [`UpAxis::parse`], as written on a command line or in a scene file.
    pub const NAMES: [&'static str; 6] = ["x", "y", "z", "-x", "-y", "-z"];

    /// The axis named `name` (`x`, `y`, `z`, `-x`, `-y`, `-z`; also `+x` and upper case), or
    /// `None`.
    pub fn parse(name: &str) -> Option<Self> {
        let name = name.trim().to_ascii_lowercase();
        let name = name.strip_prefix('+').unwrap_or(&name);
        Self::NAMES.iter().position(|n| *n == name).map(|i| Self::ALL[i])
    }

    /// Its name, as [`UpAxis::parse`] reads it.
    pub fn as_str(self) -> &'static str {
        Self::NAMES[Self::ALL.iter().position(|&a| a == self).expect("every axis is listed")]
    }

    /// The unit vector of this axis in the file's coordinates.
    pub fn direction(self) -> DVec3 {
        match self {
            UpAxis::X => DVec3::X,
            UpAxis::NegX => DVec3::NEG_X,
            UpAxis::Y => DVec3::Y,
            UpAxis::NegY => DVec3::NEG_Y,
            UpAxis::Z => DVec3::Z,
            UpAxis::NegZ => DVec3::NEG_Z,
        }
    }

    /// A point or direction of the file turned into the renderer's +y-up frame: a rotation
    /// (determinant +1, so faces keep their winding and their lit side) that takes
    /// [`UpAxis::direction`] to +y. For +z up it is the usual (x, y, z) → (x, z, −y), the turn
    /// glTF exporters make from a z-up scene; x stays x wherever x is not up.
    pub fn to_y_up(self, p: DVec3) -> DVec3 {
        match self {
            UpAxis::Y => p,
            UpAxis::Z => DVec3::new(p.x, p.z, -p.y),
            UpAxis::NegZ => DVec3::new(p.x, -p.z, p.y),
            UpAxis::X => DVec3::new(-p.y, p.x, p.z),
            UpAxis::NegX => DVec3::new(p.y, -p.x, p.z),
            UpAxis::NegY => DVec3::new(p.x, -p.y, -p.z),
        }
    }

    /// The inverse of [`UpAxis::to_y_up`]: a point of the renderer's frame in the file's own
    /// coordinates, for outputs that go back to the tool the model came from.
    pub fn from_y_up(self, p: DVec3) -> DVec3 {
        match self {
            UpAxis::Y => p,
            UpAxis::Z => DVec3::new(p.x, -p.z, p.y),
            UpAxis::NegZ => DVec3::new(p.x, p.z, -p.y),
            UpAxis::X => DVec3::new(p.y, -p.x, p.z),
            UpAxis::NegX => DVec3::new(-p.y, p.x, p.z),
            UpAxis::NegY => DVec3::new(p.x, -p.y, -p.z),
        }
    }
}

impl std::fmt::Display for UpAxis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Why a scene looks as if another axis than +y were up ([`Scene::likely_up`]).
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

impl Scene {
    /// Turns the scene from a file whose up axis is `up` into the renderer's +y-up frame:
    /// every polygon, mesh position, sphere centre and the camera ([`UpAxis::to_y_up`]).
    /// Exact (coordinates are only swapped and negated), so normals, areas and validity are
    /// unchanged; a no-op for [`UpAxis::Y`].
    pub fn rotate_to_y_up(&mut self, up: UpAxis) {
        if up != UpAxis::Y {
            self.map_exactly(|p| up.to_y_up(p));
        }
    }

    /// The inverse of [`Scene::rotate_to_y_up`]: the scene back in the frame of a file whose
    /// up axis is `up` (to read the same file with another up axis, as the viewer's up
    /// setting does).
    pub fn rotate_from_y_up(&mut self, up: UpAxis) {
        if up != UpAxis::Y {
            self.map_exactly(|p| up.from_y_up(p));
        }
    }

    /// Every point and direction of the scene mapped by `f`, a rotation that only swaps and
    /// negates coordinates.
    fn map_exactly(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for o in &mut self.objects {
            match &mut o.shape {
                Shape::Polygons(ps) => ps.iter_mut().for_each(|p| *p = p.mapped_exactly(&f)),
                Shape::Mesh(m) => *m = m.mapped_exactly(&f),
                Shape::Sphere(s) => s.center = f(s.center),
            }
        }
        if let Some(c) = &mut self.camera {
            c.position = f(c.position);
            c.look_at = f(c.look_at);
            c.up = f(c.up);
        }
        self.lighting.map_exactly(&f);
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
    pub fn likely_up(&self) -> Option<UpGuess> {
        let (lights, others) = faces(self);
        if share_facing(&lights, DVec3::NEG_Y) >= LIGHT_SHARE {
            return None;
        }
        let (lo, hi) = self.bounds();
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
            if lights_say_nothing && level_area(&others, axis) >= LEVEL_RATIO * level_y.max(f64::MIN_POSITIVE)
            {
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

    /// Each turn takes its axis to +y, is a rotation (keeps a right-handed frame) and is
    /// undone by its inverse.
    #[test]
    fn every_turn_takes_its_axis_up_and_back() {
        for up in UpAxis::ALL {
            assert_eq!(up.to_y_up(up.direction()), DVec3::Y, "{up}");
            let (x, y, z) = (up.to_y_up(DVec3::X), up.to_y_up(DVec3::Y), up.to_y_up(DVec3::Z));
            assert_eq!(x.cross(y), z, "{up}: not a rotation");
            let p = DVec3::new(1.5, -2.25, 3.125);
            assert_eq!(up.from_y_up(up.to_y_up(p)), p, "{up}");
            assert_eq!(UpAxis::parse(up.as_str()), Some(up));
        }
        assert_eq!(UpAxis::parse("+Z"), Some(UpAxis::Z));
        assert_eq!(UpAxis::parse("w"), None);
    }

    /// The Cornell box (its lamp faces −y) looks +y up; turned to stand on z (as a z-up file
    /// would hold it), it looks z up, for its lamp.
    #[test]
    fn a_room_turned_on_z_looks_z_up() {
        let cornell = crate::cornell_box();
        assert_eq!(cornell.likely_up(), None);
        let mut z_up = cornell.clone();
        // What a z-up file holds: the y-up scene turned back from +y to +z.
        z_up.rotate_from_y_up(UpAxis::Z);
        let guess = z_up.likely_up().expect("looks z up");
        assert_eq!(guess.up, UpAxis::Z, "{guess:?}");
        assert!(guess.reason.contains("−z"), "{guess:?}");
        // Turned to +y up again, it is the same scene bit for bit.
        z_up.rotate_to_y_up(UpAxis::Z);
        assert_eq!(z_up, cornell);
    }

    /// Two plates facing each other along z, the emitter facing +z: nothing says up.
    #[test]
    fn two_plates_say_nothing() {
        assert_eq!(crate::two_plates(1.0, 1.0, 0.5, 1.0).likely_up(), None);
    }
}
