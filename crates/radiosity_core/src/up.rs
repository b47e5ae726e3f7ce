//! Which way is up in a model: the renderer works in a frame with +y up (glTF's, and the
//! frame of the automatic camera and the viewer's walking controls), while building models
//! from architectural tools (Radiance, DIALux, Revit, SketchUp, most CAD exports) have +z up.
//!
//! A scene declared with another up axis is turned into the +y-up frame once, when it is
//! loaded ([`Scene::rotate_to_y_up`]); every consumer then sees an upright scene. The turns
//! are quarter or half turns, so they only swap coordinates and change signs: exact in
//! floating point, the same scene bit for bit whichever frame it was written in, and
//! reversible ([`UpAxis::from_y_up`]) for the outputs that go back to the user's tools.
//!
//! Guessing the up axis of a model that does not say is the loader's business
//! (`radiosity_io::likely_up`).

use glam::DVec3;

use crate::{Scene, Shape};

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
}
