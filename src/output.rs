//! Every file, folder and stream a command writes goes through here, so that nothing is lost
//! and nothing is reported written that was not.
//!
//! - Targets are checked **before** the solve ([`Targets`]): the folder exists and takes a new
//!   file, an existing target is a regular file and `--force` was given, and no two outputs of
//!   one run name the same file.
//! - A file is written to a temporary file in its target folder, flushed and synced to disk,
//!   then renamed into place ([`write_file`]). A crash, a signal or a full disk leaves the old
//!   file whole (at worst a hidden `.name.*.tmp` file beside it). Without `--force`, the rename
//!   refuses to replace a file that appeared during the run (link-then-unlink, the
//!   `tempfile` crate's `persist_noclobber`).
//! - A folder of files (lightmaps) is written into a temporary folder first and moved
//!   ([`write_folder`]).
//! - Text for stdout and messages for stderr are written with their errors handled
//!   ([`stdout`], [`note`]): a reader that closed the pipe ends the run quietly with the
//!   shell's status for SIGPIPE (141), any other failure (a full disk) is an error.

use std::collections::HashSet;
use std::ffi::OsString;
use std::fs::File;
use std::io::{BufWriter, ErrorKind, Write};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow};

use crate::errors::InputError;

/// Exit status for a closed output pipe: 128 + SIGPIPE (13), what a shell reports for a
/// process the signal ended, and what `head`-style pipelines expect.
pub const BROKEN_PIPE_EXIT: u8 = 141;

/// The folder a file path lives in (`.` for a bare name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
}

/// The output targets of one run, checked before any work is done.
pub struct Targets {
    force: bool,
    /// Canonical folder + file name of each target, to find two outputs naming one file.
    seen: HashSet<PathBuf>,
}

impl Targets {
    /// No targets yet; `force` allows replacing existing files.
    pub fn new(force: bool) -> Self {
        Self { force, seen: HashSet::new() }
    }

    /// The canonical identity of `path` (its folder resolved, its name as given).
    fn identity(path: &Path, option: &str) -> Result<PathBuf> {
        let name =
            path.file_name().ok_or_else(|| input(format!("{option} {}: not a file name", path.display())))?;
        let folder = folder_of(path);
        let meta = std::fs::metadata(folder).map_err(|e| {
            input(format!("{option} {}: the folder {} cannot be used: {e}", path.display(), folder.display()))
        })?;
        if !meta.is_dir() {
            return Err(input(format!("{option} {}: {} is not a folder", path.display(), folder.display())));
        }
        let folder = folder.canonicalize().with_context(|| format!("{}", folder.display()))?;
        Ok(folder.join(name))
    }

    fn remember(&mut self, id: PathBuf, path: &Path, option: &str) -> Result<()> {
        if !self.seen.insert(id) {
            return Err(input(format!(
                "{option} {}: another output of this run is the same file",
                path.display()
            )));
        }
        Ok(())
    }

    /// Checks that `path` (given as `option`) can be written at the end of the run: its folder
    /// exists and takes a new file, it is not an existing file without `--force` nor anything
    /// but a regular file, and no other target of this run is the same file. An existing
    /// character device or named pipe (`/dev/null`, `/dev/stdout`, a FIFO) is taken as it
    /// is: writing to it replaces nothing.
    ///
    /// # Errors
    /// Each problem as an [`InputError`] naming the option and the path (exit code 2).
    pub fn file(&mut self, path: &Path, option: &str) -> Result<()> {
        if is_stream(path) {
            // /dev/null, a terminal, a named pipe: written straight through, nothing stored
            // is replaced (see `write_file`).
            return Ok(());
        }
        let id = Self::identity(path, option)?;
        match std::fs::metadata(path) {
            Ok(meta) if !meta.is_file() => {
                return Err(input(format!(
                    "{option} {}: exists and is not a regular file; give a file name",
                    path.display()
                )));
            }
            Ok(_) if !self.force => {
                return Err(input(format!("{} exists; pass --force to overwrite it", path.display())));
            }
            _ => {}
        }
        // The only sure test that the folder takes a new file is to make one.
        tempfile::Builder::new().prefix(".radiosity-check").tempfile_in(folder_of(path)).map_err(|e| {
            input(format!(
                "{option} {}: cannot write into {}: {e}",
                path.display(),
                folder_of(path).display()
            ))
        })?;
        self.remember(id, path, option)
    }

    /// Checks a folder target (created if missing, with any missing folders above it, as
    /// `mkdir -p` does: the nearest existing one must be a folder that takes new files):
    /// `marker` is the file in it that says an earlier run wrote there, which needs `--force`.
    ///
    /// # Errors
    /// As [`Targets::file`].
    pub fn folder(&mut self, dir: &Path, marker: &str, option: &str) -> Result<()> {
        match std::fs::metadata(dir) {
            Ok(meta) if !meta.is_dir() => {
                Err(input(format!("{option} {}: exists and is not a folder", dir.display())))
            }
            Ok(_) => {
                if dir.join(marker).exists() && !self.force {
                    return Err(input(format!(
                        "{} already holds {marker}; pass --force to overwrite it",
                        dir.display()
                    )));
                }
                tempfile::Builder::new()
                    .prefix(".radiosity-check")
                    .tempfile_in(dir)
                    .map_err(|e| input(format!("{option} {}: cannot write into it: {e}", dir.display())))?;
                let id = dir.canonicalize().with_context(|| format!("{}", dir.display()))?;
                self.remember(id, dir, option)
            }
            Err(_) => {
                // Missing: it and the missing folders above it are made at the end, in the
                // nearest folder that exists, so that is what must take new files. Making
                // folders replaces nothing.
                let mut existing = folder_of(dir);
                while std::fs::symlink_metadata(existing).is_err() {
                    match existing.parent() {
                        Some(p) if !p.as_os_str().is_empty() => existing = p,
                        _ => {
                            existing = Path::new(".");
                            break;
                        }
                    }
                }
                if !std::fs::metadata(existing).is_ok_and(|m| m.is_dir()) {
                    return Err(input(format!(
                        "{option} {}: {} is not a folder",
                        dir.display(),
                        existing.display()
                    )));
                }
                tempfile::Builder::new().prefix(".radiosity-check").tempfile_in(existing).map_err(|e| {
                    input(format!(
                        "{option} {}: cannot write into {}: {e}",
                        dir.display(),
                        existing.display()
                    ))
                })?;
                let id = existing
                    .canonicalize()
                    .with_context(|| format!("{}", existing.display()))?
                    .join(dir.strip_prefix(existing).unwrap_or(dir));
                self.remember(id, dir, option)
            }
        }
    }
}

/// Whether `path` is an existing character device or named pipe: a stream to write into,
/// not a file to replace (`/dev/null` to discard a report).
fn is_stream(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::metadata(path).is_ok_and(|m| m.file_type().is_char_device() || m.file_type().is_fifo())
}

/// Writes `bytes` to `path` atomically (see the module doc). Without `force`, a file that
/// appeared at `path` during the run is kept and the run fails.
///
/// # Errors
/// The temporary file cannot be made, written or synced (full disk, permissions), or the
/// rename fails or would replace a file without `force`.
pub fn write_file(path: &Path, force: bool, bytes: &[u8]) -> Result<()> {
    if is_stream(path) {
        let mut out = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        return out.write_all(bytes).with_context(|| format!("cannot write {}", path.display()));
    }
    let folder = folder_of(path);
    let mut prefix = OsString::from(".");
    prefix.push(path.file_name().unwrap_or_default());
    prefix.push(".");
    let tmp =
        tempfile::Builder::new().prefix(&prefix).suffix(".tmp").tempfile_in(folder).with_context(|| {
            format!("cannot write {}: cannot make a file in {}", path.display(), folder.display())
        })?;
    let mut out = BufWriter::with_capacity(1 << 20, tmp);
    out.write_all(bytes).with_context(|| format!("cannot write {}", path.display()))?;
    let tmp = out.into_inner().map_err(|e| anyhow!("cannot write {}: {}", path.display(), e.error()))?;
    tmp.as_file().sync_all().with_context(|| format!("cannot write {}", path.display()))?;
    let persisted = if force { tmp.persist(path) } else { tmp.persist_noclobber(path) };
    match persisted {
        Ok(_) => Ok(()),
        Err(e) if e.error.kind() == ErrorKind::AlreadyExists => Err(input(format!(
            "{} appeared during the run and was kept; pass --force to overwrite it",
            path.display()
        ))),
        Err(e) => Err(anyhow!("cannot write {}: {}", path.display(), e.error)),
    }
}

/// Writes a folder of files: `fill` writes into a fresh temporary folder, whose files are
/// then moved into `dir` (made if missing, with the folders above it) one rename each. Without `force`, a file of the
/// same name that appeared meanwhile is kept and the run fails. Returns how many files moved.
///
/// # Errors
/// `fill`'s error, or a file that cannot be moved.
pub fn write_folder(
    dir: &Path,
    force: bool,
    fill: impl FnOnce(&Path) -> std::result::Result<Vec<PathBuf>, String>,
) -> Result<usize> {
    let parent = folder_of(dir);
    // The folders above it that were missing when the run was checked (`Targets::folder`).
    std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
    let staging =
        tempfile::Builder::new().prefix(".radiosity-staging").tempdir_in(parent).with_context(|| {
            format!("cannot write {}: cannot make a folder in {}", dir.display(), parent.display())
        })?;
    let written = fill(staging.path()).map_err(|e| anyhow!("cannot write {}: {e}", dir.display()))?;
    for path in &written {
        File::open(path)
            .and_then(|f| f.sync_all())
            .with_context(|| format!("cannot sync {}", path.display()))?;
    }
    if std::fs::metadata(dir).is_err() {
        // A rename of the whole folder: it appears complete or not at all.
        if std::fs::rename(staging.path(), dir).is_ok() {
            return Ok(written.len());
        }
        std::fs::create_dir(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    for path in &written {
        let target = dir.join(path.file_name().unwrap_or_default());
        let moved = if force {
            std::fs::rename(path, &target)
        } else {
            // A hard link fails when the name is taken: the no-clobber rename.
            std::fs::hard_link(path, &target).and_then(|()| std::fs::remove_file(path))
        };
        moved.map_err(|e| {
            if e.kind() == ErrorKind::AlreadyExists {
                input(format!(
                    "{} appeared during the run and was kept; pass --force to overwrite it",
                    target.display()
                ))
            } else {
                anyhow!("cannot write {}: {e}", target.display())
            }
        })?;
    }
    Ok(written.len())
}

/// An error for a failed write to a standard stream; a closed pipe is kept recognisable
/// ([`is_broken_pipe`]).
fn stream_error(e: std::io::Error, stream: &str) -> anyhow::Error {
    anyhow::Error::new(e).context(format!("cannot write to {stream}"))
}

/// Writes a report `text` to `path` as [`write_file`] does, or to stdout when `path` is `-`.
///
/// # Errors
/// As [`write_file`] and [`stdout`].
pub fn write_report(path: &str, force: bool, text: &str) -> Result<()> {
    let text = if text.ends_with('\n') { text.to_owned() } else { format!("{text}\n") };
    if path == "-" { stdout(&text) } else { write_file(Path::new(path), force, text.as_bytes()) }
}

/// A solve's power audit for the JSON reports, W per channel: where the emitted power went
/// (absorbed, escaped, still unshot) and what the solve made on top (`created`), with the
/// round-off `residual` of emitted + created − absorbed − unshot − escaped over emitted.
pub fn energy_json(e: &radiosity_solver::EnergyBalance) -> serde_json::Value {
    serde_json::json!({
        "emitted": e.emitted.to_array(),
        "absorbed": e.absorbed.to_array(),
        "escaped": e.escaped.to_array(),
        "unshot": e.unshot.to_array(),
        "created": e.created.to_array(),
        "created_fraction": e.created.sum() / e.emitted.sum(),
        "residual": e.residual().to_array(),
    })
}

/// When the last line went to stderr, milliseconds after [`epoch`]: a step's timer waits a
/// whole interval after it, whoever printed it, so a chain of short steps (loading, meshing,
/// then the first seconds of a solve) is never silent for longer than one interval.
static LAST_LINE_MS: AtomicU64 = AtomicU64::new(0);

/// The process's clock origin for [`LAST_LINE_MS`].
fn epoch() -> Instant {
    static EPOCH: OnceLock<Instant> = OnceLock::new();
    *EPOCH.get_or_init(Instant::now)
}

/// Starts the clock that silences are measured on: the start of the process counts as the
/// last line until one is printed.
pub fn start_clock() {
    epoch();
}

/// Notes that a line went to stderr now ([`note`] calls it).
pub fn line_printed() {
    LAST_LINE_MS.store(epoch().elapsed().as_millis() as u64, Ordering::Relaxed);
}

/// Time since the last line went to stderr (since the start, before any).
pub fn since_last_line() -> Duration {
    epoch().elapsed().saturating_sub(Duration::from_millis(LAST_LINE_MS.load(Ordering::Relaxed)))
}

/// Writes `text` to stdout and flushes it.
///
/// # Errors
/// The write fails (a closed pipe: see [`is_broken_pipe`]).
pub fn stdout(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes()).and_then(|()| out.flush()).map_err(|e| stream_error(e, "stdout"))
}

/// Writes one message line to stderr.
///
/// # Errors
/// The write fails (a closed pipe: see [`is_broken_pipe`]).
pub fn note(line: impl std::fmt::Display) -> Result<()> {
    line_printed();
    let mut err = std::io::stderr().lock();
    writeln!(err, "{line}").and_then(|()| err.flush()).map_err(|e| stream_error(e, "stderr"))
}

/// Whether `e` comes from writing to a pipe whose reader has gone.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == ErrorKind::BrokenPipe))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_that_appeared_meanwhile_is_kept_without_force() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.json");
        Targets::new(false).file(&path, "--json").unwrap();
        // Another run writes the file while this one solves.
        std::fs::write(&path, "theirs").unwrap();
        let e = write_file(&path, false, b"ours").unwrap_err();
        assert!(e.to_string().contains("appeared during the run"), "{e}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "theirs");
        write_file(&path, true, b"ours").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "ours");
        // No temporary file is left behind either way.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn two_outputs_naming_one_file_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let mut targets = Targets::new(true);
        targets.file(&dir.path().join("a.png"), "-o").unwrap();
        let e = targets.file(&dir.path().join("./a.png"), "--exr").unwrap_err();
        assert!(e.to_string().contains("same file"), "{e}");
        targets.file(&dir.path().join("b.png"), "--pfm").unwrap();
    }

    #[test]
    fn missing_folders_and_non_files_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let e = Targets::new(true).file(&dir.path().join("no/x.png"), "-o").unwrap_err();
        assert!(e.to_string().contains("cannot be used"), "{e}");
        let e = Targets::new(true).file(dir.path(), "-o").unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        assert!(e.is::<InputError>());
    }

    /// `/dev/null` takes a report with or without `--force`, twice in one run too: it is a
    /// stream, not a file that could be replaced.
    #[test]
    fn dev_null_takes_a_report() {
        let null = Path::new("/dev/null");
        let mut targets = Targets::new(false);
        targets.file(null, "--json").unwrap();
        targets.file(null, "-o").unwrap();
        write_file(null, false, b"{}\n").unwrap();
        write_file(null, true, b"{}\n").unwrap();
    }

    #[test]
    fn a_folder_is_written_whole_and_kept_without_force() {
        let dir = tempfile::tempdir().unwrap();
        let maps = dir.path().join("maps");
        let fill = |staging: &Path| {
            let a = staging.join("a.exr");
            std::fs::write(&a, "new").map_err(|e| e.to_string())?;
            Ok(vec![a])
        };
        Targets::new(false).folder(&maps, "a.exr", "--lightmap").unwrap();
        assert_eq!(write_folder(&maps, false, fill).unwrap(), 1);
        assert_eq!(std::fs::read_to_string(maps.join("a.exr")).unwrap(), "new");
        // A second run without --force is refused before it starts ...
        assert!(Targets::new(false).folder(&maps, "a.exr", "--lightmap").is_err());
        // ... and a file that appeared meanwhile is kept.
        std::fs::write(maps.join("a.exr"), "theirs").unwrap();
        assert!(write_folder(&maps, false, fill).is_err());
        assert_eq!(std::fs::read_to_string(maps.join("a.exr")).unwrap(), "theirs");
        assert_eq!(write_folder(&maps, true, fill).unwrap(), 1);
        assert_eq!(std::fs::read_to_string(maps.join("a.exr")).unwrap(), "new");
        // Only the folder is left in the parent: no staging folders.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_failed_fill_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let maps = dir.path().join("maps");
        assert!(write_folder(&maps, false, |_| Err("disk full".into())).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
