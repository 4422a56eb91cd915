//! Output files that are never left half-written: everything is written to a temporary file
//! in the destination directory and renamed into place only when complete.
use anyhow::{Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Writes `bytes` to `path` atomically (temporary file + rename in the same directory).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create directory {}", dir.display()))?;
    let mut tmp = tempfile::NamedTempFile::new_in(dir)
        .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
    tmp.write_all(bytes).with_context(|| format!("cannot write {}", path.display()))?;
    tmp.as_file().sync_all().ok();
    tmp.persist(path)
        .map_err(|e| e.error)
        .with_context(|| format!("cannot move the finished file to {}", path.display()))?;
    Ok(())
}

/// Paths removed if the process is interrupted (SIGINT, SIGTERM): staging directories and
/// lock files of the running command.
static CLEANUP: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Registers `path` for removal on interruption.
pub fn register_cleanup(path: &Path) {
    if let Ok(mut v) = CLEANUP.lock() {
        v.push(path.to_path_buf());
    }
}

/// Forgets `path` (finished or removed normally).
pub fn unregister_cleanup(path: &Path) {
    if let Ok(mut v) = CLEANUP.lock() {
        v.retain(|p| p != path);
    }
}

/// Removes every registered path; what the interrupt handler does before exiting.
pub fn cleanup_now() {
    let paths: Vec<PathBuf> = match CLEANUP.lock() {
        Ok(mut v) => std::mem::take(&mut *v),
        Err(_) => return,
    };
    for p in paths {
        if p.is_dir() {
            let _ = std::fs::remove_dir_all(&p);
        } else {
            let _ = std::fs::remove_file(&p);
        }
    }
}

/// Exit status of a run ended by SIGINT or SIGTERM.
pub const INTERRUPTED_EXIT: i32 = 130;

/// Installs the SIGINT / SIGTERM handler: it removes the staging directories and lock files
/// of the running command (nothing half-written is left beside `--out`), prints one line and
/// exits with status 130. Sweep checkpoints inside `--out` stay, so the run resumes.
pub fn install_interrupt_cleanup() {
    let _ = ctrlc::set_handler(|| {
        cleanup_now();
        eprintln!("error: interrupted (SIGINT or SIGTERM); staging directories and locks removed");
        std::process::exit(INTERRUPTED_EXIT);
    });
}

const STAGING_PREFIX: &str = ".moreau-staging-";

/// Whether process `pid` is alive (Linux: `/proc/PID` exists); `None` where unknown.
fn process_alive(pid: u32) -> Option<bool> {
    if !Path::new("/proc/self").exists() {
        return None;
    }
    Some(Path::new(&format!("/proc/{pid}")).exists())
}

/// Removes staging directories in `parent` left by interrupted runs: those named with the
/// id of a process that no longer exists, and unnamed (older format) ones not touched for an
/// hour. Returns how many were removed.
pub fn remove_stale_staging(parent: &Path) -> usize {
    let Ok(rd) = std::fs::read_dir(parent) else { return 0 };
    let me = std::process::id();
    let mut removed = 0;
    for e in rd.flatten() {
        let name = e.file_name();
        let Some(rest) = name.to_str().and_then(|n| n.strip_prefix(STAGING_PREFIX)) else { continue };
        if !e.file_type().map(|t| t.is_dir()).unwrap_or(false) {
            continue;
        }
        let pid = rest.split_once('-').and_then(|(p, _)| p.parse::<u32>().ok());
        let stale = match pid {
            Some(p) if p == me => false,
            Some(p) => process_alive(p) == Some(false),
            None => e
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age.as_secs() > 3600),
        };
        if stale && std::fs::remove_dir_all(e.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// A directory whose files appear all together or not at all: files are written into a
/// hidden staging directory next to `out` (`.moreau-staging-PID-XXXXXX`) and moved into
/// `out` by [`StagedDir::commit`]. Dropping without commit, or an interruption, removes the
/// staging directory; stale ones of interrupted runs are removed when the next one starts.
pub struct StagedDir {
    out: PathBuf,
    stage: Option<tempfile::TempDir>,
}

impl StagedDir {
    pub fn new(out: &Path) -> Result<Self> {
        let parent = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create directory {}", parent.display()))?;
        remove_stale_staging(parent);
        let stage = tempfile::Builder::new()
            .prefix(&format!("{STAGING_PREFIX}{}-", std::process::id()))
            .tempdir_in(parent)
            .with_context(|| format!("cannot create a staging directory in {}", parent.display()))?;
        register_cleanup(stage.path());
        Ok(Self { out: out.to_path_buf(), stage: Some(stage) })
    }
    /// Path of a file inside the staging directory.
    pub fn path(&self, name: &str) -> PathBuf {
        self.stage.as_ref().expect("not committed yet").path().join(name)
    }
    /// Moves every staged file into the output directory (each by an atomic rename).
    pub fn commit(mut self) -> Result<()> {
        let stage = self.stage.take().expect("commit once");
        std::fs::create_dir_all(&self.out)
            .with_context(|| format!("cannot create directory {}", self.out.display()))?;
        for entry in std::fs::read_dir(stage.path())? {
            let entry = entry?;
            let dest = self.out.join(entry.file_name());
            std::fs::rename(entry.path(), &dest)
                .with_context(|| format!("cannot move {} into place", dest.display()))?;
        }
        unregister_cleanup(stage.path());
        Ok(())
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if let Some(st) = &self.stage {
            unregister_cleanup(st.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn staged_files_appear_only_on_commit() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("run");
        let st = StagedDir::new(&out).unwrap();
        std::fs::write(st.path("a.csv"), "x").unwrap();
        assert!(!out.join("a.csv").exists());
        st.commit().unwrap();
        assert_eq!(std::fs::read_to_string(out.join("a.csv")).unwrap(), "x");
        let st2 = StagedDir::new(&out).unwrap();
        std::fs::write(st2.path("b.csv"), "y").unwrap();
        drop(st2);
        assert!(!out.join("b.csv").exists(), "an abandoned stage must leave nothing behind");
    }

    #[test]
    fn atomic_write_replaces_whole_file() {
        let root = tempfile::tempdir().unwrap();
        let f = root.path().join("r.json");
        write_atomic(&f, b"{}").unwrap();
        write_atomic(&f, b"{\"a\":1}").unwrap();
        assert_eq!(std::fs::read_to_string(&f).unwrap(), "{\"a\":1}");
    }
}
