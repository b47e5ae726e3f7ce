//! "Render still": the current view rendered on the CPU with a final gather, in the
//! background, while the window keeps showing the live radiosity mesh.
//!
//! The mesh is right for a walkthrough (any view, every frame, no noise) and too soft for a
//! still; the gather (`radiosity_image`'s `Gather::Direct`) gives the same view sharp shadows.
//! The still is rendered from a copy of the snapshot and camera of the moment it was asked
//! for, so flying on or a solve going on does not disturb it.

use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::time::Instant;

use radiosity_core::{Camera, Scene};
use radiosity_image::{Gather, HdrImage, RenderParams, Renderer};
use radiosity_mesh::Mesh;
use radiosity_solver::Solution;

/// Longest side of a still, pixels: the view's size, capped so a large window renders in
/// seconds on a few cores.
pub(crate) const MAX_STILL_SIDE: u32 = 1280;

/// A finished still.
pub(crate) struct Still {
    /// Linear radiance per pixel.
    pub radiance: HdrImage,
    /// How it was gathered.
    pub gather: Gather,
    /// Rendering time, seconds.
    pub seconds: f64,
    /// Shots of the solution it shows.
    pub shots: u64,
}

/// A still being rendered on its own thread.
pub(crate) struct StillJob {
    receiver: Receiver<Result<Still, String>>,
    /// When it was asked for.
    pub started: Instant,
}

/// What [`StillJob::poll`] found.
pub(crate) enum StillPoll {
    /// Still rendering.
    Running,
    /// Done (or failed, with the message to show).
    Done(Result<Still, String>),
}

impl StillJob {
    /// Starts rendering `solution` on `mesh` from `camera` at `size` pixels (capped at
    /// [`MAX_STILL_SIDE`], aspect kept), with `gather`, showing the colour textures of
    /// `textures`, the scene `mesh` was built from, when given; `notify` is called when it is
    /// done.
    pub(crate) fn spawn(
        mesh: Arc<Mesh>,
        textures: Option<Arc<Scene>>,
        solution: Solution,
        camera: Camera,
        size: [u32; 2],
        gather: Gather,
        notify: impl Fn() + Send + 'static,
    ) -> Self {
        let (sender, receiver) = channel();
        let [width, height] = still_size(size);
        std::thread::spawn(move || {
            let start = Instant::now();
            let params = RenderParams { width, height, gather, ..RenderParams::default() };
            // The textured faces' ray structure is built here, off the window's thread.
            let renderer = match textures {
                Some(scene) => Renderer::new(mesh).with_textures(&scene),
                None => Renderer::new(mesh),
            };
            let result = renderer
                .render(&solution, &camera, &params)
                .map(|r| Still {
                    radiance: r.radiance,
                    gather,
                    seconds: start.elapsed().as_secs_f64(),
                    shots: solution.shots,
                })
                .map_err(|e| e.to_string());
            // The window may have closed meanwhile: nobody to tell.
            let _ = sender.send(result);
            notify();
        });
        Self { receiver, started: Instant::now() }
    }

    /// Whether the still is done.
    pub(crate) fn poll(&self) -> StillPoll {
        match self.receiver.try_recv() {
            Ok(result) => StillPoll::Done(result),
            Err(TryRecvError::Empty) => StillPoll::Running,
            Err(TryRecvError::Disconnected) => {
                StillPoll::Done(Err("the still renderer stopped unexpectedly".to_owned()))
            }
        }
    }
}

/// The still's size for a view of `view` pixels: the same aspect, the longer side at most
/// [`MAX_STILL_SIDE`], each side at least 1.
pub(crate) fn still_size(view: [u32; 2]) -> [u32; 2] {
    let [w, h] = view.map(|v| v.max(1));
    let scale = (f64::from(MAX_STILL_SIDE) / f64::from(w.max(h))).min(1.0);
    [w, h].map(|v| ((f64::from(v) * scale).round() as u32).max(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_core::MeshParams;
    use radiosity_core::glam::DVec3;
    use radiosity_scenes::furnace_box;
    use radiosity_solver::{Problem, SolverParams, StepBudget};

    #[test]
    fn still_size_keeps_the_aspect_and_caps_the_side() {
        assert_eq!(still_size([640, 480]), [640, 480]);
        assert_eq!(still_size([2560, 1440]), [1280, 720]);
        assert_eq!(still_size([0, 0]), [1, 1]);
    }

    /// A still of the inside of the furnace arrives and shows its radiance,
    /// L = E/((1 − ρ)π), on average within 2 %.
    #[test]
    fn a_still_of_the_furnace_arrives_with_its_radiance() {
        let scene = furnace_box(0.5, 1.0);
        let problem = Problem::new(&scene, &MeshParams::try_new(0.5, 0.25).unwrap()).unwrap();
        let mesh = problem.mesh().clone();
        let mut solver = problem.solver(SolverParams::default()).unwrap();
        solver.step(StepBudget::Shots(u64::MAX));
        let camera = Camera::try_new(DVec3::splat(0.5), DVec3::new(1.0, 0.7, 1.0), DVec3::Y, 90.0).unwrap();
        let job = StillJob::spawn(mesh, None, solver.solution(), camera, [32, 24], Gather::Direct, || {});
        let still = loop {
            match job.poll() {
                StillPoll::Running => std::thread::sleep(std::time::Duration::from_millis(10)),
                StillPoll::Done(result) => break result.unwrap(),
            }
        };
        let pixels = still.radiance.pixels();
        let mean = pixels.iter().map(|p| p.sum() / 3.0).sum::<f64>() / pixels.len() as f64;
        let expected = 1.0 / (0.5 * std::f64::consts::PI);
        assert!((mean / expected - 1.0).abs() < 0.02, "mean radiance {mean}, expected {expected}");
        assert_eq!((still.radiance.width(), still.radiance.height()), (32, 24));
    }
}
