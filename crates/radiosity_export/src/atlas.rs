//! Lightmaps of the model's own meshes, as game engines take them: every face of every
//! object gets a place in one atlas (a second set of texture coordinates, `TEXCOORD_1`, made
//! by a chart-and-pack unwrap), and every texel the light at its point of the face.
//!
//! The solver meshes the scene afresh (coplanar faces merged, cut at contacts and shadow
//! outlines), so the atlas follows the input faces, not the elements: a texel's point is
//! found on its face, the element under it (same object, same side) by a ray along the
//! face's normal, and its value interpolated from that element's vertex radiosity, as the
//! vertex colours shade. Charts come from `uvunwrap` (segmentation, least-squares conformal
//! maps, shape packing with padding between charts); texels are rasterised by their centres
//! and the empty ones around each chart filled from their neighbours (dilation), so that
//! bilinear filtering and the first mip levels never mix in the black between charts.

use std::collections::HashMap;

use glam::{DVec2, DVec3, Vec3};
use radiosity_accel::{Bvh, RayQuery};
use radiosity_core::{Rgb, Scene, Shape, Sides};
use radiosity_image::{HdrImage, RenderError, RenderParams, Renderer};
use radiosity_mesh::Mesh;
use radiosity_solver::Solution;
use rayon::prelude::*;

/// What a lightmap texel holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightmapQuantity {
    /// Irradiance E arriving at the surface, W per unit²: what an engine multiplies by the
    /// material's albedo (its texture included), L = ρ(uv)·E/π. From the solution as
    /// E = (B − emission)/ρ̄ with the material's mean reflectance ρ̄ (0 where ρ̄ is 0).
    #[default]
    Irradiance,
    /// Radiosity B leaving the surface, W per unit² (the albedo already applied).
    Radiosity,
}

impl LightmapQuantity {
    /// The name used on the command line and in the glTF's description.
    pub fn as_str(self) -> &'static str {
        match self {
            LightmapQuantity::Irradiance => "irradiance",
            LightmapQuantity::Radiosity => "radiosity",
        }
    }
}

/// How the atlas is sized and filled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtlasOptions {
    /// Texels per scene unit; `None`: the most that fits one `size × size` page.
    pub texels_per_unit: Option<f64>,
    /// Page width (and most height) in texels when the density is automatic.
    pub size: u32,
    /// Empty texels kept around each chart (charts are twice this apart), filled by
    /// dilation: enough for bilinear filtering and log₂(padding) mip levels.
    pub padding: u32,
    /// What a texel holds.
    pub quantity: LightmapQuantity,
}

impl Default for AtlasOptions {
    fn default() -> Self {
        Self { texels_per_unit: None, size: 1024, padding: 4, quantity: LightmapQuantity::Irradiance }
    }
}

/// A side of a two-sided object is dim when its mean radiosity is at most this share of the
/// scene's (both area-weighted, brightest channel): the outside of a room, the back of a wall.
pub const DIM: f64 = 1e-2;

/// A dim side's texel density against the rest: an eighth along each axis, a sixty-fourth of
/// the texels, so that the outside of a room takes no more of the atlas than a chair.
pub const DIM_DENSITY: f32 = 1.0 / 8.0;

/// Up to this many triangles the charts are packed by shape (nested into each other's
/// concavities), past it in rows: Sponza's 5 323 charts took 27 s to pack by shape and 3 s in
/// rows, at 0.86 times the texel density (2 048² atlas); the Veach Bidir room's 80 packed
/// alike either way.
pub const SHAPE_PACKING_TRIANGLES: usize = 20_000;

/// How the charts of `inputs` (positions, triangle indices) are packed.
fn packing(inputs: &[(Vec<[f32; 3]>, Vec<u32>)]) -> uvunwrap::Packing {
    let triangles: usize = inputs.iter().map(|(_, i)| i.len() / 3).sum();
    if triangles <= SHAPE_PACKING_TRIANGLES { uvunwrap::Packing::Shape } else { uvunwrap::Packing::Fast }
}

/// One object's faces on one side, unwrapped: the glTF primitive it becomes.
#[derive(Clone, Debug)]
pub struct AtlasMesh {
    /// Scene object index (the same as the mesh's object index), or `usize::MAX` for a
    /// glTF primitive kept as it is (its texels take the element under them, of any object).
    pub object: usize,
    /// The back side of a two-sided object: its faces turned over.
    pub back: bool,
    /// The object is two-sided: a texel takes the element facing its side only.
    pub two_sided: bool,
    /// This side gives off its material's emission (a back side only when the object
    /// `emits_back`).
    pub emits: bool,
    /// Vertex positions, scene frame.
    pub positions: Vec<DVec3>,
    /// The model's own texture coordinates per vertex (v down), when it has them.
    pub uv0: Option<Vec<[f64; 2]>>,
    /// Lightmap coordinates per vertex in [0, 1]² of the atlas, v down (row 0 at the top).
    pub uv1: Vec<[f32; 2]>,
    /// Per vertex, the chart it lies in (numbered across the atlas); `u32::MAX` for a vertex
    /// of degenerate triangles only.
    pub chart: Vec<u32>,
    /// Per vertex, the unwrap's input vertex it was made from (vertices are split along the
    /// charts' seams).
    pub xref: Vec<u32>,
    /// Triangles, three vertex indices each, wound so their normal is the side's.
    pub indices: Vec<u32>,
}

/// A baked atlas.
#[derive(Clone, Debug)]
pub struct Atlas {
    /// The texels, linear, in the unit of [`AtlasOptions::quantity`].
    pub image: HdrImage,
    /// The unwrapped meshes.
    pub meshes: Vec<AtlasMesh>,
    /// Texels per scene unit used.
    pub texels_per_unit: f64,
    /// Charts packed.
    pub charts: u32,
    /// Sides unwrapped at [`DIM_DENSITY`] because they are [`DIM`].
    pub dim_sides: usize,
    /// Texels whose centre lies on a face.
    pub covered: usize,
    /// Of those, texels whose point found no element of its object and side (a part left out
    /// of the solve, such as a face's covered foot): filled by dilation like the padding.
    pub missed: usize,
}

/// Why an atlas cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum AtlasError {
    /// The scene has no faces to lightmap.
    #[error("no faces to lightmap (spheres have no lightmap)")]
    Empty,
    /// The unwrap failed.
    #[error("lightmap unwrap: {0}")]
    Unwrap(#[from] uvunwrap::Error),
    /// The charts did not fit one page.
    #[error("the charts take {0} pages of {1}²: give a larger --atlas-size or fewer --texels-per-unit")]
    Pages(u32, u32),
    /// The model file could not be read again, or holds what the atlas cannot rewrite.
    #[error("{0}")]
    Source(String),
    /// A gather failed.
    #[error(transparent)]
    Gather(#[from] RenderError),
}

/// How a texel's value is found at its point.
#[derive(Clone, Copy)]
pub enum AtlasTexels<'a> {
    /// Interpolated from the element's vertex radiosity.
    Interpolated,
    /// Gathered at the point by the renderer (see [`crate::Texels::Gathered`]).
    Gathered {
        /// The renderer over the same mesh.
        renderer: &'a Renderer,
        /// Gather mode, samples, seed.
        params: &'a RenderParams,
    },
}

/// A face triangle: corners in the scene frame, the model's texture coordinates per corner
/// when it has them.
type Face = ([DVec3; 3], Option<[[f64; 2]; 3]>);

/// The faces of scene object `o` as triangles, fanned from each convex face.
fn object_triangles(scene: &Scene, o: usize) -> Vec<Face> {
    let mut out = Vec::new();
    match &scene.objects[o].shape {
        Shape::Polygons(polygons) => {
            for p in polygons {
                let v = p.vertices();
                for k in 1..v.len() - 1 {
                    out.push(([v[0], v[k], v[k + 1]], None));
                }
            }
        }
        Shape::Mesh(mesh) => {
            let uvs = mesh.uvs();
            for (f, face) in mesh.faces().iter().enumerate() {
                let corner = |i: usize| mesh.positions()[face[i] as usize];
                for k in 1..face.len() - 1 {
                    let uv = uvs.get(f).map(|u| [u[0], u[k], u[k + 1]]);
                    out.push(([corner(0), corner(k), corner(k + 1)], uv));
                }
            }
        }
        Shape::Sphere(_) => {}
    }
    // Degenerate faces get no texels (the mesher dropped them too).
    out.retain(|(t, _)| (t[1] - t[0]).cross(t[2] - t[0]).length_squared() > 0.0);
    out
}

/// Unwraps `scene`'s faces (each object and each side it is meshed on) into one atlas and
/// bakes `solution` on `mesh` into it.
///
/// # Errors
/// [`AtlasError`]: nothing to lightmap, an unwrap that fails or needs several pages, a
/// gather's error.
pub fn bake_atlas(
    scene: &Scene,
    mesh: &Mesh,
    solution: &Solution,
    options: &AtlasOptions,
    texels: AtlasTexels<'_>,
) -> Result<Atlas, AtlasError> {
    let mut meshes = Vec::new();
    let mut inputs: Vec<(Vec<[f32; 3]>, Vec<u32>)> = Vec::new();
    let locator = Locator::new(scene, mesh, false);
    let scene_mean = mean_radiosity(mesh, solution, 0..mesh.elements.len());
    let mut scales = Vec::new();
    for o in 0..scene.objects.len() {
        let triangles = object_triangles(scene, o);
        if triangles.is_empty() {
            continue;
        }
        // A one-sided object: its faces as wound. A two-sided one: each side on which the
        // mesher kept elements (a closed object lit from one side is meshed on that side only:
        // the inside of a room modelled with its normals out).
        let two_sided = matches!(scene.objects[o].sides, Sides::Two { .. });
        for back in [false, true] {
            let faces: Vec<Face> = triangles
                .iter()
                .map(
                    |&(t, uv)| {
                        if back { ([t[0], t[2], t[1]], uv.map(|u| [u[0], u[2], u[1]])) } else { (t, uv) }
                    },
                )
                .collect();
            let (hits, mean) = probe_side(mesh, solution, &locator, o, &faces);
            if (two_sided && hits == 0) || (!two_sided && back) {
                continue;
            }
            let dim = two_sided && mean <= DIM * scene_mean;
            scales.push(if dim { DIM_DENSITY } else { 1.0 });
            let (positions, indices, uv0, corners) = weld(&faces);
            inputs.push((positions.iter().map(|p| p.as_vec3().to_array()).collect(), indices.clone()));
            let emits = !back || matches!(scene.objects[o].sides, Sides::Two { emits_back: true });
            meshes.push(AtlasMesh {
                object: o,
                back,
                two_sided,
                emits,
                positions: corners,
                uv0,
                uv1: Vec::new(),
                chart: Vec::new(),
                xref: Vec::new(),
                indices,
            });
        }
    }
    unwrap_and_bake(mesh, solution, options, texels, &locator, Unwrapping { meshes, inputs, scales })
}

/// What goes into one unwrap: the meshes, their positions and triangles as the unwrap takes
/// them, and each one's density against the rest.
pub(crate) struct Unwrapping {
    pub(crate) meshes: Vec<AtlasMesh>,
    pub(crate) inputs: Vec<(Vec<[f32; 3]>, Vec<u32>)>,
    pub(crate) scales: Vec<f32>,
}

/// Unwraps `work` into one atlas and bakes `solution` on `mesh` into it, texels found by
/// `locator`.
pub(crate) fn unwrap_and_bake(
    mesh: &Mesh,
    solution: &Solution,
    options: &AtlasOptions,
    texels: AtlasTexels<'_>,
    locator: &Locator,
    work: Unwrapping,
) -> Result<Atlas, AtlasError> {
    let Unwrapping { mut meshes, inputs, scales } = work;
    if meshes.is_empty() {
        return Err(AtlasError::Empty);
    }
    let density = match options.texels_per_unit {
        Some(t) => uvunwrap::Density::Fixed { texels_per_unit: t as f32, page_size: None },
        None => uvunwrap::Density::Auto { page_size: options.size },
    };
    let unwrap_options = uvunwrap::Options {
        density,
        padding: options.padding,
        packing: packing(&inputs),
        ..uvunwrap::Options::default()
    };
    let inputs: Vec<uvunwrap::MeshInput> = inputs
        .iter()
        .zip(&scales)
        .map(|((p, i), &scale)| uvunwrap::MeshInput { scale, ..uvunwrap::MeshInput::new(p, i) })
        .collect();
    let atlas = uvunwrap::generate(&inputs, &unwrap_options)?;
    if atlas.page_count > 1 {
        return Err(AtlasError::Pages(atlas.page_count, options.size));
    }
    // The unwrap's vertices are its input's, split along seams: positions and the model's
    // texture coordinates follow them back through `xref`.
    for (m, out) in meshes.iter_mut().zip(&atlas.meshes) {
        let positions: Vec<DVec3> = out.vertices.iter().map(|v| m.positions[v.xref as usize]).collect();
        m.uv0 = m.uv0.take().map(|uv| out.vertices.iter().map(|v| uv[v.xref as usize]).collect());
        m.positions = positions;
        m.uv1 = out.vertices.iter().map(|v| v.uv).collect();
        m.chart = out.vertices.iter().map(|v| v.chart.unwrap_or(u32::MAX)).collect();
        m.xref = out.vertices.iter().map(|v| v.xref).collect();
        m.indices = out.indices.clone();
    }
    let (w, h) = (atlas.width, atlas.height);
    // Texel values, None where no face's point lies.
    let rows: Vec<Vec<Option<Option<Rgb>>>> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut row = vec![None; w as usize];
            for m in &meshes {
                raster_row(m, w, h, y, |x, p, n| {
                    let key = u64::from(y) * u64::from(w) + u64::from(x);
                    let found = locator.value(mesh, solution, m, (p, n), options.quantity, texels, key);
                    row[x as usize] = Some(found);
                });
            }
            row.into_iter().map(|v| v.map(|v| v.transpose()).transpose()).collect::<Result<Vec<_>, _>>()
        })
        .collect::<Result<_, _>>()?;
    let covered = rows.iter().flatten().filter(|v| v.is_some()).count();
    let missed = rows.iter().flatten().filter(|v| matches!(v, Some(None))).count();
    let mut grid: Vec<Option<Rgb>> = rows.into_iter().flatten().map(Option::flatten).collect();
    dilate(&mut grid, w, h, 2 * options.padding + 2);
    let pixels = grid.into_iter().map(|v| v.unwrap_or(Rgb::ZERO)).collect();
    Ok(Atlas {
        image: HdrImage::from_pixels(w, h, pixels),
        meshes,
        texels_per_unit: f64::from(atlas.texels_per_unit),
        charts: atlas.chart_count,
        dim_sides: scales.iter().filter(|&&s| s < 1.0).count(),
        covered,
        missed,
    })
}

/// Welds the corners of `faces` that share both position and model texture coordinates:
/// (positions, triangle indices, texture coordinates per vertex, positions again in double
/// precision). Corners that share a position but not texture coordinates stay apart, so the
/// unwrap's seams include the model's own (and each vertex keeps its one coordinate).
#[allow(clippy::type_complexity)]
fn weld(faces: &[Face]) -> (Vec<DVec3>, Vec<u32>, Option<Vec<[f64; 2]>>, Vec<DVec3>) {
    let textured = faces.iter().all(|(_, uv)| uv.is_some());
    let mut index = HashMap::new();
    let (mut positions, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for (t, uv) in faces {
        for k in 0..3 {
            let u = if textured { uv.map_or([0.0; 2], |u| u[k]) } else { [0.0; 2] };
            let key = (t[k].to_array().map(f64::to_bits), u.map(f64::to_bits));
            let i = *index.entry(key).or_insert_with(|| {
                positions.push(t[k]);
                uvs.push(u);
                positions.len() as u32 - 1
            });
            indices.push(i);
        }
    }
    let corners = positions.clone();
    (positions, indices, textured.then_some(uvs), corners)
}

/// Calls `texel(x, p, n)` for every texel of row `y` (of a `w × h` atlas) whose centre lies
/// in one of `m`'s triangles in lightmap coordinates, with `p` the face's point there and `n`
/// its unit normal.
fn raster_row(m: &AtlasMesh, w: u32, h: u32, y: u32, mut texel: impl FnMut(u32, DVec3, DVec3)) {
    let cy = (f64::from(y) + 0.5) / f64::from(h);
    for tri in m.indices.chunks_exact(3) {
        let uv = [0, 1, 2].map(|k| {
            let t = m.uv1[tri[k] as usize];
            DVec2::new(f64::from(t[0]), f64::from(t[1]))
        });
        let (lo, hi) = (uv[0].y.min(uv[1].y).min(uv[2].y), uv[0].y.max(uv[1].y).max(uv[2].y));
        if cy < lo || cy > hi {
            continue;
        }
        let area = (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]);
        if area.abs() < 1e-18 {
            continue;
        }
        let corners = [0, 1, 2].map(|k| m.positions[tri[k] as usize]);
        let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize_or_zero();
        let x0 = ((uv[0].x.min(uv[1].x).min(uv[2].x) * f64::from(w)).floor().max(0.0)) as u32;
        let x1 = ((uv[0].x.max(uv[1].x).max(uv[2].x) * f64::from(w)).ceil() as u32).min(w);
        for x in x0..x1 {
            let c = DVec2::new((f64::from(x) + 0.5) / f64::from(w), cy);
            let b1 = (c - uv[0]).perp_dot(uv[2] - uv[0]) / area;
            let b2 = (uv[1] - uv[0]).perp_dot(c - uv[0]) / area;
            let b0 = 1.0 - b1 - b2;
            if b0 >= 0.0 && b1 >= 0.0 && b2 >= 0.0 {
                texel(x, corners[0] * b0 + corners[1] * b1 + corners[2] * b2, normal);
            }
        }
    }
}

/// Fills empty texels from their filled neighbours (the mean of the up to eight around),
/// `passes` rings outwards.
fn dilate(grid: &mut [Option<Rgb>], w: u32, h: u32, passes: u32) {
    let (w, h) = (w as i64, h as i64);
    for _ in 0..passes {
        let before = grid.to_vec();
        let mut changed = false;
        for y in 0..h {
            for x in 0..w {
                if before[(y * w + x) as usize].is_some() {
                    continue;
                }
                let (mut sum, mut n) = (Rgb::ZERO, 0.0);
                for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                    let (nx, ny) = (x + dx, y + dy);
                    if (0..w).contains(&nx)
                        && (0..h).contains(&ny)
                        && let Some(v) = before[(ny * w + nx) as usize]
                    {
                        sum += v;
                        n += 1.0;
                    }
                }
                if n > 0.0 {
                    grid[(y * w + x) as usize] = Some(sum * (1.0 / n));
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
}

/// A locator triangle's element and the three of its vertex indices it spans.
type Owner = (u32, [u32; 3]);

/// An element found under a face's point: the element and its radiosity interpolated there.
struct Found {
    element: usize,
    radiosity: Rgb,
}

/// Finds the element under a point of an object's face. Per object, two ray structures over
/// its element triangles (a quad split in two): its front surfaces' and its back surfaces'
/// (a two-sided object's twins), so that the coplanar twin of an element is never in the
/// same structure and the nearest hit along the face's normal is one element.
pub(crate) struct Locator {
    /// Per (object, back surfaces): the structure and, per triangle, its element and corners.
    parts: HashMap<(usize, bool), (Bvh, Vec<Owner>)>,
    /// Distance off the face the rays start from, and twice it their reach: far above the
    /// structure's single precision, far below a model's detail.
    lift: f64,
}

/// The object key of a [`Locator`] over every object at once.
pub(crate) const ANY_OBJECT: usize = usize::MAX;

impl Locator {
    /// The locator over `mesh`'s elements, per object, or over all of them as one
    /// ([`ANY_OBJECT`]) when `any` (faces that are not the scene's objects: a glTF's
    /// primitives kept as they are).
    pub(crate) fn new(scene: &Scene, mesh: &Mesh, any: bool) -> Self {
        let (lo, hi) = scene.bounds();
        let lift = 1e-4 * (hi - lo).length().max(1e-9);
        type Part = (Vec<[Vec3; 3]>, Vec<Owner>);
        let mut triangles: HashMap<(usize, bool), Part> = HashMap::new();
        for (e, el) in mesh.elements.iter().enumerate() {
            let surface = &mesh.surfaces[mesh.patches[el.patch as usize].surface as usize];
            let object = if any { ANY_OBJECT } else { surface.object as usize };
            let entry = triangles.entry((object, surface.back)).or_default();
            let v = el.vertex_indices();
            for k in 1..v.len() - 1 {
                let corners = [v[0], v[k], v[k + 1]];
                entry.0.push(corners.map(|i| mesh.positions[i as usize].as_vec3()));
                entry.1.push((e as u32, corners));
            }
        }
        let parts =
            triangles.into_iter().map(|(key, (tris, owners))| (key, (Bvh::new(&tris), owners))).collect();
        Self { parts, lift }
    }

    /// The element of object `o` under point `p` of a face with unit normal `normal`, and its
    /// radiosity there: one facing the same way as the face, or, unless `facing` is asked
    /// for, one facing the other way (a one-sided object the mesher turned over).
    fn find(
        &self,
        mesh: &Mesh,
        solution: &Solution,
        o: usize,
        p: DVec3,
        normal: DVec3,
        facing: bool,
    ) -> Option<Found> {
        let start = (p + normal * self.lift).as_vec3();
        let mut turned = None;
        for back in [false, true] {
            let Some((bvh, owners)) = self.parts.get(&(o, back)) else { continue };
            let Some(hit) = bvh.closest_hit(start, -normal.as_vec3(), (2.0 * self.lift) as f32) else {
                continue;
            };
            let (e, corners) = owners[hit.triangle as usize];
            let weights = [1.0 - f64::from(hit.u) - f64::from(hit.v), f64::from(hit.u), f64::from(hit.v)];
            let radiosity = corners
                .iter()
                .zip(weights)
                .map(|(&v, w)| solution.vertex_radiosity[v as usize] * w)
                .sum::<Rgb>();
            let found = Found { element: e as usize, radiosity };
            if mesh.elements[e as usize].normal.dot(normal) > 0.0 {
                return Some(found);
            }
            turned = turned.or(Some(found));
        }
        if facing { None } else { turned }
    }

    /// The texel value at point `p` of one of `m`'s faces, whose unit normal is `normal`
    /// (the gather's random stream keyed by `key`): `None` when no element of its object lies
    /// under it, facing the way the side does when the object is two-sided.
    #[allow(clippy::too_many_arguments)]
    fn value(
        &self,
        mesh: &Mesh,
        solution: &Solution,
        m: &AtlasMesh,
        (p, normal): (DVec3, DVec3),
        quantity: LightmapQuantity,
        texels: AtlasTexels<'_>,
        key: u64,
    ) -> Option<Result<Rgb, RenderError>> {
        let Found { element: e, radiosity } = self.find(mesh, solution, m.object, p, normal, m.two_sided)?;
        let b = match texels {
            AtlasTexels::Interpolated => radiosity,
            AtlasTexels::Gathered { renderer, params } => {
                // A thousandth of the way to the element's centre: a face's edge may be a
                // room's edge, where rays graze the next wall.
                let q = p + (mesh.elements[e].centre - p) * 1e-3;
                match renderer.gathered_radiosity(solution, e, q, params, key) {
                    Ok(b) => b,
                    Err(err) => return Some(Err(err)),
                }
            }
        };
        Some(Ok(match quantity {
            LightmapQuantity::Radiosity => b,
            LightmapQuantity::Irradiance => irradiance(mesh, e, b, m.emits),
        }))
    }
}

/// Faces probed to tell which sides of a two-sided object were meshed and how bright they
/// are, at most.
const PROBES: usize = 256;

/// Points probed per face: the inner points of a lattice of this many steps per edge (a face
/// may lie partly under a solid standing on it, left out of the solve, its centroid too).
const PROBE_STEPS: u32 = 6;

/// Of the faces `faces` of object `o` seen from the side whose normals they have: at how
/// many points (spread over up to [`PROBES`] of them) an element facing that way lies, and
/// the area-weighted mean of the brightest channel of its radiosity there.
fn probe_side(mesh: &Mesh, solution: &Solution, locator: &Locator, o: usize, faces: &[Face]) -> (usize, f64) {
    let step = faces.len().div_ceil(PROBES).max(1);
    let (mut hits, mut sum, mut area) = (0, 0.0, 0.0);
    for (t, _) in faces.iter().step_by(step) {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        for i in 1..PROBE_STEPS {
            for j in 1..PROBE_STEPS - i {
                let (a, b) = (f64::from(i) / f64::from(PROBE_STEPS), f64::from(j) / f64::from(PROBE_STEPS));
                let point = t[0] * (1.0 - a - b) + t[1] * a + t[2] * b;
                if let Some(found) = locator.find(mesh, solution, o, point, n.normalize(), true) {
                    let b = found.radiosity;
                    hits += 1;
                    sum += b.r.max(b.g).max(b.b) * n.length();
                    area += n.length();
                }
            }
        }
    }
    (hits, if area > 0.0 { sum / area } else { 0.0 })
}

/// The area-weighted mean of the brightest channel of `elements`' radiosity.
fn mean_radiosity(mesh: &Mesh, solution: &Solution, elements: impl Iterator<Item = usize>) -> f64 {
    let (mut sum, mut area) = (0.0, 0.0);
    for e in elements {
        let (b, a) = (solution.element_radiosity[e], mesh.elements[e].area);
        sum += b.r.max(b.g).max(b.b) * a;
        area += a;
    }
    if area > 0.0 { sum / area } else { 0.0 }
}

/// Irradiance from radiosity `b` on element `e`: (B − emission)/ρ̄ per channel (the emission
/// only where the side `emits`), 0 where ρ̄ is 0.
fn irradiance(mesh: &Mesh, e: usize, b: Rgb, emits: bool) -> Rgb {
    let material = mesh.element_material(e);
    let emitted = if emits { material.emission } else { Rgb::ZERO };
    let reflected = (b - emitted).to_array();
    let rho = material.reflectance.to_array();
    let c = |k: usize| if rho[k] > 0.0 { (reflected[k] / rho[k]).max(0.0) } else { 0.0 };
    Rgb::new(c(0), c(1), c(2))
}
