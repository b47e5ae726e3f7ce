//! How finely surfaces are cut into patches and elements: [`MeshParams`], with its presets and
//! limits. The mesher itself is the `radiosity_mesh` crate; the parameters live here because
//! a scene file carries them.

use crate::SceneError;

/// Subdivision of surfaces (the source document's "discrétisation", S10).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshParams {
    /// Longest patch edge, scene units, > 0. Patches shoot; smaller is more accurate and
    /// slower (more shots).
    pub patch_size: f64,
    /// Longest element edge, scene units, > 0; clamped to `patch_size`. Elements receive;
    /// smaller gives sharper shadows and smoother shading. A quad's elements are squares of
    /// this side at most; a model's triangles are cut by bisection into pieces whose longest
    /// edge is at most the diagonal of that square (√2 times it), as are patches.
    pub element_size: f64,
    /// Smooth shading joins the surfaces of one object at a shared corner when their normals
    /// differ by less than this, degrees in [0, 180); 0 keeps every surface apart. Default
    /// [`DEFAULT_CREASE_ANGLE_DEG`].
    pub crease_angle_deg: f64,
    /// Cut surfaces along the footprints of solids standing on them and leave the covered
    /// part out (see the `contacts` module). Default true.
    pub contacts: bool,
    /// Cut surfaces along the outlines of the penumbrae and umbrae that convex solids cast
    /// from the bright emitters and point luminaires (see the `shadows` module). Default true.
    pub shadow_outlines: bool,
    /// How many times elements along inside corners (a wall meeting the floor, a block
    /// standing on it) are halved towards the corner, in [0, [`MAX_CORNER_REFINEMENT`]]; 0
    /// grades nothing (see the `grading` module). Default [`DEFAULT_CORNER_REFINEMENT`].
    pub corner_refinement: u32,
    /// How many times elements that other geometry comes nearer to than half their size (a wall
    /// behind a model, a board under the next shelf) are quartered, in
    /// [0, [`MAX_PROXIMITY_REFINEMENT`]]; 0 refines nothing (see `grading::refine_near`).
    /// Default [`DEFAULT_PROXIMITY_REFINEMENT`].
    pub proximity_refinement: u32,
    /// Levels of adaptive subdivision, in [0, [`MAX_ADAPTIVE_LEVELS`]]: elements where the
    /// light changes steeply between neighbours (shadow edges) are quartered, each level after
    /// a quick probe solve of the mesh so far. `Mesh::build` alone does not do it:
    /// `radiosity_solver::Problem` does, with `radiosity_mesh::Mesh::build_refined`. Default
    /// [`DEFAULT_ADAPTIVE_LEVELS`].
    pub adaptive_levels: u32,
}

/// The default [`MeshParams::adaptive_levels`]: shadow edges' elements down to a quarter of
/// the element size.
pub const DEFAULT_ADAPTIVE_LEVELS: u32 = 2;

/// The largest [`MeshParams::adaptive_levels`].
pub const MAX_ADAPTIVE_LEVELS: u32 = 4;

/// The default [`MeshParams::corner_refinement`]: elements next to an inside corner a
/// quarter as wide as the rest.
pub const DEFAULT_CORNER_REFINEMENT: u32 = 2;

/// The default [`MeshParams::proximity_refinement`]: one level. It brings a model on a shelf
/// from 3 % dark to within 1.3 % of the path tracer, and with a model's near field fine
/// enough to light the ground under it (the solver's shooter groups) the models standing on
/// a table stay within 1.5 %; it costs up to 24 % of the solve time on a big room and 5 % on
/// the Cornell box (docs/PERFORMANCE.md).
pub const DEFAULT_PROXIMITY_REFINEMENT: u32 = 1;

/// The largest [`MeshParams::proximity_refinement`]: elements 1/16 as wide as the rest.
pub const MAX_PROXIMITY_REFINEMENT: u32 = 4;

/// The largest [`MeshParams::corner_refinement`]: elements 1/64 as wide as the rest.
pub const MAX_CORNER_REFINEMENT: u32 = 6;

/// The default crease angle: a tessellated curve (a sphere of 24 segments turns 15° per
/// facet, a coarse cylinder 30°) shades smooth, while a box's 90° edges and a chamfer's 45°
/// stay sharp.
pub const DEFAULT_CREASE_ANGLE_DEG: f64 = 40.0;

impl MeshParams {
    /// Validated parameters.
    ///
    /// # Errors
    /// [`SceneError::BadMeshSize`] when a size is not a finite number > 0.
    pub fn try_new(patch_size: f64, element_size: f64) -> Result<Self, SceneError> {
        for (key, value) in [("patch_size", patch_size), ("element_size", element_size)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SceneError::BadMeshSize { key, value });
            }
        }
        Ok(Self::with_defaults(patch_size, element_size.min(patch_size)))
    }

    /// `patch_size` and `element_size` as given, every other setting at its default.
    fn with_defaults(patch_size: f64, element_size: f64) -> Self {
        Self {
            patch_size,
            element_size,
            crease_angle_deg: DEFAULT_CREASE_ANGLE_DEG,
            contacts: true,
            shadow_outlines: true,
            corner_refinement: DEFAULT_CORNER_REFINEMENT,
            proximity_refinement: DEFAULT_PROXIMITY_REFINEMENT,
            adaptive_levels: DEFAULT_ADAPTIVE_LEVELS,
        }
    }

    /// The same parameters with contact cutting on or off.
    pub fn with_contacts(self, contacts: bool) -> Self {
        Self { contacts, ..self }
    }

    /// The same parameters with shadow outlines cut or not.
    pub fn with_shadow_outlines(self, shadow_outlines: bool) -> Self {
        Self { shadow_outlines, ..self }
    }

    /// The same parameters with elements halved `levels` times towards inside corners.
    ///
    /// # Errors
    /// [`SceneError::BadCornerRefinement`] when `levels` exceeds [`MAX_CORNER_REFINEMENT`].
    pub fn with_corner_refinement(self, levels: u32) -> Result<Self, SceneError> {
        if levels > MAX_CORNER_REFINEMENT {
            return Err(SceneError::BadCornerRefinement { value: levels });
        }
        Ok(Self { corner_refinement: levels, ..self })
    }

    /// The same parameters with elements near other geometry quartered `levels` times.
    ///
    /// # Errors
    /// [`SceneError::BadProximityRefinement`] when `levels` exceeds
    /// [`MAX_PROXIMITY_REFINEMENT`].
    pub fn with_proximity_refinement(self, levels: u32) -> Result<Self, SceneError> {
        if levels > MAX_PROXIMITY_REFINEMENT {
            return Err(SceneError::BadProximityRefinement { value: levels });
        }
        Ok(Self { proximity_refinement: levels, ..self })
    }

    /// The same parameters with `levels` of adaptive subdivision.
    ///
    /// # Errors
    /// [`SceneError::BadAdaptiveLevels`] when `levels` exceeds [`MAX_ADAPTIVE_LEVELS`].
    pub fn with_adaptive_levels(self, levels: u32) -> Result<Self, SceneError> {
        if levels > MAX_ADAPTIVE_LEVELS {
            return Err(SceneError::BadAdaptiveLevels { value: levels });
        }
        Ok(Self { adaptive_levels: levels, ..self })
    }

    /// The same sizes with crease angle `degrees`.
    ///
    /// # Errors
    /// [`SceneError::BadCreaseAngle`] when `degrees` is not in [0, 180).
    pub fn with_crease_angle(self, degrees: f64) -> Result<Self, SceneError> {
        if !(0.0..180.0).contains(&degrees) {
            return Err(SceneError::BadCreaseAngle { value: degrees });
        }
        Ok(Self { crease_angle_deg: degrees, ..self })
    }

    /// Default subdivision for a scene whose bounding-box diagonal is `diagonal`: patches of
    /// 1/8 and elements of 1/32 of it.
    pub fn for_extent(diagonal: f64) -> Self {
        let d = if diagonal.is_finite() && diagonal > 0.0 { diagonal } else { 1.0 };
        Self::with_defaults(d / 8.0, d / 32.0)
    }

    /// The same parameters with both sizes multiplied by `factor` (e.g. 0.5 for a finer mesh).
    pub fn scaled(self, factor: f64) -> Self {
        Self { patch_size: self.patch_size * factor, element_size: self.element_size * factor, ..self }
    }
}
