//! Progress on stderr for every step that can take more than a few seconds (loading,
//! meshing, solving, rendering, the reference, baking, writing): what it is doing, how far it
//! is and, where the step knows its length, an ETA. A long step that says nothing looks like a
//! hang.
//!
//! On a terminal it is one line redrawn in place (indicatif), ticking even while the step
//! reports nothing. Without one (a log file, a CI job) a redrawn line would be noise, so a
//! line is printed every [`LOG_INTERVAL`] instead, by a timer thread, so that steps without
//! progress callbacks (meshing, a glTF being encoded) are not silent either. `--quiet` turns
//! both off. Progress only reads the step's state: it never changes a result.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// Seconds between progress lines when stderr is not a terminal: often enough that no step is
/// silent for more than this, seldom enough for a log.
pub const LOG_INTERVAL: Duration = Duration::from_secs(5);

/// The interval in use, milliseconds: [`LOG_INTERVAL`] unless a test set another.
static INTERVAL_MS: AtomicU64 = AtomicU64::new(5000);

/// Sets the interval between log lines (the hidden `--progress-interval`, so that tests see
/// lines without waiting seconds).
pub fn set_log_interval(interval: Duration) {
    INTERVAL_MS.store(interval.as_millis().clamp(1, u128::from(u64::MAX)) as u64, Ordering::Relaxed);
}

/// How often the terminal line is redrawn while a step reports nothing.
const TICK: Duration = Duration::from_millis(120);

/// Set by `--quiet`: no progress at all (results, notes and warnings still print).
static QUIET: AtomicBool = AtomicBool::new(false);

/// Silences (or restores) every progress display of this process.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Where a step stands, shared with the timer thread.
#[derive(Default)]
struct State {
    /// Steps done and planned (`len` 0: unknown).
    pos: u64,
    len: u64,
    /// What the step says about itself (rates, counts, ETA).
    message: String,
}

/// What the timer thread of a log (non-terminal) display reads.
struct Shared {
    what: String,
    /// The units counted (`rows`), empty when the count means nothing to a reader.
    unit: String,
    start: Instant,
    state: Mutex<State>,
    /// Set when the step ends; the condition variable wakes the timer at once.
    ended: Mutex<bool>,
    wake: Condvar,
}

impl Shared {
    /// The log line: `[12 s] rendering: 40/100 rows, message`.
    fn line(&self) -> String {
        let secs = self.start.elapsed().as_secs_f64();
        let state = self.state.lock().map(|s| (s.pos, s.len, s.message.clone()));
        let (pos, len, message) = state.unwrap_or_default();
        let mut line = format!("[{secs:.0} s] {}", self.what);
        let mut parts = Vec::new();
        if len > 0 && !self.unit.is_empty() {
            parts.push(format!("{pos}/{len} {}", self.unit));
        }
        if !message.is_empty() {
            parts.push(message);
        }
        if !parts.is_empty() {
            line += ": ";
            line += &parts.join(", ");
        } else {
            line += "…";
        }
        line
    }
}

/// The progress display of one step; it ends (and clears its line) when dropped.
pub struct Progress {
    bar: ProgressBar,
    shared: Arc<Shared>,
    timer: Option<JoinHandle<()>>,
}

impl Progress {
    /// A step of `len` units (rows, paths, …; 0: unknown) doing `what`; `unit` names the
    /// units on the terminal line (`rows`), empty for none.
    pub fn bar(what: &str, len: u64, unit: &str) -> Self {
        let template = if unit.is_empty() {
            format!("{{spinner}} {what} [{{bar:30}}] {{msg}}")
        } else {
            format!("{{spinner}} {what} [{{bar:30}}] {{pos}}/{{len}} {unit}, ETA {{eta}} {{msg}}")
        };
        Self::start(what, len, unit, &template)
    }

    /// A step whose length is unknown (loading, meshing, writing a file): a spinner and the
    /// time it has taken.
    pub fn spinner(what: &str) -> Self {
        Self::start(what, 0, "", &format!("{{spinner}} {what}… {{elapsed}} {{msg}}"))
    }

    fn start(what: &str, len: u64, unit: &str, template: &str) -> Self {
        let shared = Arc::new(Shared {
            what: what.to_owned(),
            unit: unit.to_owned(),
            start: Instant::now(),
            state: Mutex::new(State { len, ..State::default() }),
            ended: Mutex::new(false),
            wake: Condvar::new(),
        });
        if QUIET.load(Ordering::Relaxed) {
            return Self { bar: ProgressBar::hidden(), shared, timer: None };
        }
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new(len.max(1));
            bar.set_style(
                ProgressStyle::with_template(template).expect("valid template").progress_chars("=> "),
            );
            bar.enable_steady_tick(TICK);
            return Self { bar, shared, timer: None };
        }
        let timer_shared = shared.clone();
        let interval = Duration::from_millis(INTERVAL_MS.load(Ordering::Relaxed));
        let timer = std::thread::spawn(move || {
            let s = timer_shared;
            let Ok(mut ended) = s.ended.lock() else { return };
            // Checked before every wait: the step may have ended before this thread ran, and
            // a wake-up sent then is not kept.
            while !*ended {
                let wait = interval.saturating_sub(crate::output::since_last_line());
                if wait.is_zero() {
                    // Best effort: a stderr that cannot be written is reported by the
                    // step's own summary line, on the main thread. The note marks the time.
                    let _ = crate::output::note(s.line());
                    continue;
                }
                let Ok((guard, _)) = s.wake.wait_timeout(ended, wait) else { return };
                ended = guard;
            }
        });
        Self { bar: ProgressBar::hidden(), shared, timer: Some(timer) }
    }

    /// Sets how far the step is, of how many (0: unknown), and its message. Cheap, and
    /// callable from any thread.
    pub fn set(&self, pos: u64, len: u64, message: impl Into<String>) {
        let message = message.into();
        if len > 0 {
            self.bar.set_length(len);
        }
        self.bar.set_position(pos);
        self.bar.set_message(message.clone());
        if self.timer.is_some()
            && let Ok(mut s) = self.shared.state.lock()
        {
            *s = State { pos, len, message };
        }
    }

    /// One more unit done (from any thread).
    pub fn inc(&self) {
        self.bar.inc(1);
        if self.timer.is_some()
            && let Ok(mut s) = self.shared.state.lock()
        {
            s.pos += 1;
        }
    }

    /// Time since the step started.
    pub fn elapsed(&self) -> Duration {
        self.shared.start.elapsed()
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
        if let Some(timer) = self.timer.take() {
            if let Ok(mut ended) = self.shared.ended.lock() {
                *ended = true;
            }
            self.shared.wake.notify_all();
            let _ = timer.join();
        }
    }
}

/// Runs `f` with a [`Progress::spinner`] saying `what` meanwhile.
pub fn spinning<T>(what: &str, f: impl FnOnce() -> T) -> T {
    let _progress = Progress::spinner(what);
    f()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The log line says what, how far and the message, or only what when nothing is known.
    #[test]
    fn log_lines_say_what_and_how_far() {
        let p = Progress::spinner("meshing");
        assert!(p.shared.line().ends_with("] meshing…"), "{}", p.shared.line());
        let shared = Shared {
            what: "reference".into(),
            unit: "rows".into(),
            start: Instant::now(),
            state: Mutex::new(State { pos: 3, len: 10, message: "1.2 M paths/s".into() }),
            ended: Mutex::new(false),
            wake: Condvar::new(),
        };
        assert_eq!(shared.line(), "[0 s] reference: 3/10 rows, 1.2 M paths/s");
    }
}
