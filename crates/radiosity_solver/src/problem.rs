//! The one way from a scene to something to solve: mesh the scene, build the ray queries over
//! its blocking occluders, hand both to the solver.
//!
//! Every caller (the command line, the viewer's worker, tests, benches, examples) goes through
//! [`Problem::new`], so they all solve the same mesh with the same BVH build and therefore get
//! the same numbers for the same scene, parameters and seed.

use std::sync::Arc;

use radiosity_accel::{Bvh, RayQuery};
use radiosity_core::{Mesh, MeshError, MeshParams, Scene};

use crate::{Solver, SolverError, SolverParams, occluder_triangles};

/// A meshed scene with its ray queries: everything [`Solver::new`] needs besides its params.
///
/// Cheap to clone (two shared pointers); one problem can feed several solvers (different
/// params, a restart) without meshing again.
///
/// ```
/// use radiosity_core::furnace_box;
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
}

impl Problem {
    /// Meshes `scene` with `mesh_params` and builds a [`Bvh`] over the mesh's blocking occluder
    /// triangles ([`occluder_triangles`]).
    ///
    /// Emission is taken from the scene as it is: a caller that scales the lights does so on
    /// the scene before calling this.
    ///
    /// # Errors
    /// [`MeshError`] when the scene cannot be meshed with these sizes (too many elements, …).
    pub fn new(scene: &Scene, mesh_params: &MeshParams) -> Result<Self, MeshError> {
        Ok(Self::from_mesh(Arc::new(Mesh::build(scene, mesh_params)?)))
    }

    /// A problem over a mesh built elsewhere: builds the [`Bvh`] over its blocking occluder
    /// triangles, exactly as [`Problem::new`] does.
    pub fn from_mesh(mesh: Arc<Mesh>) -> Self {
        let ray_queries = Arc::new(Bvh::new(&occluder_triangles(&mesh)));
        Self { mesh, ray_queries }
    }

    /// A problem with a ray-query backend of the caller's choice (for example
    /// [`radiosity_accel::BruteForce`] over every occluder, to test the production path
    /// against it). The backend must answer for the occluders of `mesh`.
    pub fn with_ray_queries(mesh: Arc<Mesh>, ray_queries: Arc<dyn RayQuery>) -> Self {
        Self { mesh, ray_queries }
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
        Solver::new(self.mesh.clone(), self.ray_queries.clone(), params)
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
    use radiosity_core::furnace_box;

    /// The problem's solver gives what the hand-built mesh and BVH give, bit for bit: the
    /// same mesh and the same BVH build.
    #[test]
    fn solves_like_the_steps_spelled_out() {
        let scene = furnace_box(0.5, 1.0);
        let params = SolverParams { max_shots: Some(20), ..SolverParams::default() };
        let mut via_problem =
            Problem::new(&scene, &scene.mesh_params()).unwrap().solver(params.clone()).unwrap();
        let mesh = Arc::new(Mesh::build(&scene, &scene.mesh_params()).unwrap());
        let accel = Arc::new(Bvh::new(&occluder_triangles(&mesh)));
        let mut by_hand = Solver::new(mesh, accel, params).unwrap();
        via_problem.solve();
        by_hand.solve();
        assert_eq!(via_problem.solution().element_radiosity, by_hand.solution().element_radiosity);
        assert!(via_problem.solution().shots > 0);
    }

    #[test]
    fn a_mesh_error_is_returned_not_panicked() {
        let scene = furnace_box(0.5, 1.0);
        let tiny = MeshParams::try_new(1e-6, 1e-6).unwrap();
        assert!(Problem::new(&scene, &tiny).is_err());
    }
}
