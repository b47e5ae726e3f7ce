//! The solve worker: meshes the scene and runs the solver on its own thread, and publishes the
//! newest solution so the window can show it without ever waiting for a shot.
//!
//! Protocol: the UI sends commands over a channel (pause, resume, step one shot, restart with
//! a new job, shut down); the worker publishes a [`Status`] and, when the solution changed, a
//! [`Snapshot`] into one shared slot (newest wins: nothing queues up if the UI is slow).
//! The worker blocks on the channel whenever it has nothing to do (paused, stopped), so an
//! idle viewer costs no CPU, and dropping the [`SolveWorker`] ends and joins the thread.
//! Restarts arriving faster than meshing are coalesced: only the newest job is built.

use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use radiosity_core::{MeshParams, Scene};
use radiosity_image::ElementUvs;
use radiosity_mesh::Mesh;
use radiosity_solver::{Problem, Solution, Solver, SolverParams, StepBudget, StopReason};

/// How long the worker shoots between two publications: 20 updates a second, well above the
/// 10 the viewer promises, while a publication (a copy of the solution) stays a small cost.
pub const PUBLISH_INTERVAL: Duration = Duration::from_millis(50);

/// What to solve: a scene with its light scale, subdivision and solver settings.
#[derive(Clone, Debug)]
pub struct SolveJob {
    /// What the user gave to open it (a path or a built-in name), for display.
    pub label: String,
    /// The scene as loaded, before the light scale.
    pub scene: Arc<Scene>,
    /// Factor on every emission (the source document's light intensity, S11), > 0.
    pub light_scale: f64,
    /// Subdivision into patches and elements (S10).
    pub mesh_params: MeshParams,
    /// Solver settings, stop criteria included.
    pub solver_params: SolverParams,
}

impl SolveJob {
    /// Whether `other` has the same geometry, so its mesh and ray-query structure can be
    /// reused and a restart need not re-mesh.
    fn same_mesh(&self, other: &SolveJob) -> bool {
        Arc::ptr_eq(&self.scene, &other.scene)
            && self.light_scale == other.light_scale
            && self.mesh_params == other.mesh_params
    }
}

/// Options of the worker thread itself.
#[derive(Clone, Default)]
pub struct WorkerOptions {
    /// Solver threads; `None`: all cores but one, which stays with the window.
    pub threads: Option<usize>,
    /// Start paused (the first job is still meshed).
    pub start_paused: bool,
    /// Pause by itself once this many shots are done (screenshots after N shots).
    pub pause_at_shots: Option<u64>,
    /// Called after every publication, from the worker thread (the window asks for a repaint).
    pub notify: Option<Arc<dyn Fn() + Send + Sync>>,
}

/// What the worker is doing.
#[derive(Clone, Debug, PartialEq)]
pub enum WorkerState {
    /// Building the mesh and the ray-query structure of a new job.
    Meshing,
    /// Shooting.
    Running,
    /// Waiting for resume or step.
    Paused,
    /// The solver met a stop criterion.
    Stopped(StopReason),
    /// The worker thread has ended (only seen if it panicked: dropping joins it).
    Ended,
}

/// Figures of the current solve.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Progress {
    /// Patches (shooters).
    pub patches: usize,
    /// Elements (receivers).
    pub elements: usize,
    /// Shots done.
    pub shots: u64,
    /// Unshot power / emitted power, in [0, 1] (may exceed 1 briefly with overshooting).
    pub unshot_fraction: f64,
    /// The convergence threshold on `unshot_fraction`.
    pub unshot_threshold: f64,
    /// Rays traced so far.
    pub rays: u64,
    /// Solving time so far (excludes meshing and pauses).
    pub elapsed: Duration,
}

impl Progress {
    /// Rays per second of solving time.
    pub fn rays_per_second(&self) -> f64 {
        self.rays as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }

    /// Fraction done on a log scale, from 0 (nothing shot) to 1 (threshold reached): the
    /// unshot fraction falls roughly geometrically, so this grows roughly linearly in time.
    pub fn done_fraction(&self) -> f64 {
        let t = self.unshot_threshold.clamp(1e-300, 0.999_999);
        (self.unshot_fraction.max(t).ln() / t.ln()).clamp(0.0, 1.0)
    }

    /// Estimated solving time left, from the log-scale progress so far; `None` before the
    /// first shot.
    pub fn eta(&self) -> Option<Duration> {
        let done = self.done_fraction();
        if done <= 0.0 || self.shots == 0 {
            return None;
        }
        let secs = self.elapsed.as_secs_f64() * (1.0 - done) / done;
        secs.is_finite().then(|| Duration::from_secs_f64(secs.max(0.0)))
    }
}

/// The worker's published state; cheap to clone.
#[derive(Clone, Debug, PartialEq)]
pub struct Status {
    /// Increments with every job that meshes successfully (0 until the first one does).
    pub generation: u64,
    /// What the worker is doing.
    pub state: WorkerState,
    /// Figures of the current solve (of the last good job while a new one meshes).
    pub progress: Progress,
    /// The last job that failed to mesh or start, one line; cleared by the next good job.
    pub error: Option<String>,
}

/// One published solution with the mesh it belongs to.
#[derive(Debug)]
pub struct Snapshot {
    /// The job generation this solution belongs to (see [`Status::generation`]).
    pub generation: u64,
    /// The mesh the solution is on.
    pub mesh: Arc<Mesh>,
    /// Texture coordinates of the mesh's element corners ([`radiosity_image::element_uvs`]);
    /// empty when the scene has no texture. Shared by every snapshot of the mesh.
    pub element_uvs: Arc<Vec<Option<ElementUvs>>>,
    /// The job that produced it.
    pub job: SolveJob,
    /// Radiosity per element and vertex, linear.
    pub solution: Solution,
    /// Figures when it was taken.
    pub progress: Progress,
}

enum Command {
    Pause,
    Resume,
    Step,
    Restart(Option<Box<SolveJob>>),
    PauseAt(Option<u64>),
}

struct Slot {
    status: Status,
    snapshot: Option<Arc<Snapshot>>,
    /// Bumped at every publication, so waiters can tell news from wake-ups.
    serial: u64,
}

struct Shared {
    slot: Mutex<Slot>,
    changed: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Slot> {
        // A panic on the worker poisons nothing the UI cannot read: the slot is always whole.
        self.slot.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Handle to the solve worker thread. Dropping it stops and joins the thread.
pub struct SolveWorker {
    commands: Option<Sender<Command>>,
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

impl SolveWorker {
    /// Starts a worker on `job`: it meshes the scene, then shoots until a stop criterion,
    /// publishing as it goes.
    ///
    /// # Panics
    /// If the operating system cannot start a thread.
    pub fn spawn(job: SolveJob, options: WorkerOptions) -> Self {
        let shared = Arc::new(Shared {
            slot: Mutex::new(Slot {
                status: Status {
                    generation: 0,
                    state: WorkerState::Meshing,
                    progress: Progress::default(),
                    error: None,
                },
                snapshot: None,
                serial: 0,
            }),
            changed: Condvar::new(),
        });
        let (tx, rx) = channel();
        let worker_shared = shared.clone();
        let thread = std::thread::Builder::new()
            .name("radiosity-solve".into())
            .spawn(move || {
                Worker::new(job, options, rx, worker_shared.clone()).run();
                let mut slot = worker_shared.lock();
                slot.status.state = WorkerState::Ended;
                slot.serial += 1;
                worker_shared.changed.notify_all();
            })
            .expect("cannot start the solve thread");
        Self { commands: Some(tx), shared, thread: Some(thread) }
    }

    fn send(&self, c: Command) {
        // The worker only goes away when this handle drops; if it died of a panic, commands
        // have nobody to reach and the state already says `Ended`.
        if let Some(tx) = &self.commands {
            let _ = tx.send(c);
        }
    }

    /// Stops shooting after the current shot.
    pub fn pause(&self) {
        self.send(Command::Pause);
    }

    /// Goes on shooting.
    pub fn resume(&self) {
        self.send(Command::Resume);
    }

    /// Shoots exactly one more shot, then stays paused.
    pub fn step_one(&self) {
        self.send(Command::Step);
    }

    /// Starts over: with `job`, or with the current job when `None` (reusing its mesh).
    /// Keeps the paused/running state.
    pub fn restart(&self, job: Option<SolveJob>) {
        self.send(Command::Restart(job.map(Box::new)));
    }

    /// Pauses by itself once this many shots are done (`None`: never).
    pub fn set_pause_at_shots(&self, shots: Option<u64>) {
        self.send(Command::PauseAt(shots));
    }

    /// The newest status.
    pub fn status(&self) -> Status {
        self.shared.lock().status.clone()
    }

    /// The newest solution, if a job has meshed.
    pub fn latest(&self) -> Option<Arc<Snapshot>> {
        self.shared.lock().snapshot.clone()
    }

    /// Blocks until `done(status)` holds or `timeout` passes; returns the last status seen
    /// and whether it held. For tests and scripted runs; the window never waits.
    pub fn wait_for(&self, timeout: Duration, done: impl Fn(&Status) -> bool) -> (Status, bool) {
        let deadline = Instant::now() + timeout;
        let mut slot = self.shared.lock();
        loop {
            if done(&slot.status) {
                return (slot.status.clone(), true);
            }
            let now = Instant::now();
            if now >= deadline || slot.status.state == WorkerState::Ended {
                return (slot.status.clone(), false);
            }
            slot =
                self.shared.changed.wait_timeout(slot, deadline - now).unwrap_or_else(|e| e.into_inner()).0;
        }
    }
}

impl Drop for SolveWorker {
    fn drop(&mut self) {
        // Closing the channel is the shutdown signal: a blocked worker wakes with an error,
        // a shooting one sees it between shots.
        self.commands = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Texture coordinates of a mesh's element corners, shared by its snapshots.
type SharedUvs = Arc<Vec<Option<ElementUvs>>>;

/// A job that meshed, with its solver.
struct Run {
    job: SolveJob,
    problem: Problem,
    /// Texture coordinates of the problem's mesh, found once per mesh: a ray per element.
    element_uvs: SharedUvs,
    solver: Solver,
}

struct Worker {
    rx: Receiver<Command>,
    shared: Arc<Shared>,
    notify: Option<Arc<dyn Fn() + Send + Sync>>,
    pool: Option<rayon::ThreadPool>,
    run: Option<Run>,
    generation: u64,
    paused: bool,
    pause_at: Option<u64>,
    pending_job: Option<SolveJob>,
    pending_steps: u64,
    error: Option<String>,
    shutdown: bool,
}

impl Worker {
    fn new(job: SolveJob, o: WorkerOptions, rx: Receiver<Command>, shared: Arc<Shared>) -> Self {
        let threads = o.threads.unwrap_or_else(|| {
            std::thread::available_parallelism().map_or(1, |n| n.get().saturating_sub(1).max(1))
        });
        // A pool of our own keeps the window's core free and leaves the process-wide pool
        // alone; if it cannot be built, the global pool does the work.
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .thread_name(|i| format!("radiosity-solve-{i}"))
            .build()
            .ok();
        Self {
            rx,
            shared,
            notify: o.notify,
            pool,
            run: None,
            generation: 0,
            paused: o.start_paused,
            pause_at: o.pause_at_shots,
            pending_job: Some(job),
            pending_steps: 0,
            error: None,
            shutdown: false,
        }
    }

    fn in_pool<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        match &self.pool {
            Some(p) => p.install(f),
            None => f(),
        }
    }

    fn apply(&mut self, c: Command) {
        match c {
            Command::Pause => self.paused = true,
            Command::Resume => {
                self.paused = false;
                self.pending_steps = 0;
            }
            Command::Step => {
                self.paused = true;
                self.pending_steps += 1;
            }
            Command::Restart(job) => {
                self.pending_job = match job {
                    Some(j) => Some(*j),
                    None => self.pending_job.take().or_else(|| self.run.as_ref().map(|r| r.job.clone())),
                };
                self.pending_steps = 0;
            }
            Command::PauseAt(n) => self.pause_at = n,
        }
    }

    fn stopped(&self) -> bool {
        self.run.as_ref().is_none_or(|r| r.solver.stop_reason().is_some())
    }

    fn at_pause_mark(&self) -> bool {
        match (self.pause_at, &self.run) {
            (Some(n), Some(r)) => r.solver.shots() >= n,
            _ => false,
        }
    }

    fn wants_to_shoot(&self) -> bool {
        !self.stopped() && (self.pending_steps > 0 || (!self.paused && !self.at_pause_mark()))
    }

    fn run(mut self) {
        loop {
            // Block when there is nothing to do; otherwise only look at what has arrived.
            if self.pending_job.is_none() && !self.wants_to_shoot() {
                match self.rx.recv() {
                    Ok(c) => self.apply(c),
                    Err(_) => self.shutdown = true,
                }
            }
            loop {
                match self.rx.try_recv() {
                    Ok(c) => self.apply(c),
                    Err(TryRecvError::Empty) => break,
                    Err(TryRecvError::Disconnected) => {
                        self.shutdown = true;
                        break;
                    }
                }
            }
            if self.shutdown {
                return;
            }
            if let Some(job) = self.pending_job.take() {
                self.start(job);
                continue; // Commands sent while meshing come first.
            }
            if self.wants_to_shoot() {
                self.shoot_slice();
            }
            self.publish();
        }
    }

    fn start(&mut self, job: SolveJob) {
        self.set_state(WorkerState::Meshing);
        let reuse = self
            .run
            .as_ref()
            .filter(|r| r.job.same_mesh(&job))
            .map(|r| (r.problem.clone(), r.element_uvs.clone()));
        let built = match reuse {
            Some(p) => Ok(p),
            None => self.in_pool(|| build_problem(&job)),
        };
        let started = built.and_then(|(problem, element_uvs)| {
            problem
                .solver(job.solver_params.clone())
                .map(|solver| Run { job, problem, element_uvs, solver })
                .map_err(|e| format!("cannot start the solver: {e}"))
        });
        match started {
            Ok(run) => {
                self.run = Some(run);
                self.generation += 1;
                self.error = None;
            }
            // Keep the previous solve: a bad subdivision must not lose the picture.
            Err(e) => self.error = Some(e),
        }
        self.publish();
    }

    fn shoot_slice(&mut self) {
        let start = Instant::now();
        let Some(run) = self.run.as_mut() else { return };
        let pool = self.pool.as_ref();
        let step = |solver: &mut Solver| match pool {
            Some(p) => p.install(|| solver.step(StepBudget::Shots(1))),
            None => solver.step(StepBudget::Shots(1)),
        };
        if self.pending_steps > 0 {
            self.pending_steps -= 1;
            step(&mut run.solver);
            return;
        }
        // One shot at a time so the pause mark is met exactly and a pause or a restart waits
        // for one shot at most; a step's own bookkeeping is tiny next to a shot.
        while start.elapsed() < PUBLISH_INTERVAL && run.solver.stop_reason().is_none() {
            if self.pause_at.is_some_and(|n| run.solver.shots() >= n) {
                break;
            }
            step(&mut run.solver);
        }
    }

    fn state(&self) -> WorkerState {
        if self.pending_job.is_some() {
            return WorkerState::Meshing;
        }
        match &self.run {
            None => WorkerState::Paused,
            Some(r) => match r.solver.stop_reason() {
                Some(s) => WorkerState::Stopped(s),
                None if self.paused || self.at_pause_mark() => WorkerState::Paused,
                None => WorkerState::Running,
            },
        }
    }

    fn set_state(&self, state: WorkerState) {
        let mut slot = self.shared.lock();
        slot.status.state = state;
        slot.serial += 1;
        drop(slot);
        self.shared.changed.notify_all();
        if let Some(n) = &self.notify {
            n();
        }
    }

    fn progress(&self) -> Progress {
        match &self.run {
            None => Progress::default(),
            Some(r) => Progress {
                patches: r.problem.mesh().patches.len(),
                elements: r.problem.mesh().elements.len(),
                shots: r.solver.shots(),
                unshot_fraction: r.solver.unshot_fraction(),
                unshot_threshold: r.job.solver_params.unshot_threshold,
                rays: r.solver.rays(),
                elapsed: r.solver.elapsed(),
            },
        }
    }

    /// Publishes the status, and a new snapshot when the solution changed since the last one.
    fn publish(&self) {
        let status = Status {
            generation: self.generation,
            state: self.state(),
            progress: self.progress(),
            error: self.error.clone(),
        };
        let mut slot = self.shared.lock();
        let stale = match (&slot.snapshot, &self.run) {
            (_, None) => false,
            (None, Some(_)) => true,
            (Some(s), Some(r)) => s.generation != self.generation || s.solution.shots != r.solver.shots(),
        };
        if slot.status == status && !stale {
            return;
        }
        // Take the solution outside the lock: it copies every element and vertex.
        drop(slot);
        let snapshot = match (&self.run, stale) {
            (Some(r), true) => Some(Arc::new(Snapshot {
                generation: self.generation,
                mesh: r.problem.mesh().clone(),
                element_uvs: r.element_uvs.clone(),
                job: r.job.clone(),
                solution: r.solver.solution(),
                progress: status.progress.clone(),
            })),
            _ => None,
        };
        slot = self.shared.lock();
        slot.status = status;
        if snapshot.is_some() {
            slot.snapshot = snapshot;
        }
        slot.serial += 1;
        drop(slot);
        self.shared.changed.notify_all();
        if let Some(n) = &self.notify {
            n();
        }
    }
}

/// Meshes the job's scene (light scale applied) and builds its ray-query structure; finds the
/// texture coordinates of the mesh's elements here too, off the window's thread.
fn build_problem(job: &SolveJob) -> Result<(Problem, SharedUvs), String> {
    let mut scene = (*job.scene).clone();
    scene.scale_emission(job.light_scale);
    let problem =
        Problem::new(&scene, &job.mesh_params).map_err(|e| format!("cannot mesh the scene: {e}"))?;
    let element_uvs = Arc::new(radiosity_image::element_uvs(&scene, problem.mesh()));
    Ok((problem, element_uvs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_scenes::furnace_box;

    const LONG: Duration = Duration::from_secs(60);

    fn job(patch: f64) -> SolveJob {
        let scene = Arc::new(furnace_box(0.5, 1.0));
        SolveJob {
            label: "furnace".into(),
            scene,
            light_scale: 1.0,
            mesh_params: MeshParams::try_new(patch, patch / 2.0).unwrap(),
            // Tight threshold and no kept rows (a kept row makes a shot take microseconds),
            // so the solve outlasts the test unless something stops it.
            solver_params: SolverParams {
                unshot_threshold: 1e-12,
                row_cache_bytes: Some(0),
                ..SolverParams::preview()
            },
        }
    }

    fn options() -> WorkerOptions {
        WorkerOptions { threads: Some(1), ..WorkerOptions::default() }
    }

    #[test]
    fn runs_and_publishes_a_growing_solution() {
        let w = SolveWorker::spawn(job(0.25), options());
        let (s, ok) = w.wait_for(LONG, |s| s.progress.shots >= 20);
        assert!(ok, "no progress: {s:?}");
        let snap = w.latest().expect("a snapshot");
        assert_eq!(snap.generation, 1);
        assert_eq!(snap.solution.vertex_radiosity.len(), snap.mesh.positions.len());
        assert!(snap.solution.shots > 0);
    }

    #[test]
    fn pausing_stops_shots_and_resume_goes_on() {
        let w = SolveWorker::spawn(job(0.25), options());
        assert!(w.wait_for(LONG, |s| s.progress.shots >= 5).1);
        w.pause();
        let (s, ok) = w.wait_for(LONG, |s| s.state == WorkerState::Paused);
        assert!(ok, "{s:?}");
        let shots = s.progress.shots;
        std::thread::sleep(Duration::from_millis(300));
        assert_eq!(w.status().progress.shots, shots, "a paused worker shoots no more");
        w.step_one();
        let (s, ok) = w.wait_for(LONG, |s| s.progress.shots == shots + 1 && s.state == WorkerState::Paused);
        assert!(ok, "step shoots exactly one: {s:?}");
        std::thread::sleep(Duration::from_millis(200));
        assert_eq!(w.status().progress.shots, shots + 1);
        w.resume();
        assert!(w.wait_for(LONG, |s| s.progress.shots > shots + 5).1);
    }

    #[test]
    fn restart_resets_and_new_job_remeshes() {
        let w = SolveWorker::spawn(job(0.25), options());
        assert!(w.wait_for(LONG, |s| s.progress.shots >= 30).1);
        let elements = w.status().progress.elements;
        w.pause();
        w.restart(None);
        let (s, ok) = w.wait_for(LONG, |s| s.generation == 2 && s.state == WorkerState::Paused);
        assert!(ok, "{s:?}");
        assert_eq!(s.progress.shots, 0, "restart starts from no shots");
        assert_eq!(s.progress.elements, elements, "same job, same mesh");
        let snap = w.latest().unwrap();
        assert_eq!((snap.generation, snap.solution.shots), (2, 0));
        w.restart(Some(job(0.5)));
        let (s, ok) = w.wait_for(LONG, |s| s.generation == 3);
        assert!(ok, "{s:?}");
        assert!(s.progress.elements < elements, "coarser subdivision, fewer elements");
        assert_eq!(s.state, WorkerState::Paused, "restart keeps the paused state");
    }

    #[test]
    fn a_job_that_cannot_mesh_keeps_the_old_solve() {
        let w = SolveWorker::spawn(job(0.25), options());
        assert!(w.wait_for(LONG, |s| s.generation == 1).1);
        let mut bad = job(0.25);
        bad.mesh_params = MeshParams::try_new(1e-6, 1e-6).unwrap();
        w.restart(Some(bad));
        let (s, ok) = w.wait_for(LONG, |s| s.error.is_some());
        assert!(ok, "{s:?}");
        assert!(s.error.as_deref().unwrap().contains("mesh"), "{s:?}");
        assert_eq!(s.generation, 1);
        let shots = s.progress.shots;
        assert!(w.wait_for(LONG, |s| s.progress.shots > shots).1, "the old solve goes on");
    }

    #[test]
    fn pause_mark_stops_at_exactly_n_shots() {
        let w = SolveWorker::spawn(job(0.25), WorkerOptions { pause_at_shots: Some(7), ..options() });
        let (s, ok) = w.wait_for(LONG, |s| s.state == WorkerState::Paused && s.progress.shots > 0);
        assert!(ok, "{s:?}");
        assert_eq!(s.progress.shots, 7);
        assert_eq!(w.latest().unwrap().solution.shots, 7, "the snapshot shows the mark");
    }

    #[test]
    fn stop_criterion_ends_shooting() {
        let mut j = job(0.5);
        j.solver_params.max_shots = Some(3);
        let w = SolveWorker::spawn(j, options());
        let (s, ok) = w.wait_for(LONG, |s| matches!(s.state, WorkerState::Stopped(_)));
        assert!(ok, "{s:?}");
        assert_eq!(s.state, WorkerState::Stopped(StopReason::ShotLimit));
        assert_eq!(s.progress.shots, 3);
    }

    #[test]
    fn dropping_the_handle_ends_the_worker_promptly() {
        for paused in [false, true] {
            let w = SolveWorker::spawn(job(0.25), WorkerOptions { start_paused: paused, ..options() });
            assert!(w.wait_for(LONG, |s| s.generation == 1).1);
            let (tx, rx) = channel();
            std::thread::spawn(move || {
                drop(w);
                let _ = tx.send(());
            });
            rx.recv_timeout(Duration::from_secs(20)).expect("dropping the handle must join the worker");
        }
    }

    /// Many threads' worth of rapid, contradictory commands: the worker neither deadlocks nor
    /// loses track, ends on the newest job, and still shuts down.
    #[test]
    fn stress_rapid_parameter_changes() {
        let notified = Arc::new(std::sync::atomic::AtomicU64::new(0));
        let n2 = notified.clone();
        let w = SolveWorker::spawn(
            job(0.25),
            WorkerOptions {
                notify: Some(Arc::new(move || {
                    n2.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                })),
                ..options()
            },
        );
        let sizes = [0.25, 0.5, 1.0 / 3.0, 0.2];
        for i in 0..2000 {
            match i % 7 {
                0 => w.pause(),
                1 => w.resume(),
                2 => w.step_one(),
                3 => w.restart(None),
                4 => w.restart(Some(job(sizes[i % sizes.len()]))),
                5 => w.set_pause_at_shots(if i % 2 == 0 { Some(1000) } else { None }),
                _ => {
                    let _ = w.status();
                    let _ = w.latest();
                }
            }
        }
        // The last command of each kind decides: running the newest job, no pause mark.
        let last = job(0.2);
        let elements = Mesh::build(&last.scene, &last.mesh_params).unwrap().elements.len();
        w.set_pause_at_shots(None);
        w.restart(Some(last));
        w.resume();
        let (s, ok) = w.wait_for(LONG, |s| {
            s.state == WorkerState::Running && s.progress.elements == elements && s.progress.shots > 3
        });
        assert!(ok, "{s:?}");
        assert!(notified.load(std::sync::atomic::Ordering::Relaxed) > 0);
        let snap = w.latest().unwrap();
        assert_eq!(snap.mesh.elements.len(), elements);
        assert_eq!(snap.solution.element_radiosity.len(), elements);
        drop(w);
    }
}
