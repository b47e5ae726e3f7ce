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

// Fx hashing: the mesher's maps hold millions of small integer keys (a vertex's bits, an
// edge's two indices), where SipHash was a third of the meshing time of a 834 k-triangle
// model; nothing here is keyed by untrusted input an attacker could collide.
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};
use std::ops::Range;

use glam::DVec3;
use thiserror::Error;

use crate::Material;
use crate::contacts::{Contacts, PolygonId};
use crate::grading;
use crate::scene::{Facing, Polygon, PolygonMesh, Scene, SceneError, Shape, Sides, Sphere};
use crate::shadows::ShadowOutlines;

/// Subdivision of surfaces (the source document's "discrétisation", S10).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshParams {
    /// Longest patch edge, scene units, > 0. Patches shoot; smaller is more accurate and
    /// slower (more shots).
    pub patch_size: f64,
    /// Longest element edge, scene units, > 0; clamped to `patch_size`. Elements receive;
    /// smaller gives sharper shadows and smoother shading.
    pub element_size: f64,
    /// Smooth shading joins the surfaces of one object at a shared corner when their normals
    /// differ by less than this, degrees in [0, 180); 0 keeps every surface apart. Default
    /// [`DEFAULT_CREASE_ANGLE_DEG`].
    pub crease_angle_deg: f64,
    /// Cut surfaces along the footprints of solids standing on them and leave the covered
    /// part out (see the `contacts` module). Default true.
    pub contacts: bool,
    /// Cut surfaces along the outlines of the penumbrae and umbrae that convex solids cast
    /// from the bright emitters (see the `shadows` module). Default true.
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
    /// `radiosity_solver::Problem` does, with [`Mesh::build_refined`]. Default
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
        Ok(Self {
            patch_size,
            element_size: element_size.min(patch_size),
            crease_angle_deg: DEFAULT_CREASE_ANGLE_DEG,
            contacts: true,
            shadow_outlines: true,
            corner_refinement: DEFAULT_CORNER_REFINEMENT,
            proximity_refinement: DEFAULT_PROXIMITY_REFINEMENT,
            adaptive_levels: DEFAULT_ADAPTIVE_LEVELS,
        })
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
        Self {
            patch_size: d / 8.0,
            element_size: d / 32.0,
            crease_angle_deg: DEFAULT_CREASE_ANGLE_DEG,
            contacts: true,
            shadow_outlines: true,
            corner_refinement: DEFAULT_CORNER_REFINEMENT,
            proximity_refinement: DEFAULT_PROXIMITY_REFINEMENT,
            adaptive_levels: DEFAULT_ADAPTIVE_LEVELS,
        }
    }

    /// The same parameters with both sizes multiplied by `factor` (e.g. 0.5 for a finer mesh).
    pub fn scaled(self, factor: f64) -> Self {
        Self { patch_size: self.patch_size * factor, element_size: self.element_size * factor, ..self }
    }
}

/// Whether a surface's inside corners are needed: to grade towards them, or to leave them to
/// the grading when refining near other geometry (with the grading off too, they are left
/// ungraded).
fn grades_or_refines(params: &MeshParams) -> bool {
    params.corner_refinement > 0 || params.proximity_refinement > 0
}

/// Quarters the elements of surface `b` (facing `normal`) that other geometry comes nearer
/// to than half their size, [`MeshParams::proximity_refinement`] times (see
/// `grading::refine_near`), no smaller than the element size over 2^levels.
fn refine_near(
    b: &mut SurfaceBuilder,
    normal: DVec3,
    corners: &[(DVec3, DVec3)],
    contacts: &Contacts,
    params: &MeshParams,
) {
    let levels = params.proximity_refinement;
    if levels == 0 {
        return;
    }
    let min_size = params.element_size / f64::from(1u32 << levels);
    let near =
        |centre: DVec3, reach: f64| contacts.geometry_within(centre, normal, reach, 1e-4 * reach, corners);
    grading::refine_near(b, levels, min_size, &near);
}

/// What cuts a polygon before it is meshed.
#[derive(Clone, Copy)]
struct Cutters<'a, 'b> {
    contacts: Option<&'a Contacts<'b>>,
    shadows: Option<&'a ShadowOutlines>,
}

/// Elements to quarter when a scene is meshed again, level after level (see
/// [`Mesh::build_refined`]): adaptive subdivision (Cohen, Greenberg, Immel & Brock 1986)
/// decided outside the mesher, e.g. where a solution's radiosity changes steeply.
///
/// An element is named by its surface and the exact bits of its centre, which the same scene,
/// parameters and earlier levels reproduce.
#[derive(Clone, Debug, Default)]
pub struct Refinement {
    levels: Vec<HashMap<u32, HashSet<[u64; 3]>>>,
}

impl Refinement {
    /// Adds a level: the `elements` of `mesh` (built with this refinement's levels so far).
    /// An element on the back of a two-sided surface names its front twin (the back is
    /// a copy of the front's mesh). Returns how many elements the level names.
    pub fn add_level(&mut self, mesh: &Mesh, elements: impl IntoIterator<Item = usize>) -> usize {
        let mut level: HashMap<u32, HashSet<[u64; 3]>> = HashMap::default();
        let mut count = 0;
        for e in elements {
            let e = if mesh.element_is_back(e) { mesh.element_twin(e).unwrap_or(e) } else { e };
            let surface = mesh.patches[mesh.elements[e].patch as usize].surface;
            let c = mesh.elements[e].centre;
            count += usize::from(level.entry(surface).or_default().insert([c.x, c.y, c.z].map(f64::to_bits)));
        }
        if count > 0 {
            self.levels.push(level);
        }
        count
    }
}

/// The key of the element with vertices `vs` in `b`: its centre's bits, computed as
/// [`Mesh`]'s element centres are.
fn centre_key(b: &SurfaceBuilder, vs: &[u32]) -> [u64; 3] {
    let pts: Vec<DVec3> = vs.iter().map(|&i| b.positions[i as usize]).collect();
    let c = polygon_area_normal(&pts).2;
    [c.x, c.y, c.z].map(f64::to_bits)
}

/// Why a scene could not be meshed.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MeshError {
    /// The subdivision would create more elements than the limit.
    #[error(
        "the mesh would have more than {limit} elements by object '{object}' (patch_size {}, element_size {}); use a larger element_size ([mesh] in the scene, or --element-size)",
        short_number(*.patch_size),
        short_number(*.element_size)
    )]
    TooManyElements {
        /// The object at which the running count passed the limit.
        object: String,
        /// The limit.
        limit: usize,
        /// Patch size asked for.
        patch_size: f64,
        /// Element size asked for.
        element_size: f64,
    },
}

/// A number as a person reads it: plain in the usual range, in exponent form otherwise (a
/// `1e300` is not printed as 301 digits).
fn short_number(v: f64) -> String {
    if v == 0.0 || (1e-4..1e9).contains(&v.abs()) { format!("{v}") } else { format!("{v:e}") }
}

/// Most elements a mesh may have; beyond this memory and time explode, so it is an error
/// rather than a hang.
pub const MAX_ELEMENTS: usize = 20_000_000;

/// A receiving element: a planar convex triangle or quad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Element {
    /// Indices into [`Mesh::positions`], counter-clockwise; only the first `vertex_count`.
    pub vertices: [u32; 4],
    /// 3 or 4.
    pub vertex_count: u8,
    /// The patch this element belongs to.
    pub patch: u32,
    /// Centroid.
    pub centre: DVec3,
    /// Unit normal of the lit side.
    pub normal: DVec3,
    /// Area, scene units².
    pub area: f64,
}

impl Element {
    /// The vertex indices in use.
    pub fn vertex_indices(&self) -> &[u32] {
        &self.vertices[..self.vertex_count as usize]
    }
}

/// A shooting patch: a planar convex triangle or quad made of contiguous elements.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    /// Corner positions, counter-clockwise; only the first `corner_count`.
    pub corners: [DVec3; 4],
    /// 3 or 4.
    pub corner_count: u8,
    /// Unit normal of the lit side.
    pub normal: DVec3,
    /// Centroid.
    pub centre: DVec3,
    /// Area (sum of its elements' areas), scene units².
    pub area: f64,
    /// Its elements, a range into [`Mesh::elements`].
    pub elements: Range<u32>,
    /// The surface it belongs to.
    pub surface: u32,
}

impl Patch {
    /// The corners in use.
    pub fn corners(&self) -> &[DVec3] {
        &self.corners[..self.corner_count as usize]
    }
}

/// One input polygon, one sphere, or one group of coplanar edge-connected triangles of a
/// polygon mesh: the unit within which vertices are shared.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Index into [`Mesh::object_names`].
    pub object: u32,
    /// Index into [`Mesh::materials`].
    pub material: u32,
    /// Its patches, a range into [`Mesh::patches`].
    pub patches: Range<u32>,
    /// True for the back face of a two-sided object ([`Sides::Two`]): the same geometry as
    /// its `twin`, wound the other way.
    pub back: bool,
    /// The surface on the other face of a two-sided object: same elements in the same order,
    /// reversed. `None` for one-sided objects.
    pub twin: Option<u32>,
}

/// The meshed scene: surfaces → patches → elements, plus the coarse occluder triangles that
/// visibility rays test against.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions (shared within a surface only).
    pub positions: Vec<DVec3>,
    /// Per-vertex shading normals (the sphere's true normal on spheres).
    pub shading_normals: Vec<DVec3>,
    /// Receiving elements, grouped by patch.
    pub elements: Vec<Element>,
    /// Shooting patches, grouped by surface.
    pub patches: Vec<Patch>,
    /// Surfaces.
    pub surfaces: Vec<Surface>,
    /// Object names, in scene order.
    pub object_names: Vec<String>,
    /// Materials, in scene order.
    pub materials: Vec<Material>,
    /// The scene's geometry as triangles (input polygons fan-triangulated, sphere facets), for
    /// visibility: far fewer than the element triangles, hence faster rays.
    pub occluders: Vec<[DVec3; 3]>,
    /// Vertices of other surfaces that smooth shading pools with each vertex.
    pub smoothing: Smoothing,
    /// Per object, the area left out of the mesh because a solid stands on it or it lies
    /// flat against another surface ([`MeshParams::contacts`]), scene units².
    pub hidden_area: Vec<f64>,
    /// Per object, how many more surfaces its polygons were cut into along shadow outlines
    /// ([`MeshParams::shadow_outlines`]).
    pub shadow_pieces: Vec<u32>,
    /// True when the scene had too many large faces to look for contacts on all of them:
    /// some were meshed whole.
    pub contacts_incomplete: bool,
    /// True when looking for geometry near elements ([`MeshParams::proximity_refinement`])
    /// ran out of its budget: some elements near other geometry were left unrefined.
    pub proximity_incomplete: bool,
}

/// Which vertices of *different* surfaces share their radiosity in smooth shading: those in
/// one place, on one object and one face of it, whose normals differ by less than the crease
/// angle. Vertices are never shared across surfaces (light must not leak round a corner),
/// so a tessellated curve — one surface per facet — would otherwise shade as facets, and two
/// coplanar polygons of one object (the Cornell ceiling round its lamp) would show their
/// common edge. The test is made per vertex against each neighbour, not chained, so a run of
/// slight bends never carries smoothing across a sharp crease (the usual crease-angle rule of
/// modelling tools).
///
/// Where the two surfaces' lattices do not meet point for point (a T-junction: a vertex of
/// one lies inside an element edge of the other), the vertex pools with that edge's two ends
/// in proportion to where it lies on it, so both sides show nearly the same value there.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Smoothing {
    /// Per vertex, a range into `partners` and `weights` (`offsets[v]..offsets[v + 1]`);
    /// empty when the vertex pools with nobody (or the whole table is empty: no smoothing).
    pub offsets: Vec<u32>,
    /// The vertices pooled with each vertex, itself not included.
    pub partners: Vec<u32>,
    /// The weight of each partner's element sums: 1 for a vertex in the same place, the
    /// linear-interpolation weight for the ends of an edge it lies on.
    pub weights: Vec<f32>,
}

impl Smoothing {
    /// The vertices pooled with vertex `v`, with their weights.
    pub fn partners_of(&self, v: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let range = match (self.offsets.get(v), self.offsets.get(v + 1)) {
            (Some(&a), Some(&b)) => a as usize..b as usize,
            _ => 0..0,
        };
        self.partners[range.clone()].iter().copied().zip(self.weights[range].iter().map(|&w| f64::from(w)))
    }

    /// The table for `mesh` with `crease_angle_deg` (0: none). Places are matched on a grid
    /// of 1e-7 of the scene's diagonal, so points an exporter or the mesher computed along
    /// an edge from either end still meet.
    fn new(mesh: &Mesh, crease_angle_deg: f64) -> Self {
        if crease_angle_deg <= 0.0 || mesh.positions.is_empty() {
            return Self::default();
        }
        let cos_limit = crease_angle_deg.to_radians().cos();
        let mut vertex_surface = vec![u32::MAX; mesh.positions.len()];
        for el in &mesh.elements {
            let surface = mesh.patches[el.patch as usize].surface;
            for &v in el.vertex_indices() {
                vertex_surface[v as usize] = surface;
            }
        }
        // Two vertices may pool: other surfaces, the same object and face, a bend below the
        // crease angle.
        let compatible = |a: u32, b: u32| {
            let (sa, sb) = (vertex_surface[a as usize], vertex_surface[b as usize]);
            let (ta, tb) = (&mesh.surfaces[sa as usize], &mesh.surfaces[sb as usize]);
            sa != sb
                && ta.object == tb.object
                && ta.back == tb.back
                && mesh.shading_normals[a as usize].dot(mesh.shading_normals[b as usize]) > cos_limit
        };
        let (lo, hi) = mesh.bounds();
        let diagonal = (hi - lo).length().max(f64::MIN_POSITIVE);
        let grid = 1e-7 * diagonal;
        // Vertices sorted by place, those in one place side by side (sorting millions of them
        // is faster than a map of lists, which allocated a list per place). Places are counted
        // from the lowest corner, so indices stay below 2·10⁷: from the origin, a scene far
        // away saturated them, and all its vertices shared one place (every pair a partner).
        let mut places: Vec<([i64; 3], u32)> = (0..mesh.positions.len())
            .filter(|&v| vertex_surface[v] != u32::MAX)
            .map(|v| ((mesh.positions[v] - lo).to_array().map(|c| (c / grid).round() as i64), v as u32))
            .collect();
        places.sort_unstable();
        let mut pairs: Vec<(u32, u32, f32)> = Vec::new();
        for group in places.chunk_by(|x, y| x.0 == y.0).filter(|g| g.len() > 1) {
            for &(_, a) in group {
                pairs.extend(group.iter().filter(|&&(_, b)| compatible(a, b)).map(|&(_, b)| (a, b, 1.0)));
            }
        }
        drop(places);
        t_junctions(mesh, &vertex_surface, 1e-6 * diagonal, &compatible, &mut pairs);
        if pairs.is_empty() {
            return Self::default();
        }
        // Bucketed by vertex (a counting sort: a scanned model pools each of its millions of
        // vertices with several others), then each vertex's few partners in order.
        let mut offsets = vec![0u32; mesh.positions.len() + 1];
        for &(a, _, _) in &pairs {
            offsets[a as usize + 1] += 1;
        }
        for v in 0..mesh.positions.len() {
            offsets[v + 1] += offsets[v];
        }
        let mut filled = offsets.clone();
        let mut by_vertex = vec![(0u32, 0.0f32); pairs.len()];
        for &(a, b, w) in &pairs {
            by_vertex[filled[a as usize] as usize] = (b, w);
            filled[a as usize] += 1;
        }
        drop(pairs);
        for v in 0..mesh.positions.len() {
            by_vertex[offsets[v] as usize..offsets[v + 1] as usize]
                .sort_unstable_by_key(|&(b, w)| (b, w.to_bits()));
        }
        let (partners, weights) = by_vertex.into_iter().unzip();
        Self { offsets, partners, weights }
    }
}

/// Adds to `pairs`, for every vertex on a surface's outline that lies strictly inside an
/// outline edge (a, b) of another surface it may pool with (`compatible`), the pairs
/// (v, a, 1 − t) and (v, b, t), t its place along the edge. Outline edges are element edges
/// used once within their surface; they are found through a uniform grid of cells as large
/// as the median of them, so each vertex tests only the edges of its own cell. (Cells as
/// large as the longest edge put a whole model's vertices in one cell beside a room's long
/// walls: 30 k triangles took 9 s.)
fn t_junctions(
    mesh: &Mesh,
    vertex_surface: &[u32],
    tolerance: f64,
    compatible: &dyn Fn(u32, u32) -> bool,
    pairs: &mut Vec<(u32, u32, f32)>,
) {
    // Every element edge, sorted: an edge used once within its surface stands alone.
    let mut edges: Vec<(u32, u32)> = (mesh.elements.iter())
        .flat_map(|el| {
            let v = el.vertex_indices();
            (0..v.len()).map(move |k| (v[k].min(v[(k + 1) % v.len()]), v[k].max(v[(k + 1) % v.len()])))
        })
        .collect();
    edges.sort_unstable();
    let outline: Vec<(u32, u32)> =
        edges.chunk_by(|x, y| x == y).filter(|run| run.len() == 1).map(|run| run[0]).collect();
    drop(edges);
    // Copies: the facets of a model repeat each corner and edge of their neighbours, and the
    // two faces of a two-sided object each other's; every place and every segment is tested
    // once, its copies only on a hit (on a million facets, testing each copy was 143 M tests
    // and most of the meshing time). Copies are found by sorting (ends as bits, lower end
    // first): a sort of millions of entries beats a map of them.
    let bits = |p: DVec3| p.to_array().map(f64::to_bits);
    let mut copies: Vec<([u64; 3], [u64; 3], u32, u32)> = outline
        .iter()
        .map(|&(a, b)| {
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            if bits(pa) <= bits(pb) { (bits(pa), bits(pb), a, b) } else { (bits(pb), bits(pa), b, a) }
        })
        .collect();
    copies.sort_unstable();
    let mut segments: Vec<(DVec3, DVec3)> = Vec::new(); // start, direction
    let mut edge_start = vec![0usize];
    for run in copies.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let (from, to) = (mesh.positions[run[0].2 as usize], mesh.positions[run[0].3 as usize]);
        segments.push((from, to - from));
        edge_start.push(edge_start.last().copied().unwrap_or(0) + run.len());
    }
    let edge_copies: Vec<(u32, u32)> = copies.iter().map(|&(_, _, from, to)| (from, to)).collect();
    drop(copies);
    let mut lengths: Vec<f64> = segments.iter().map(|(_, d)| d.length()).collect();
    if lengths.is_empty() {
        return;
    }
    let total_length: f64 = lengths.iter().sum();
    let middle = lengths.len() / 2;
    let median = *lengths.select_nth_unstable_by(middle, f64::total_cmp).1;
    // The median edge, but no smaller than:
    // * an eighth of the mean edge: a long slanted edge enters a cell per `size` of its
    //   length, so the (cell, edge) entries below number at most 27 · (8 + 1) per edge
    //   whatever the lengths (a 5 000-corner star's ear-clipped slivers, each as long as the
    //   star, beside its finely meshed outline, asked for 3 GB of entries);
    // * twice the tolerance, which the long-edge walk assumes is below a cell, and which keeps
    //   every cell index below 10⁶ (the tolerance is a millionth of the mesh's diagonal), so
    //   cell arithmetic cannot overflow whatever the coordinates.
    let size = median.max(total_length / (8.0 * lengths.len() as f64)).max(2.0 * tolerance);
    if !(size > 0.0 && size.is_finite()) {
        return;
    }
    // Cells are counted from the mesh's lowest corner, not the origin: far from the origin,
    // indices of points divided by a small cell would saturate the integer conversion, and
    // every point out there would share one cell.
    let (origin, _) = mesh.bounds();
    let cell = |p: DVec3| ((p - origin) / size).floor().as_i64vec3().to_array();
    // (cell, segment) for every cell a segment passes near, sorted by cell: a cell's segments
    // are one run, found by binary search.
    let mut cells: Vec<([i64; 3], u32)> = Vec::new();
    let mut touched = Vec::new();
    for (i, &(pa, d)) in segments.iter().enumerate() {
        let pb = pa + d;
        let (lo, hi) =
            (cell(pa.min(pb) - DVec3::splat(tolerance)), cell(pa.max(pb) + DVec3::splat(tolerance)));
        touched.clear();
        let box_cells = (0..3).map(|k| (hi[k] - lo[k] + 1) as u64).product::<u64>();
        if box_cells <= 27 {
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        touched.push([x, y, z]);
                    }
                }
            }
        } else {
            // A long slanted edge: the cells around points one cell apart along it. A point
            // within `tolerance` (far below a cell) of the edge is within a cell of one of
            // them, so in a neighbouring cell.
            let steps = (d.length() / size).ceil() as usize;
            for s in 0..=steps {
                let c = cell(pa.lerp(pb, s as f64 / steps as f64));
                for k in 0..27 {
                    touched.push([c[0] + k % 3 - 1, c[1] + k / 3 % 3 - 1, c[2] + k / 9 - 1]);
                }
            }
            touched.sort_unstable();
            touched.dedup();
        }
        cells.extend(touched.iter().map(|&c| (c, i as u32)));
    }
    cells.sort_unstable();
    let in_cell = |c: [i64; 3]| {
        let first = cells.partition_point(|&(k, _)| k < c);
        cells[first..].iter().take_while(move |&&(k, _)| k == c).map(|&(_, i)| i)
    };
    // The outline's vertices, copies of one place next to each other.
    // (Each vertex ends two outline edges: its index is deduplicated before the 32-byte
    // entries are made.)
    let mut outline_vertices: Vec<u32> = outline.iter().flat_map(|&(a, b)| [a, b]).collect();
    drop(outline);
    outline_vertices.sort_unstable();
    outline_vertices.dedup();
    let mut on_outline: Vec<([u64; 3], u32)> =
        outline_vertices.iter().map(|&v| (bits(mesh.positions[v as usize]), v)).collect();
    drop(outline_vertices);
    on_outline.sort_unstable();
    for place in on_outline.chunk_by(|x, y| x.0 == y.0) {
        let p = mesh.positions[place[0].1 as usize];
        for i in in_cell(cell(p)) {
            let (pa, d) = segments[i as usize];
            let t = (p - pa).dot(d) / d.length_squared();
            let end = tolerance / d.length();
            if !(t > end && t < 1.0 - end && (pa + d * t).distance(p) < tolerance) {
                continue;
            }
            for &(_, v) in place {
                for &(a, b) in &edge_copies[edge_start[i as usize]..edge_start[i as usize + 1]] {
                    if vertex_surface[a as usize] != vertex_surface[v as usize] && compatible(v, a) {
                        pairs.push((v, a, (1.0 - t) as f32));
                        pairs.push((v, b, t as f32));
                    }
                }
            }
        }
    }
}

/// Geometry of one surface before it joins the mesh: local vertices, elements labelled by a
/// local patch number, and patch corner lists.
#[derive(Default)]
pub(crate) struct SurfaceBuilder {
    pub(crate) positions: Vec<DVec3>,
    pub(crate) normals: Vec<DVec3>,
    index: HashMap<[u64; 3], u32>,
    pub(crate) elements: Vec<(Vec<u32>, usize)>,
    patches: Vec<Vec<DVec3>>,
}

impl SurfaceBuilder {
    /// The index of the vertex at exactly `p`, added with normal `n` if new.
    pub(crate) fn vertex(&mut self, p: DVec3, n: DVec3) -> u32 {
        let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        *self.index.entry(key).or_insert_with(|| {
            self.positions.push(p);
            self.normals.push(n);
            (self.positions.len() - 1) as u32
        })
    }
}

/// Whether polygon `p` meshes into several elements. A face that meshes into a few gains
/// nothing from a cut or a grading (the facets of a tessellated model): only larger ones are
/// looked at for contacts and inside corners.
fn is_large(p: &Polygon, params: &MeshParams) -> bool {
    p.area() >= 4.0 * params.element_size * params.element_size
}

fn divisions(length: f64, size: f64) -> usize {
    ((length / size) * (1.0 - 1e-9)).ceil().max(1.0) as usize
}

fn polygon_area_normal(pts: &[DVec3]) -> (f64, DVec3, DVec3) {
    let mut n = DVec3::ZERO;
    for (i, &a) in pts.iter().enumerate() {
        n += a.cross(pts[(i + 1) % pts.len()]);
    }
    let area = 0.5 * n.length();
    // Area-weighted centroid via a fan from the first vertex.
    let mut c = DVec3::ZERO;
    let mut total = 0.0;
    for i in 1..pts.len() - 1 {
        let a = 0.5 * (pts[i] - pts[0]).cross(pts[i + 1] - pts[0]).length();
        c += (pts[0] + pts[i] + pts[i + 1]) / 3.0 * a;
        total += a;
    }
    let centre = if total > 0.0 { c / total } else { pts.iter().copied().sum::<DVec3>() / pts.len() as f64 };
    (area, n.normalize_or_zero(), centre)
}

/// A convex planar quad: one bilinear lattice whose lines at every `ne` step are patch edges.
fn mesh_quad(b: &mut SurfaceBuilder, c: [DVec3; 4], normal: DVec3, params: &MeshParams) {
    let len_u = c[0].distance(c[1]).max(c[3].distance(c[2]));
    let len_v = c[0].distance(c[3]).max(c[1].distance(c[2]));
    let (npu, npv) = (divisions(len_u, params.patch_size), divisions(len_v, params.patch_size));
    let neu = divisions(len_u / npu as f64, params.element_size);
    let nev = divisions(len_v / npv as f64, params.element_size);
    let (nu, nv) = (npu * neu, npv * nev);
    let at = |i: usize, j: usize| {
        let (u, v) = (i as f64 / nu as f64, j as f64 / nv as f64);
        c[0] * ((1.0 - u) * (1.0 - v)) + c[1] * (u * (1.0 - v)) + c[2] * (u * v) + c[3] * ((1.0 - u) * v)
    };
    let base = b.patches.len();
    for pj in 0..npv {
        for pi in 0..npu {
            let (i0, j0, i1, j1) = (pi * neu, pj * nev, (pi + 1) * neu, (pj + 1) * nev);
            b.patches.push(vec![at(i0, j0), at(i1, j0), at(i1, j1), at(i0, j1)]);
        }
    }
    for j in 0..nv {
        for i in 0..nu {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let v = q.map(|p| b.vertex(p, normal)).to_vec();
            b.elements.push((v, base + (j / nev) * npu + i / neu));
        }
    }
}

/// A triangle: one barycentric lattice with `np * ne` steps per edge; its lines at every `ne`
/// step (in all three directions) are patch edges, so each element lies in exactly one patch.
fn mesh_triangle(b: &mut SurfaceBuilder, t: [DVec3; 3], normal: DVec3, np: usize, ne: usize) {
    let n = np * ne;
    let at = |i: usize, j: usize| {
        t[0] + (t[1] - t[0]) * (i as f64 / n as f64) + (t[2] - t[0]) * (j as f64 / n as f64)
    };
    mesh_triangle_lattice(b, &at, normal, np, ne);
}

/// The lattice of [`mesh_triangle`] with lattice point `(i, j)` (`i` steps along the first
/// edge, `j` along the third, `np * ne` steps per edge) placed by `at`.
fn mesh_triangle_lattice(
    b: &mut SurfaceBuilder,
    at: &dyn Fn(usize, usize) -> DVec3,
    normal: DVec3,
    np: usize,
    ne: usize,
) {
    let n = np * ne;
    let coarse = |i: usize, j: usize| at(i * ne, j * ne);
    let mut patch_of: HashMap<(usize, usize, bool), usize> = HashMap::default();
    let mut label = |b: &mut SurfaceBuilder, x3: usize, y3: usize| {
        // Centroid in lattice units times 3, to stay in integers.
        let (pp, qq) = (x3 / (3 * ne), y3 / (3 * ne));
        let up = (x3 - 3 * ne * pp) + (y3 - 3 * ne * qq) < 3 * ne;
        *patch_of.entry((pp, qq, up)).or_insert_with(|| {
            let corners = if up {
                vec![coarse(pp, qq), coarse(pp + 1, qq), coarse(pp, qq + 1)]
            } else {
                vec![coarse(pp + 1, qq), coarse(pp + 1, qq + 1), coarse(pp, qq + 1)]
            };
            b.patches.push(corners);
            b.patches.len() - 1
        })
    };
    for j in 0..n {
        for i in 0..n - j {
            let up = [(i, j), (i + 1, j), (i, j + 1)];
            let p = label(b, 3 * i + 1, 3 * j + 1);
            let v = up.map(|(a, c)| b.vertex(at(a, c), normal)).to_vec();
            b.elements.push((v, p));
            if i + j + 2 <= n {
                let down = [(i + 1, j), (i + 1, j + 1), (i, j + 1)];
                let p = label(b, 3 * i + 2, 3 * j + 2);
                let v = down.map(|(a, c)| b.vertex(at(a, c), normal)).to_vec();
                b.elements.push((v, p));
            }
        }
    }
}

fn mesh_polygon(b: &mut SurfaceBuilder, poly: &Polygon, params: &MeshParams) {
    let v = poly.vertices();
    if v.len() == 4 {
        mesh_quad(b, [v[0], v[1], v[2], v[3]], poly.normal(), params);
        return;
    }
    // Fan triangles share the lattice step count so that points on shared diagonals are
    // computed by the same formula and merge exactly.
    let fans: Vec<[DVec3; 3]> = (1..v.len() - 1).map(|i| [v[0], v[i], v[i + 1]]).collect();
    let longest = |t: &[DVec3; 3]| t[0].distance(t[1]).max(t[1].distance(t[2])).max(t[2].distance(t[0]));
    let np = fans.iter().map(|t| divisions(longest(t), params.patch_size)).max().unwrap_or(1);
    let ne = fans.iter().map(|t| divisions(longest(t) / np as f64, params.element_size)).max().unwrap_or(1);
    for t in fans {
        mesh_triangle(b, t, poly.normal(), np, ne);
    }
}

/// A latitude/longitude tessellation; every facet is one patch and one element (a curved
/// surface has no planar patch bigger than a facet).
fn mesh_sphere(b: &mut SurfaceBuilder, s: &Sphere, params: &MeshParams) {
    use std::f64::consts::PI;
    let n_lat = divisions(PI * s.radius, params.element_size).max(6);
    let n_lon = divisions(2.0 * PI * s.radius, params.element_size).max(2 * n_lat).max(12);
    let sign = if s.facing == Facing::Inward { -1.0 } else { 1.0 };
    let dir = |k: usize, m: usize| {
        let (theta, phi) = (PI * k as f64 / n_lat as f64, 2.0 * PI * (m % n_lon) as f64 / n_lon as f64);
        if k == 0 {
            DVec3::Y
        } else if k == n_lat {
            -DVec3::Y
        } else {
            DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
        }
    };
    for k in 0..n_lat {
        for m in 0..n_lon {
            let mut ring = vec![dir(k, m), dir(k, m + 1), dir(k + 1, m + 1), dir(k + 1, m)];
            ring.dedup();
            if ring.first() == ring.last() && ring.len() > 3 {
                ring.pop();
            }
            let mut pts: Vec<DVec3> = ring.iter().map(|d| s.center + *d * s.radius).collect();
            let (_, n, c) = polygon_area_normal(&pts);
            let mut dirs = ring;
            if n.dot(c - s.center) * sign < 0.0 {
                pts.reverse();
                dirs.reverse();
            }
            let verts = pts.iter().zip(&dirs).map(|(p, d)| b.vertex(*p, *d * sign)).collect();
            b.patches.push(pts);
            b.elements.push((verts, b.patches.len() - 1));
        }
    }
}

/// Patch and element steps per edge for a triangle meshed on its own, as [`mesh_polygon`]
/// chooses them for a one-triangle fan.
fn triangle_steps(t: &[DVec3; 3], params: &MeshParams) -> (usize, usize) {
    let longest = t[0].distance(t[1]).max(t[1].distance(t[2])).max(t[2].distance(t[0]));
    let np = divisions(longest, params.patch_size);
    (np, divisions(longest / np as f64, params.element_size))
}

/// Disjoint sets over face numbers, to group triangles into surfaces and faces into solids.
pub(crate) struct UnionFind(Vec<u32>);

impl UnionFind {
    /// `n` sets of one each.
    pub(crate) fn new(n: usize) -> Self {
        Self((0..n as u32).collect())
    }

    /// The root of `x`'s set: its smallest member.
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            // Path halving keeps the trees flat without recursion.
            self.0[x as usize] = self.0[self.0[x as usize] as usize];
            x = self.0[x as usize];
        }
        x
    }

    /// Joins the sets of `a` and `b`.
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        // The smaller root wins, so a group's root is its first triangle: deterministic order.
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi as usize] = lo;
        }
    }
}

/// How the faces of a [`PolygonMesh`] are cut into surfaces: groups of triangles (face
/// numbers), each meshed with shared vertices; a face of 4+ vertices is a group of its own.
///
/// Two triangles join one group when they share an edge (by vertex index) used by no other
/// face, are coplanar (normals within ~1e-4 rad, the far vertex within 1e-6 of the longest
/// edge off the plane) and either their whole coplanar set needs step counts within a factor
/// 2 of each other (then all are meshed with the set's largest steps) or they need the same
/// steps; either way the lattice points on a common edge coincide bit for bit.
fn group_mesh_faces(m: &PolygonMesh, params: &MeshParams) -> Vec<Vec<u32>> {
    let faces = m.faces();
    let polys = m.polygons();
    let is_tri = |f: usize| faces[f].len() == 3;
    // Edge → the (up to two) triangles using it, and how many faces use it at all.
    let mut edges: HashMap<(u32, u32), (u32, u32, u32)> = HashMap::default();
    for (f, face) in faces.iter().enumerate() {
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let e = edges.entry((a.min(b), a.max(b))).or_insert((u32::MAX, u32::MAX, 0));
            if is_tri(f) {
                if e.0 == u32::MAX {
                    e.0 = f as u32;
                } else if e.1 == u32::MAX {
                    e.1 = f as u32;
                }
            }
            e.2 += 1;
        }
    }
    let coplanar = |a: usize, b: usize| {
        let (pa, pb) = (&polys[a], &polys[b]);
        if pa.normal().dot(pb.normal()) < 1.0 - 5e-9 {
            return false;
        }
        let v = pa.vertices();
        let longest = (0..3).map(|k| v[k].distance(v[(k + 1) % 3])).fold(0.0, f64::max);
        pb.vertices().iter().all(|p| (*p - v[0]).dot(pa.normal()).abs() <= 1e-6 * longest)
    };
    let steps = |f: usize| {
        let v = polys[f].vertices();
        triangle_steps(&[v[0], v[1], v[2]], params)
    };
    let mut pairs: Vec<(u32, u32)> = edges
        .values()
        .filter(|&&(a, b, count)| count == 2 && b != u32::MAX && coplanar(a as usize, b as usize))
        .map(|&(a, b, _)| (a.min(b), a.max(b)))
        .collect();
    // HashMap order is arbitrary; sorting keeps the grouping (and so the mesh) deterministic.
    pairs.sort_unstable();
    // First pass: every coplanar edge-connected set. A set of exactly two triangles is kept
    // whole (it becomes a quad when convex); larger sets are split where the steps differ.
    let mut all = UnionFind::new(faces.len());
    for &(a, b) in &pairs {
        all.union(a, b);
    }
    // Per set: its size and the least and most lattice steps (np · ne) of its triangles.
    let mut size = vec![0u32; faces.len()];
    let mut step_range = vec![(usize::MAX, 0usize); faces.len()];
    for f in 0..faces.len() as u32 {
        let r = all.find(f) as usize;
        size[r] += 1;
        if is_tri(f as usize) {
            let (np, ne) = steps(f as usize);
            step_range[r] = (step_range[r].0.min(np * ne), step_range[r].1.max(np * ne));
        }
    }
    let mut same_steps = UnionFind::new(faces.len());
    for &(a, b) in &pairs {
        let r = all.find(a) as usize;
        // A set whose triangles need at most twice as many steps as each other is meshed
        // whole with the largest steps (at most 2× finer per edge than each one needs, the
        // common case of an n-gon split by an exporter); otherwise only equal steps join.
        let whole = size[r] == 2 || step_range[r].1 <= 2 * step_range[r].0;
        if whole || steps(a as usize) == steps(b as usize) {
            same_steps.union(a, b);
        }
    }
    let mut group_of: HashMap<u32, usize> = HashMap::default();
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for f in 0..faces.len() as u32 {
        let r = same_steps.find(f);
        let g = *group_of.entry(r).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(f);
    }
    groups
}

/// The quad formed by two triangles sharing an edge, when it is planar and convex.
fn pair_as_quad(m: &PolygonMesh, a: usize, b: usize) -> Option<Polygon> {
    let (fa, fb) = (&m.faces()[a], &m.faces()[b]);
    // Rotate `a` so that its edge k→k+1 is the one `b` shares (b runs it the other way).
    for k in 0..3 {
        let (u, v) = (fa[k], fa[(k + 1) % 3]);
        if let Some(j) = (0..3).find(|&j| fb[j] == v && fb[(j + 1) % 3] == u) {
            let w = fb[(j + 2) % 3];
            let x = fa[(k + 2) % 3];
            // Start at `v`: for the usual fan split of a quad [0 1 2] [0 2 3] that is the quad's
            // own first vertex, so the lattice (and element order) is the quad's exactly.
            let pts = [v, x, u, w].map(|i| m.positions()[i as usize]);
            return Polygon::try_new(pts.to_vec()).ok();
        }
    }
    None
}

/// Meshes a group of coplanar triangles into `b` with the same steps for all, placing lattice
/// points on an edge from the edge's lower vertex index so both triangles on a shared edge
/// compute the same bits and their vertices merge.
fn mesh_triangle_group(b: &mut SurfaceBuilder, m: &PolygonMesh, group: &[u32], params: &MeshParams) {
    let (mut np, mut ne) = (1, 1);
    for &f in group {
        let v = m.polygons()[f as usize].vertices();
        let (p, e) = triangle_steps(&[v[0], v[1], v[2]], params);
        np = np.max(p);
        ne = ne.max(e);
    }
    let n = np * ne;
    let pos = m.positions();
    for &f in group {
        let idx = &m.faces()[f as usize];
        let normal = m.polygons()[f as usize].normal();
        let t = [idx[0], idx[1], idx[2]];
        let edge = |p: u32, q: u32, k: usize| {
            // Point k of n from vertex p towards q, computed from the lower index.
            let (a, c, k) = if p < q { (p, q, k) } else { (q, p, n - k) };
            let (pa, pc) = (pos[a as usize], pos[c as usize]);
            if k == 0 {
                pa
            } else if k == n {
                pc
            } else {
                pa + (pc - pa) * (k as f64 / n as f64)
            }
        };
        let at = |i: usize, j: usize| {
            if j == 0 {
                edge(t[0], t[1], i)
            } else if i == 0 {
                edge(t[0], t[2], j)
            } else if i + j == n {
                edge(t[1], t[2], j)
            } else {
                let [p0, p1, p2] = t.map(|i| pos[i as usize]);
                p0 + (p1 - p0) * (i as f64 / n as f64) + (p2 - p0) * (j as f64 / n as f64)
            }
        };
        mesh_triangle_lattice(b, &at, normal, np, ne);
    }
}

fn estimate_polygon_elements(poly: &Polygon, params: &MeshParams) -> usize {
    let v = poly.vertices();
    // The bounding box's diagonal bounds the diameter (within √3) in linear time: the
    // pairwise maximum was quadratic in the corners (39 s for a 10⁵-gon).
    let (lo, hi) = v.iter().fold((v[0], v[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let per_edge = divisions(lo.distance(hi), params.element_size) as f64;
    // A fan of k-2 triangles with n² elements each bounds every case.
    (per_edge * per_edge * (v.len() - 2) as f64).min(usize::MAX as f64) as usize
}

/// An upper bound on the elements `shape` meshes into with `params`, computed in time linear in
/// its corners (saturating, never overflowing).
pub fn estimate_elements(shape: &Shape, params: &MeshParams) -> usize {
    let polygons = |ps: &[Polygon]| {
        ps.iter().fold(0usize, |n, p| n.saturating_add(estimate_polygon_elements(p, params)))
    };
    match shape {
        Shape::Polygons(ps) => polygons(ps),
        Shape::Sphere(s) => {
            let k = divisions(std::f64::consts::PI * s.radius, params.element_size).max(6) as f64;
            (k * k * 4.0).min(usize::MAX as f64) as usize
        }
        Shape::Mesh(m) => polygons(m.polygons()),
    }
}

/// The index of the object with which the running total of [`estimate_elements`] over
/// `scene`'s objects first passes [`MAX_ELEMENTS`], if any: the object a too-large mesh is
/// blamed on (scene loaders report it with its line before anything is meshed).
pub fn first_object_over_limit(scene: &Scene, params: &MeshParams) -> Option<usize> {
    let mut total = 0usize;
    scene.objects.iter().position(|o| {
        let faces = usize::from(o.sides.count());
        total = total.saturating_add(estimate_elements(&o.shape, params).saturating_mul(faces));
        total > MAX_ELEMENTS
    })
}

impl Mesh {
    /// Meshes `scene` with `params`.
    ///
    /// # Errors
    /// [`MeshError::TooManyElements`] when the subdivision would exceed [`MAX_ELEMENTS`].
    pub fn build(scene: &Scene, params: &MeshParams) -> Result<Mesh, MeshError> {
        Self::build_refined(scene, params, &Refinement::default())
    }

    /// Meshes `scene` with `params`, then quarters the elements `refinement` names, level
    /// after level (each level names elements of the mesh the levels before it give), with
    /// the neighbours that gain a vertex on a side cut into triangles that use it.
    ///
    /// # Errors
    /// [`MeshError::TooManyElements`] when the subdivision would exceed [`MAX_ELEMENTS`].
    pub fn build_refined(
        scene: &Scene,
        params: &MeshParams,
        refinement: &Refinement,
    ) -> Result<Mesh, MeshError> {
        let too_many = |object: &str| MeshError::TooManyElements {
            object: object.chars().take(80).collect(),
            limit: MAX_ELEMENTS,
            patch_size: params.patch_size,
            element_size: params.element_size,
        };
        if let Some(i) = first_object_over_limit(scene, params) {
            return Err(too_many(&scene.objects[i].name));
        }
        let mut mesh = Mesh {
            object_names: scene.objects.iter().map(|o| o.name.clone()).collect(),
            materials: scene.materials.clone(),
            hidden_area: vec![0.0; scene.objects.len()],
            shadow_pieces: vec![0; scene.objects.len()],
            ..Mesh::default()
        };
        let contacts = (params.contacts || params.corner_refinement > 0 || params.proximity_refinement > 0)
            .then(|| Contacts::new(scene));
        let shadows = params.shadow_outlines.then(|| ShadowOutlines::new(scene)).filter(|s| !s.is_empty());
        // The back face of an emitting material that emits from its front only: the same
        // reflectance, no emission (one per material, made when first needed).
        let mut dark_back = HashMap::default();
        for (oi, o) in scene.objects.iter().enumerate() {
            let first_surface = mesh.surfaces.len() as u32;
            // A polygon of this object, cut around what stands on it, graded and refined.
            let cut = |mesh: &mut Mesh, p: &Polygon, id: Option<PolygonId>| {
                let cutters = Cutters { contacts: contacts.as_ref(), shadows: shadows.as_ref() };
                mesh.mesh_cut_polygon(cutters, p, id, oi, o.material, params, refinement);
            };
            match &o.shape {
                Shape::Polygons(ps) => {
                    for (index, p) in ps.iter().enumerate() {
                        let v = p.vertices();
                        mesh.occluders.extend((1..v.len() - 1).map(|i| [v[0], v[i], v[i + 1]]));
                        let id = PolygonId { object: oi, index };
                        if contacts.as_ref().is_some_and(|c| c.is_pressed_flat(id, p)) {
                            mesh.hidden_area[oi] += p.area();
                            continue;
                        }
                        cut(&mut mesh, p, Some(id));
                    }
                }
                Shape::Sphere(s) => {
                    let mut b = SurfaceBuilder::default();
                    mesh_sphere(&mut b, s, params);
                    for pts in &b.patches {
                        mesh.occluders.extend((1..pts.len() - 1).map(|i| [pts[0], pts[i], pts[i + 1]]));
                    }
                    mesh.push_surface(b, oi, o.material, refinement);
                }
                Shape::Mesh(m) => {
                    for group in group_mesh_faces(m, params) {
                        let first = group[0] as usize;
                        if m.faces()[first].len() > 3 {
                            let id = PolygonId { object: oi, index: first };
                            let p = &m.polygons()[first];
                            cut(&mut mesh, p, Some(id));
                        } else if let [a, c] = group[..]
                            && let Some(quad) = pair_as_quad(m, a as usize, c as usize)
                        {
                            // Two triangles that make a convex quad (how exporters write one
                            // quad) are meshed as that quad, exactly as a quad polygon would be.
                            cut(&mut mesh, &quad, None);
                        } else {
                            let mut b = SurfaceBuilder::default();
                            mesh_triangle_group(&mut b, m, &group, params);
                            if let Some(c) = contacts.as_ref() {
                                let edges: Vec<(DVec3, DVec3)> = if grades_or_refines(params) {
                                    group
                                        .iter()
                                        .map(|&f| (f as usize, &m.polygons()[f as usize]))
                                        .filter(|(_, p)| is_large(p, params))
                                        .flat_map(|(index, p)| {
                                            c.inside_corners(p, Some(PolygonId { object: oi, index }))
                                        })
                                        .collect()
                                } else {
                                    Vec::new()
                                };
                                grading::grade(&mut b, &edges, params.corner_refinement);
                                let normal = m.polygons()[first].normal();
                                refine_near(&mut b, normal, &edges, c, params);
                            }
                            mesh.push_surface(b, oi, o.material, refinement);
                        }
                    }
                    for p in m.polygons() {
                        let v = p.vertices();
                        mesh.occluders.extend((1..v.len() - 1).map(|i| [v[0], v[i], v[i + 1]]));
                    }
                }
            }
            if let Sides::Two { emits_back } = o.sides {
                let material = scene.materials[o.material].clone();
                let back_material = if emits_back || !material.is_emitter() {
                    o.material as u32
                } else {
                    *dark_back.entry(o.material).or_insert_with(|| {
                        let name = format!("{} (back)", material.name);
                        mesh.materials.push(Material { name, emission: crate::Rgb::ZERO, ..material });
                        (mesh.materials.len() - 1) as u32
                    })
                };
                // The back faces repeat the front's patches, elements and vertices one for one:
                // room for them at once, rather than doubling tables of millions.
                let front = &mesh.surfaces[first_surface as usize..];
                if let (Some(first), Some(last)) = (front.first(), front.last()) {
                    let patches = (last.patches.end - first.patches.start) as usize;
                    let elements = (mesh.patches[last.patches.end as usize - 1].elements.end
                        - mesh.patches[first.patches.start as usize].elements.start)
                        as usize;
                    mesh.surfaces.reserve_exact(front.len());
                    mesh.patches.reserve_exact(patches);
                    mesh.elements.reserve_exact(elements);
                }
                for s in first_surface..mesh.surfaces.len() as u32 {
                    mesh.push_back_face(s, back_material);
                }
            }
        }
        mesh.contacts_incomplete = contacts.as_ref().is_some_and(|c| c.budget_spent());
        mesh.proximity_incomplete = contacts.as_ref().is_some_and(|c| c.proximity_budget_spent());
        mesh.shrink_to_fit();
        mesh.smoothing = Smoothing::new(&mesh, params.crease_angle_deg);
        Ok(mesh)
    }

    /// Meshes polygon `p` of object `object` as one surface, or, where solids stand on it or
    /// cast shadows on it, as one surface per piece of it around their footprints (the
    /// covered area counted in [`Mesh::hidden_area`]) and shadow outlines; each surface graded
    /// and refined as `params` and `refinement` say.
    #[allow(clippy::too_many_arguments)]
    fn mesh_cut_polygon(
        &mut self,
        Cutters { contacts, shadows }: Cutters,
        p: &Polygon,
        id: Option<PolygonId>,
        object: usize,
        material: usize,
        params: &MeshParams,
        refinement: &Refinement,
    ) {
        let large = is_large(p, params);
        let cut = contacts
            .filter(|_| large && params.contacts)
            .and_then(|c| c.cut(p, id, |q| estimate_polygon_elements(q, params)));
        let pieces = match &cut {
            Some(cut) => {
                self.hidden_area[object] += cut.hidden;
                &cut.pieces[..]
            }
            None => std::slice::from_ref(p),
        };
        let shadowed = shadows
            .filter(|_| large)
            .and_then(|s| s.cut(p, pieces, |q| estimate_polygon_elements(q, params)));
        if let Some(cut) = &shadowed {
            self.shadow_pieces[object] += (cut.len() - pieces.len()) as u32;
        }
        let pieces = shadowed.as_deref().unwrap_or(pieces);
        for piece in pieces {
            let mut b = SurfaceBuilder::default();
            mesh_polygon(&mut b, piece, params);
            if let Some(c) = contacts.filter(|_| large) {
                let edges = if grades_or_refines(params) { c.inside_corners(piece, id) } else { Vec::new() };
                grading::grade(&mut b, &edges, params.corner_refinement);
                refine_near(&mut b, p.normal(), &edges, c, params);
            }
            self.push_surface(b, object, material, refinement);
        }
    }

    fn push_surface(
        &mut self,
        mut b: SurfaceBuilder,
        object: usize,
        material: usize,
        refinement: &Refinement,
    ) {
        let surface = self.surfaces.len() as u32;
        for level in &refinement.levels {
            if let Some(marked) = level.get(&surface) {
                let mut splits = grading::Splits::default();
                splits.quarter_marked(&mut b, &|b, vs| marked.contains(&centre_key(b, vs)));
                splits.conform(&mut b);
            }
        }
        let vbase = self.positions.len() as u32;
        self.positions.extend(&b.positions);
        self.shading_normals.extend(&b.normals);
        let first_patch = self.patches.len() as u32;
        let mut by_patch: Vec<Vec<usize>> = vec![Vec::new(); b.patches.len()];
        for (e, (_, p)) in b.elements.iter().enumerate() {
            by_patch[*p].push(e);
        }
        for (p, corners) in b.patches.iter().enumerate() {
            let start = self.elements.len() as u32;
            let mut area = 0.0;
            for &e in &by_patch[p] {
                let local = &b.elements[e].0;
                let pts: Vec<DVec3> = local.iter().map(|&i| b.positions[i as usize]).collect();
                let (a, n, c) = polygon_area_normal(&pts);
                let mut vertices = [0u32; 4];
                for (k, &i) in local.iter().enumerate() {
                    vertices[k] = vbase + i;
                }
                area += a;
                self.elements.push(Element {
                    vertices,
                    vertex_count: local.len() as u8,
                    patch: self.patches.len() as u32,
                    centre: c,
                    normal: n,
                    area: a,
                });
            }
            let (_, n, c) = polygon_area_normal(corners);
            let mut cs = [DVec3::ZERO; 4];
            cs[..corners.len()].copy_from_slice(corners);
            self.patches.push(Patch {
                corners: cs,
                corner_count: corners.len() as u8,
                normal: n,
                centre: c,
                area,
                elements: start..self.elements.len() as u32,
                surface,
            });
        }
        self.surfaces.push(Surface {
            object: object as u32,
            material: material as u32,
            patches: first_patch..self.patches.len() as u32,
            back: false,
            twin: None,
        });
    }

    /// Gives back the tables' spare capacity: grown push by push, they hold up to twice
    /// what a million-facet model needs, for as long as the mesh lives.
    fn shrink_to_fit(&mut self) {
        self.positions.shrink_to_fit();
        self.shading_normals.shrink_to_fit();
        self.elements.shrink_to_fit();
        self.patches.shrink_to_fit();
        self.surfaces.shrink_to_fit();
        self.occluders.shrink_to_fit();
    }

    /// Adds the back face of surface `s`: its vertices (normals negated), patches and elements
    /// in the same order, each wound the other way, with `material`; links the two as twins.
    fn push_back_face(&mut self, s: u32, material: u32) {
        let front = self.surfaces[s as usize].clone();
        let back = self.surfaces.len() as u32;
        let patches = front.patches.start as usize..front.patches.end as usize;
        let elements = self.patches[patches.start].elements.start as usize
            ..self.patches[patches.end - 1].elements.end as usize;
        // A surface's vertices are its own and contiguous: from its first element's lowest
        // index to the highest index any of its elements uses.
        let used = || self.elements[elements.clone()].iter().flat_map(|e| e.vertex_indices().iter().copied());
        let (vlo, vhi) = used().fold((u32::MAX, 0), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let vbase = self.positions.len() as u32;
        self.positions.extend_from_within(vlo as usize..=vhi as usize);
        for i in vlo..=vhi {
            self.shading_normals.push(-self.shading_normals[i as usize]);
        }
        let first_patch = self.patches.len() as u32;
        for p in patches {
            let mut patch = self.patches[p].clone();
            patch.corners[..patch.corner_count as usize].reverse();
            patch.normal = -patch.normal;
            patch.surface = back;
            let start = self.elements.len() as u32;
            for e in patch.elements.clone() {
                let mut el = self.elements[e as usize];
                el.vertices[..el.vertex_count as usize].reverse();
                for v in &mut el.vertices[..el.vertex_count as usize] {
                    *v = *v - vlo + vbase;
                }
                el.normal = -el.normal;
                el.patch = self.patches.len() as u32;
                self.elements.push(el);
            }
            patch.elements = start..self.elements.len() as u32;
            self.patches.push(patch);
        }
        self.surfaces.push(Surface {
            object: front.object,
            material,
            patches: first_patch..self.patches.len() as u32,
            back: true,
            twin: Some(s),
        });
        self.surfaces[s as usize].twin = Some(back);
    }

    /// Whether element `e` lies on the back face of a two-sided object.
    pub fn element_is_back(&self, e: usize) -> bool {
        let patch = &self.patches[self.elements[e].patch as usize];
        self.surfaces[patch.surface as usize].back
    }

    /// The element on the other face of element `e` (the same place, wound the other way),
    /// when `e` belongs to a two-sided object.
    pub fn element_twin(&self, e: usize) -> Option<usize> {
        let patch = &self.patches[self.elements[e].patch as usize];
        let surface = &self.surfaces[patch.surface as usize];
        let twin = &self.surfaces[surface.twin? as usize];
        let first = |s: &Surface| self.patches[s.patches.start as usize].elements.start as usize;
        Some(e - first(surface) + first(twin))
    }

    /// The material of element `e`.
    pub fn element_material(&self, e: usize) -> &Material {
        let patch = &self.patches[self.elements[e].patch as usize];
        &self.materials[self.surfaces[patch.surface as usize].material as usize]
    }

    /// The object index of element `e`.
    pub fn element_object(&self, e: usize) -> usize {
        let patch = &self.patches[self.elements[e].patch as usize];
        self.surfaces[patch.surface as usize].object as usize
    }

    /// Corner positions of element `e`.
    pub fn element_corners(&self, e: usize) -> impl Iterator<Item = DVec3> + '_ {
        self.elements[e].vertex_indices().iter().map(|&i| self.positions[i as usize])
    }

    /// Element triangles for drawing and ray casting: `(element, [v0, v1, v2])` with vertex
    /// indices into [`Mesh::positions`]; a quad gives two triangles sharing its first vertex.
    pub fn element_triangles(&self) -> impl Iterator<Item = (u32, [u32; 3])> + '_ {
        self.elements.iter().enumerate().flat_map(|(e, el)| {
            let v = el.vertices;
            let first = std::iter::once((e as u32, [v[0], v[1], v[2]]));
            let second = (el.vertex_count == 4).then_some((e as u32, [v[0], v[2], v[3]]));
            first.chain(second)
        })
    }

    /// Per surface, the area of its one-sided, non-emitting patches that no emitter lies in
    /// front of (every corner of every emitting patch on or behind the patch's plane, some
    /// strictly behind): they
    /// can receive only reflected light, never direct light, whatever is in between. A large
    /// flat surface like that usually has its normals the wrong way round (a room's walls
    /// modelled facing out); a curved object's far side is many small surfaces.
    pub fn area_facing_away_from_light(&self) -> Vec<f64> {
        let mut away = vec![0.0; self.surfaces.len()];
        let emitting =
            |p: &Patch| self.materials[self.surfaces[p.surface as usize].material as usize].is_emitter();
        let lamps: Vec<DVec3> =
            self.patches.iter().filter(|p| emitting(p)).flat_map(|p| p.corners().to_vec()).collect();
        let (lo, hi) = self.bounds();
        let margin = 1e-9 * (hi - lo).length();
        for p in self.patches.iter().filter(|p| !emitting(p)) {
            let surface = &self.surfaces[p.surface as usize];
            // A lamp in the surface's own plane (the Cornell lamp in its ceiling) lights it
            // no more than one behind it, but it is no sign of a wrong normal: it needs one
            // lamp point strictly behind.
            let side = |q: &DVec3| p.normal.dot(*q - p.centre);
            if surface.twin.is_none()
                && lamps.iter().all(|q| side(q) <= margin)
                && lamps.iter().any(|q| side(q) < -margin)
            {
                away[p.surface as usize] += p.area;
            }
        }
        away
    }

    /// Total area, scene units².
    pub fn total_area(&self) -> f64 {
        self.elements.iter().map(|e| e.area).sum()
    }

    /// Axis-aligned bounds of all vertices.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.positions
            .iter()
            .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Object, box_faces};
    use crate::{Material, Rgb};

    fn scene_of(shape: Shape) -> Scene {
        let m = Material::try_new("m", Rgb::splat(0.5), Rgb::ONE).unwrap();
        Scene::try_new(
            "t",
            None,
            vec![m],
            vec![Object { name: "o".into(), material: 0, shape, sides: crate::Sides::One }],
        )
        .unwrap()
    }

    fn check_mesh(mesh: &Mesh, expected_area: f64, params: &MeshParams) {
        let area: f64 = mesh.elements.iter().map(|e| e.area).sum();
        assert!((area - expected_area).abs() < 1e-9 * expected_area, "area {area} vs {expected_area}");
        for p in &mesh.patches {
            let sum: f64 = mesh.elements[p.elements.start as usize..p.elements.end as usize]
                .iter()
                .map(|e| e.area)
                .sum();
            assert!((sum - p.area).abs() < 1e-9 * p.area);
            for e in p.elements.clone() {
                let el = &mesh.elements[e as usize];
                assert!(el.normal.dot(p.normal) > 0.999);
                let pts: Vec<DVec3> = mesh.element_corners(e as usize).collect();
                for k in 0..pts.len() {
                    assert!(pts[k].distance(pts[(k + 1) % pts.len()]) <= params.element_size * (1.0 + 1e-9));
                }
            }
        }
    }

    #[test]
    fn quad_is_cut_into_patches_and_elements_with_shared_vertices() {
        let q =
            Polygon::try_new(vec![DVec3::ZERO, DVec3::X * 4.0, DVec3::new(4.0, 2.0, 0.0), DVec3::Y * 2.0])
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
        // Euler: a triangulated disc has V - E + F = 1; with exact merging V = F/2 + boundary/2 + 1.
        let f = mesh.elements.len();
        let mut edges = std::collections::HashSet::new();
        for e in &mesh.elements {
            let v = e.vertex_indices();
            for k in 0..v.len() {
                let (a, b) = (v[k], v[(k + 1) % v.len()]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        assert_eq!(mesh.positions.len() as i64 - edges.len() as i64 + f as i64, 1);
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
            let mesh =
                Mesh::build(&scene_of(Shape::Sphere(s)), &MeshParams::try_new(1.0, 0.5).unwrap()).unwrap();
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

    /// A flat n×n grid of unit squares in z = 0, each cut into two triangles.
    fn triangle_grid(n: u32) -> PolygonMesh {
        let positions =
            (0..=n).flat_map(|j| (0..=n).map(move |i| DVec3::new(i as f64, j as f64, 0.0))).collect();
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
        let params = MeshParams::try_new(2.0, 1.0).unwrap();
        let mesh = Mesh::build(&scene_of(Shape::Mesh(grid)), &params).unwrap();
        assert_eq!(mesh.surfaces.len(), 1);
        // Each triangle (longest edge √2) gets 2 element steps: 4 elements, 32 triangles.
        assert_eq!(mesh.elements.len(), 128);
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
        // An L fanned into four triangles as an exporter splits an n-gon: the two on the long
        // arm need 8 steps per edge, the two on the short arm 6 — one surface, 8 steps.
        let positions = [(0.0, 0.0), (3.0, 0.0), (3.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)]
            .map(|(x, y)| DVec3::new(x, y, 0.0))
            .to_vec();
        let faces = vec![vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 4], vec![0, 4, 5]];
        let l = PolygonMesh::try_new(positions, faces).unwrap();
        let params = MeshParams::try_new(1.0, 0.5).unwrap();
        let mesh = Mesh::build(&scene_of(Shape::Mesh(l)), &params).unwrap();
        assert_eq!(mesh.surfaces.len(), 1);
        assert_eq!(mesh.elements.len(), 4 * 8 * 8);
        check_mesh(&mesh, 4.0, &params);
        // A disc (V − E + F = 1) only when the fan's shared diagonals merged exactly.
        assert_eq!(euler_characteristic(&mesh), 1);
    }

    #[test]
    fn a_triangle_pair_making_a_quad_is_meshed_as_that_quad() {
        let params = MeshParams::try_new(2.0, 0.5).unwrap();
        let quad =
            Polygon::try_new(vec![DVec3::ZERO, DVec3::X * 4.0, DVec3::new(4.0, 2.0, 0.0), DVec3::Y * 2.0])
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
        let mesh =
            Mesh::build(&scene_of(Shape::Mesh(cube)), &MeshParams::try_new(0.5, 0.25).unwrap()).unwrap();
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
            Mesh::build(&scene_of(Shape::Mesh(crate::uv_sphere_mesh(DVec3::ZERO, 1.0, 24))), &params)
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
            &scene_of(Shape::Mesh(crate::uv_sphere_mesh(DVec3::ZERO, 1.0, 24))),
            &params.with_crease_angle(0.0).unwrap(),
        )
        .unwrap();
        assert_eq!(flat.smoothing, Smoothing::default());
        // 4 segments make an octahedron: 70.5° between neighbouring facets, above 40°.
        let coarse =
            Mesh::build(&scene_of(Shape::Mesh(crate::uv_sphere_mesh(DVec3::ZERO, 1.0, 4))), &params).unwrap();
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
        let board = crate::scene::box_faces(
            DVec3::new(1.5, 0.05, 1.5),
            DVec3::new(2.5, 0.1, 2.5),
            crate::scene::Facing::Outward,
            0.0,
        )
        .unwrap();
        let lit = Material::try_new("lit", Rgb::splat(0.5), Rgb::ONE).unwrap();
        let wood = Material::try_new("wood", Rgb::splat(0.5), Rgb::ZERO).unwrap();
        let object = |name: &str, material, ps| Object {
            name: name.into(),
            material,
            shape: Shape::Polygons(ps),
            sides: crate::Sides::One,
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
        let floor_elements = |mesh: &Mesh| {
            (0..mesh.elements.len()).filter(|&e| mesh.element_object(e) == 0).collect::<Vec<_>>()
        };
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
        let scene = crate::cornell_box();
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
        let scene = crate::cornell_box();
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
        let scene = crate::cornell_box();
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
                        Shape::Polygons(ps) => {
                            ps.iter().flat_map(|p| p.vertices().to_vec()).collect::<Vec<_>>()
                        }
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
        assert_eq!(room.area_facing_away_from_light(), vec![0.0; 6]);
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
        let away = mesh.area_facing_away_from_light();
        // The lamp faces down (counter-clockwise from below is clockwise from above): the
        // walls' outward faces, one surface each, all have it behind them.
        assert_eq!(away.len(), 7);
        assert!(away[..6].iter().all(|a| (a - 1.0).abs() < 1e-9), "{away:?}");
        assert_eq!(away[6], 0.0, "emitters are not counted");
    }
}
