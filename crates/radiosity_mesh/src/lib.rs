//! Meshing: every surface is cut into patches (the shooters) and patches into elements (the
//! receivers), after Cohen, Greenberg, Immel & Brock 1986, "An efficient radiosity approach for
//! realistic image synthesis" (substructuring).
//!
//! Vertices are shared between the elements of one surface (so smooth shading interpolates
//! within it) and never across surfaces (so light never leaks round a corner). Lattice points
//! are computed with one formula per surface, so shared points are bit-identical and are
//! merged exactly, never by a distance tolerance.
//!
//! A surface is one input polygon, one sphere, or — for a [`PolygonMesh`] from a model file —
//! one group of coplanar triangles connected through shared edges with the same subdivision
//! steps; there, points on an edge are computed from the edge's lower vertex index, so the two
//! triangles on it place them identically. A pair of triangles that forms a convex quad is
//! meshed as that quad (exporters split every quad so), larger faces each as their own
//! polygon. A coplanar set whose triangles need step counts within a factor 2 of each other is
//! one surface meshed with the largest steps; in a set with a wider range, triangles that
//! differ in steps start a new surface: a shading seam there, the price of keeping every
//! lattice exact without subdividing small triangles far below the element size.
//!
//! Files, bottom-up: `union_find`, `planar` (convex polygons on a plane) and `builder` (one
//! surface's vertices and elements) are used by the rest; `lattice` and `model_faces` cut a
//! surface; `contacts`, `shadows` and `grading` cut and grade it further; `refinement` names
//! elements to quarter; `smoothing` is the table of vertices pooled across surfaces and
//! `pooling` builds it; `build` puts it all
//! together into a [`Mesh`] (`mesh`), within the `limits`; `sealed` makes closed models
//! one-sided before meshing, and `enclosed_luminaires` (above `sealed`, whose hole caps it
//! uses) finds luminaires shut inside solids; `masks` lets light through alpha-masked faces.
//!
//! [`PolygonMesh`]: radiosity_core::PolygonMesh
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod bisection;
mod build;
mod builder;
mod contacts;
mod enclosed_luminaires;
mod grading;
mod lattice;
mod limits;
mod masks;
mod mesh;
mod model_faces;
mod outline;
mod planar;
mod pooling;
mod refinement;
mod sealed;
mod shadows;
mod smoothing;
mod triangles;
mod union_find;

#[cfg(test)]
mod tests;

pub use enclosed_luminaires::{
    EnclosedLuminaire, LuminaireEnclosures, MAX_WINDING_TRIANGLES, luminaires_in_solids,
};
pub use limits::{MAX_ELEMENTS, MeshError, estimate_elements, first_object_over_limit};
pub use masks::{MaskedOccluder, coverage, opaque_at, uv_at, wrapped};
pub use mesh::{Element, Mesh, Patch, Surface};
pub use planar::distance_to_polygon;
pub use refinement::Refinement;
pub use sealed::{MAX_HOLE_SHARE, Sealed, seal_closed_objects};
pub use smoothing::Smoothing;
pub use triangles::{fan_triangles, strip_triangles};
