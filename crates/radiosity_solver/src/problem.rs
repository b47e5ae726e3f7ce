//! The one way from a scene to something to solve: mesh the scene, build the ray queries over
//! its blocking occluders, hand both to the solver.
//!
//! Every caller (the command line, the viewer's worker, tests, benches, examples) goes through
//! [`Problem::new`], so they all solve the same mesh with the same BVH build and therefore get
//! the same numbers for the same scene, parameters and seed.

use std::sync::Arc;

use radiosity_accel::RayQuery;
use radiosity_core::{Daylight, Luminaire, MeshParams, Rgb, Scene};
use radiosity_mesh::{MAX_ELEMENTS, Mesh, MeshError, Refinement};

use crate::solution::VertexElements;
use crate::{Solver, SolverError, SolverParams, occluder_queries};

/// Unshot share at which [`Problem::new`]'s probe solves stop: the shadows and the light's
/// falloff are in place long before convergence.
pub const PROBE_UNSHOT: f64 = 0.2;

/// Gauss cells per side at most in the probe solves' receivers (the solve's default is 2):
/// the probe only tells steep from smooth. On the Cornell box the whole `solve` is 5 % faster
/// (1.00 → 0.95 s on one core), the refined mesh 11 976 elements instead of 11 990, and
/// neither the object means against the path tracer (four seeds) nor the pictures' error
/// per pixel (`render --gather none` 2.90 %, `direct` 1.86 %) move. Stopping the probes
/// later (30 % unshot) saved a fifth of the command but put `none` at 3.43 %.
pub const PROBE_QUADRATURE: u32 = 1;

/// Penumbra rays in the probe solves (the solve's default is 56): the probe only tells
/// steep from smooth, and its refinement was measured with 12. With 56 it refines 3 % fewer
/// elements on the Cornell box (11 580 instead of 11 976) and the solve's object means move
/// darker by 0.1–0.2 % (floor −0.24 % against −0.12 %, median object 0.20–0.36 % against
/// 0.14–0.24 % over seeds 0–3), though the mesh's picture gains (`render --gather none`
/// 2.49 % against 2.70 %).
pub const PROBE_PENUMBRA_RAYS: u32 = 12;

/// Relative difference between neighbouring elements' radiosity above which adaptive
/// subdivision quarters them: a shadow's edge, not the few percent of a smooth gradient or of
/// the probe's visibility noise.
pub const STEEP: f64 = 0.3;

/// Meshes of more elements than this are not refined: each level's probe solve costs about
/// what the solve does, and on a large model the first light would wait for them.
pub const ADAPTIVE_MAX_ELEMENTS: usize = 50_000;

/// Meshes of more patches than this are not refined either: a probe's cost is mostly its
/// shooters' first rows (a tessellated model of 7 000 facets, each its own patch, solves in
/// about 10 s; two probes would hold its first picture back by several seconds).
pub const ADAPTIVE_MAX_PATCHES: usize = 2_000;

/// Adaptive subdivision stops before the mesh has this many times the unrefined mesh's
/// elements.
pub const REFINE_GROWTH: usize = 3;

/// The elements of `mesh` larger than `min_area` whose luminance differs from a neighbour's
/// (same surface, a shared vertex) by more than [`STEEP`] of the larger, steepest first (ties
/// by index), each with its largest relative difference. Pairs darker than 1 % of the mean
/// of the elements that do not emit are left alone: their differences are the probe's noise.
fn steep_elements(mesh: &Mesh, radiosity: &[Rgb], min_area: f64) -> Vec<(usize, f64)> {
    let y: Vec<f64> = radiosity.iter().map(|c| c.luminance()).collect();
    let emits = |e: usize| mesh.element_material(e).emission.max_channel() > 0.0;
    let lit: Vec<f64> = (0..y.len()).filter(|&e| !emits(e)).map(|e| y[e]).collect();
    let floor = 0.01 * lit.iter().sum::<f64>() / lit.len().max(1) as f64;
    let at_vertex = VertexElements::new(mesh);
    // The difference below grows as the neighbour's luminance moves away from the element's
    // either way, so the darkest and the brightest element at a vertex give the largest:
    // each vertex's range stands for its elements. (Visiting every element at every vertex of
    // every element was quadratic in a vertex's valence: the centre of a fan of 10⁵
    // triangles.)
    let range: Vec<(f64, f64)> = (0..mesh.positions.len())
        .map(|v| {
            at_vertex.of(v).iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &n| {
                (lo.min(y[n as usize]), hi.max(y[n as usize]))
            })
        })
        .collect();
    let difference = |a: f64, b: f64| {
        let larger = a.max(b);
        if larger <= floor { 0.0 } else { (a - b).abs() / larger }
    };
    let mut out: Vec<(usize, f64)> = Vec::new();
    for (e, el) in mesh.elements.iter().enumerate() {
        if el.area < min_area || emits(e) {
            continue;
        }
        let worst = el
            .vertex_indices()
            .iter()
            .map(|&v| range[v as usize])
            .filter(|(lo, hi)| lo <= hi)
            .map(|(lo, hi)| difference(y[e], lo).max(difference(y[e], hi)))
            .fold(0.0, f64::max);
        if worst > STEEP {
            out.push((e, worst));
        }
    }
    out.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    out
}

/// A meshed scene with its ray queries: everything [`Solver::new`] needs besides its params.
///
/// Cheap to clone (two shared pointers); one problem can feed several solvers (different
/// params, a restart) without meshing again.
///
/// ```
/// use radiosity_scenes::furnace_box;
/// use radiosity_solver::{Problem, SolverParams};
///
/// let scene = furnace_box(0.5, 1.0);
/// let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
/// let mut solver = problem.solver(SolverParams::preview()).unwrap();
/// solver.solve();
/// assert!(solver.solution().shots > 0);
/// ```
#[derive(Clone)]
pub struct Problem {
    mesh: Arc<Mesh>,
    ray_queries: Arc<dyn RayQuery>,
    /// Elements before adaptive subdivision.
    unrefined_elements: usize,
    /// The scene's point luminaires, which shoot first in every solver made here.
    luminaires: Arc<[Luminaire]>,
    /// The scene's sun and sky, which shoot first too.
    daylight: Daylight,
}

impl Problem {
    /// Meshes `scene` with `mesh_params` and builds a [`Bvh`] over the mesh's blocking occluder
    /// triangles ([`occluder_queries`]).
    ///
    /// Emission is taken from the scene as it is: a caller that scales the lights does so on
    /// the scene before calling this.
    ///
    /// With [`MeshParams::adaptive_levels`] > 0 the mesh is then refined where the light
    /// changes steeply: probe solves find the elements whose radiosity differs from a
    /// neighbour's by more than 30 % (`STEEP`), and the scene is meshed again with those
    /// quartered (adaptive subdivision, see `refined` in the source).
    ///
    /// # Errors
    /// [`MeshError`] when the scene cannot be meshed with these sizes (too many elements, …).
    pub fn new(scene: &Scene, mesh_params: &MeshParams) -> Result<Self, MeshError> {
        let problem = Self::from_mesh(Arc::new(Mesh::build(scene, mesh_params)?))
            .with_luminaires(scene.lighting.luminaires.clone())
            .with_daylight(scene.lighting.daylight());
        Ok(problem.refined(scene, mesh_params))
    }

    /// Adaptive subdivision (Cohen, Greenberg, Immel & Brock 1986), `adaptive_levels` times:
    /// a quick probe solve of the mesh so far (to [`PROBE_UNSHOT`] unshot, the solver's
    /// default seed, so the mesh does not depend on the caller's seed or threads), then every
    /// element whose radiosity differs from a neighbour's (an element of its surface sharing
    /// a vertex) by more than [`STEEP`] of the larger is quartered, if it is larger than the
    /// element size / 2^levels — shadow edges, the light's own falloff near it — and the
    /// scene meshed again with those quartered. The final solve starts from scratch on the
    /// last mesh, so nothing shot is lost or counted twice. Steepest first, as many as keep
    /// the refined mesh under [`REFINE_GROWTH`] times the unrefined count (and
    /// [`MAX_ELEMENTS`]); meshes of more than [`ADAPTIVE_MAX_ELEMENTS`] elements or
    /// [`ADAPTIVE_MAX_PATCHES`] patches are left as they are.
    /// The occluders are the scene's polygons whatever the mesh, so the ray queries are kept.
    fn refined(self, scene: &Scene, params: &MeshParams) -> Self {
        let base = self.mesh.elements.len();
        if base > ADAPTIVE_MAX_ELEMENTS || self.mesh.patches.len() > ADAPTIVE_MAX_PATCHES {
            return self;
        }
        let budget = (base * REFINE_GROWTH).min(MAX_ELEMENTS);
        let min_area = (params.element_size / f64::from(1u32 << params.adaptive_levels)).powi(2);
        let mut refinement = Refinement::default();
        let mut problem = self;
        for _ in 0..params.adaptive_levels {
            let probe_params = SolverParams {
                unshot_threshold: PROBE_UNSHOT,
                max_quadrature: PROBE_QUADRATURE,
                penumbra_rays: PROBE_PENUMBRA_RAYS,
                ..SolverParams::default()
            };
            let Ok(mut probe) = problem.solver(probe_params) else { break };
            probe.solve();
            let mesh = &problem.mesh;
            let mut steep = steep_elements(mesh, &probe.solution().element_radiosity, min_area);
            // Each quartered element adds three, and its neighbours' fans about two more.
            let room = budget.saturating_sub(mesh.elements.len()) / 5;
            steep.truncate(room);
            if refinement.add_level(mesh, steep.into_iter().map(|(e, _)| e)) == 0 {
                break;
            }
            match Mesh::build_refined(scene, params, &refinement) {
                Ok(m) => {
                    problem = Self::with_ray_queries(Arc::new(m), problem.ray_queries.clone())
                        .with_luminaires(problem.luminaires.to_vec())
                        .with_daylight(problem.daylight);
                }
                Err(_) => break,
            }
        }
        problem.unrefined_elements = base;
        problem
    }

    /// A problem over a mesh built elsewhere: builds the ray structure over its blocking
    /// occluder triangles ([`occluder_queries`]), exactly as [`Problem::new`] does.
    pub fn from_mesh(mesh: Arc<Mesh>) -> Self {
        let ray_queries = occluder_queries(&mesh);
        Self::with_ray_queries(mesh, ray_queries)
    }

    /// The same problem lit by the sun and sky of `daylight` too (they shoot first in every
    /// solver made from it).
    pub fn with_daylight(mut self, daylight: Daylight) -> Self {
        self.daylight = daylight;
        self
    }

    /// The same problem lit by `luminaires` too (each shoots first in every solver made
    /// from it).
    pub fn with_luminaires(mut self, luminaires: Vec<Luminaire>) -> Self {
        self.luminaires = Arc::from(luminaires);
        self
    }

    /// The point luminaires every solver of this problem starts from.
    pub fn luminaires(&self) -> &[Luminaire] {
        &self.luminaires
    }

    /// A problem with a ray-query backend of the caller's choice (for example
    /// [`radiosity_accel::BruteForce`] over every occluder, to test the production path
    /// against it). The backend must answer for the occluders of `mesh`.
    pub fn with_ray_queries(mesh: Arc<Mesh>, ray_queries: Arc<dyn RayQuery>) -> Self {
        let unrefined_elements = mesh.elements.len();
        Self {
            mesh,
            ray_queries,
            unrefined_elements,
            luminaires: Arc::from([]),
            daylight: Daylight::default(),
        }
    }

    /// How many elements the mesh had before adaptive subdivision (its own count when it was
    /// not refined).
    pub fn unrefined_elements(&self) -> usize {
        self.unrefined_elements
    }

    /// The meshed scene: patches, elements, occluders.
    pub fn mesh(&self) -> &Arc<Mesh> {
        &self.mesh
    }

    /// Occlusion queries over the mesh's blocking occluders.
    pub fn ray_queries(&self) -> &Arc<dyn RayQuery> {
        &self.ray_queries
    }

    /// A solver for this problem.
    ///
    /// # Errors
    /// As [`Solver::new`]: out-of-range params, a scene that emits nothing.
    pub fn solver(&self, params: SolverParams) -> Result<Solver, SolverError> {
        Solver::with_lights(
            self.mesh.clone(),
            self.ray_queries.clone(),
            params,
            &self.luminaires,
            self.daylight.clone(),
        )
    }
}

impl std::fmt::Debug for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Problem")
            .field("patches", &self.mesh.patches.len())
            .field("elements", &self.mesh.elements.len())
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Ambient;
    use radiosity_scenes::furnace_box;

    /// The problem's solver gives what the hand-built mesh and BVH give, bit for bit: the
    /// same mesh and the same BVH build.
    #[test]
    fn solves_like_the_steps_spelled_out() {
        let scene = furnace_box(0.5, 1.0);
        let params = SolverParams { max_shots: Some(20), ..SolverParams::default() };
        let mut via_problem =
            Problem::new(&scene, &scene.mesh_params()).unwrap().solver(params.clone()).unwrap();
        let mesh = Arc::new(Mesh::build(&scene, &scene.mesh_params()).unwrap());
        let accel = occluder_queries(&mesh);
        let mut by_hand = Solver::new(mesh, accel, params).unwrap();
        via_problem.solve();
        by_hand.solve();
        assert_eq!(via_problem.solution().element_radiosity, by_hand.solution().element_radiosity);
        assert!(via_problem.solution().shots > 0);
    }

    /// The solver's object means (what `solve` prints) are the snapshot's, ambient term
    /// included, and mid-solve (unshot power left for the ambient term to stand for).
    #[test]
    fn object_means_without_a_snapshot_are_the_snapshots() {
        let scene = radiosity_scenes::cornell_box();
        for ambient in [Ambient::Off, Ambient::On] {
            let params = SolverParams { max_shots: Some(30), ambient, ..SolverParams::preview() };
            let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
            let mut solver = problem.solver(params).unwrap();
            solver.solve();
            let direct = solver.object_radiosity();
            assert_eq!(direct, solver.solution().object_radiosity(problem.mesh()), "{ambient:?}");
            assert!(direct.iter().any(|o| o.radiosity.sum() > 0.0));
        }
    }

    #[test]
    fn a_mesh_error_is_returned_not_panicked() {
        let scene = furnace_box(0.5, 1.0);
        let tiny = MeshParams::try_new(1e-6, 1e-6).unwrap();
        assert!(Problem::new(&scene, &tiny).is_err());
    }
}
