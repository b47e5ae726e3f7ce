//! The largest values a scene may hold: coordinates, polygon corners, solve time.

/// Most vertices of one polygon (or one model face): 1024. Validation is linear in the
/// corners, but the mesher cuts a polygon into a fan of triangles, each meshed on its own
/// lattice as long as the polygon is wide, and a concave model face is ear-clipped into such
/// slivers: a 4096-corner light made half a million elements and solved in 37 s, a
/// 10⁵-corner one never finished (every patch shoots, each shot visiting every patch). A
/// 1024-gon solves in about 4 s at the default sizes. A face with more corners is a
/// tessellated curve, better given as fewer corners or as a model's triangles.
pub const MAX_POLYGON_VERTICES: usize = 1024;

/// Largest coordinate magnitude accepted on any axis, in scene units: 10¹². Every point of a
/// scene (polygon and mesh corners, box corners, a sphere's bounds, the camera) lies within
/// ±10¹² of the origin. Why a bound: the mesher, the ray tracer and the form factors work with
/// squares and fourth powers of distances and with grids over the scene's bounds, which
/// overflow or collapse for points near `f64::MAX` (a sphere centred at 10³⁰⁸ asked for a
/// 25 GB table and then crashed the ray tracer's build); and there, a point's spacing from the
/// next representable one (10⁻⁴ of a unit at 10¹², a whole unit by 10¹⁶) already exceeds the
/// details of any model. In metres that is beyond the Sun; in millimetres, 10⁶ km.
pub const MAX_COORDINATE: f64 = 1e12;

/// Longest solve time limit accepted, in seconds (about 31.7 years): any longer limit is no
/// limit, and a larger number does not fit a `Duration`'s arithmetic in every caller.
pub const MAX_TIME_LIMIT_SECONDS: f64 = 1e9;
