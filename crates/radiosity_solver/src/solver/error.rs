//! Why solving cannot start.

use thiserror::Error;

/// Why solving cannot start.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SolverError {
    /// Nothing emits: there is no light to shoot.
    #[error("the scene emits no light (total emitted power is 0); give a material an emission > 0")]
    NoEmission,
    /// Nothing emits and the scene's luminaires light no element: each is behind a surface
    /// that faces away from it, inside a closed object, or aimed where nothing is.
    #[error(
        "none of the scene's {count} luminaire(s) lights any surface, and no material emits: each is behind a surface that faces away from it, inside a closed object, or aimed where nothing is; move or aim them"
    )]
    DarkLuminaires {
        /// Luminaires in the scene.
        count: usize,
    },
    /// Nothing emits, there is no luminaire, and the sun lights no element: every shadow ray
    /// towards it meets the scene (a closed room) or it is below every surface.
    #[error(
        "the sun and sky light no surface and nothing else lights the scene: every shadow ray towards them meets the scene (a room with no opening) or they are below every surface; open the room, turn the sun or add a light"
    )]
    DarkDaylight,
    /// The mesh has no elements.
    #[error("the mesh has no elements")]
    EmptyMesh,
    /// The patches do not own consecutive runs of all the elements, in order.
    #[error("mesh patch {patch}: patches must own consecutive runs of the elements, in order")]
    BadMesh {
        /// The first patch out of order (the patch count when elements are left over).
        patch: usize,
    },
    /// A parameter is out of range.
    #[error("solver parameter {name} = {value} is out of range: {expected}")]
    BadParameter {
        /// Parameter name.
        name: &'static str,
        /// Value given.
        value: String,
        /// What is expected.
        expected: &'static str,
    },
}
