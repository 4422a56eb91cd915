//! Output files that are never left half-written, never replace what is not ours and never
//! overwrite an input: a regular file is written to a temporary file in the destination
//! directory and renamed into place only when complete (mode `0666 & !umask`, like any Unix
//! tool); a symlink is followed to the file it names (the link stays); a character device or
//! FIFO (`/dev/null`, `/dev/stdout`) is written through; a directory, block device or socket
//! is refused; a target that is one of the command's inputs ([`register_input`]) is refused.
use anyhow::{bail, Context, Result};
use std::io::Write;
use std::os::unix::fs::{FileTypeExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Symlinks followed at most (as the kernel's `ELOOP` limit).
const MAX_LINKS: usize = 40;

/// Input files of the running command, by `(device, inode)`: an output must not replace one.
static INPUTS: Mutex<Vec<(u64, u64, PathBuf)>> = Mutex::new(Vec::new());

/// Registers `path` as an input of the running command (a file that does not exist is
/// ignored: reading it fails on its own).
pub fn register_input(path: &Path) {
    if let (Ok(m), Ok(mut v)) = (std::fs::metadata(path), INPUTS.lock()) {
        v.push((m.dev(), m.ino(), path.to_path_buf()));
    }
}

/// Forgets every registered input: for a process that runs many commands one after another
/// (the fuzz targets of `crate::fuzzing`); a command-line run never needs it.
pub fn forget_inputs() {
    if let Ok(mut v) = INPUTS.lock() {
        v.clear();
    }
}

/// Refuses an output target that is (or resolves to, through links) an input of the command.
pub fn refuse_input(path: &Path) -> Result<()> {
    let Ok(m) = std::fs::metadata(path) else { return Ok(()) };
    if !m.is_file() {
        return Ok(());
    }
    if let Ok(v) = INPUTS.lock() {
        // The input must still be the registered file: an inode number freed by a deleted
        // input can be reused by an unrelated file.
        let same = |d: u64, i: u64, input: &Path| {
            d == m.dev() && i == m.ino() && std::fs::metadata(input).is_ok_and(|now| now.dev() == d && now.ino() == i)
        };
        if let Some((_, _, input)) = v.iter().find(|(d, i, input)| same(*d, *i, input)) {
            bail!(
                "output {} is the input {} of this command: refusing to overwrite it (choose another output path)",
                path.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// What an output path names, symlinks followed.
enum Target {
    /// A regular file at this path, or nothing yet: written by temporary file and rename.
    File(PathBuf),
    /// A character device or FIFO: written through (`/dev/null`, `/dev/stdout`, a pipe).
    Stream,
}

/// Follows symlinks from `path` (a dangling link names the file it would create) and
/// classifies the result; refuses directories, block devices and sockets.
fn resolve_target(path: &Path) -> Result<Target> {
    let mut p = path.to_path_buf();
    // MAX_LINKS links, then the file they lead to
    for _ in 0..=MAX_LINKS {
        let Ok(m) = std::fs::symlink_metadata(&p) else { return Ok(Target::File(p)) };
        let t = m.file_type();
        if t.is_symlink() {
            let link = std::fs::read_link(&p).with_context(|| format!("cannot read the symlink {}", p.display()))?;
            p = match p.parent() {
                Some(dir) if link.is_relative() => dir.join(link),
                _ => link,
            };
            continue;
        }
        if t.is_file() {
            return Ok(Target::File(p));
        }
        if t.is_char_device() || t.is_fifo() {
            return Ok(Target::Stream);
        }
        let what = if t.is_dir() {
            "a directory"
        } else if t.is_block_device() {
            "a block device"
        } else if t.is_socket() {
            "a socket"
        } else {
            "not a regular file"
        };
        bail!("output {} is {what}: refusing to replace it (give a file path)", path.display());
    }
    bail!("output {}: more than {MAX_LINKS} levels of symlinks", path.display())
}

/// Writes `bytes` to `path`: atomically for a regular file (temporary file + rename in the
/// same directory, mode `0666 & !umask`), through for a character device or FIFO; see the
/// module doc for what is refused.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    refuse_input(path)?;
    let file = match resolve_target(path)? {
        Target::Stream => {
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .with_context(|| format!("cannot open {} for writing", path.display()))?;
            return f.write_all(bytes).with_context(|| format!("cannot write {}", path.display()));
        }
        Target::File(f) => f,
    };
    let dir = file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create directory {}", dir.display()))?;
    // open(2) with 0666 applies the umask, as File::create does.
    let mut tmp = tempfile::Builder::new()
        .permissions(std::fs::Permissions::from_mode(0o666))
        .tempfile_in(dir)
        .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
    tmp.write_all(bytes).with_context(|| format!("cannot write {}", path.display()))?;
    tmp.as_file().sync_all().ok();
    tmp.persist(&file)
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

/// Exit status of a run whose standard output was closed by its reader (`| head`): 128 +
/// SIGPIPE, as a Unix tool killed by the signal reports.
pub const BROKEN_PIPE_EXIT: i32 = 141;

/// Whether a panic message is the standard library's report of a closed standard output.
fn is_broken_stdout(message: &str) -> bool {
    message.starts_with("failed printing to stdout") && message.contains("Broken pipe")
}

/// Installs a panic hook under which a closed standard output (`moreau validate m.toml | head
/// -c 10`) ends the process quietly with [`BROKEN_PIPE_EXIT`] instead of a panic message and a
/// backtrace; every other panic goes to the previous hook.
pub fn exit_quietly_on_broken_pipe() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if is_broken_stdout(message) {
            cleanup_now();
            std::process::exit(BROKEN_PIPE_EXIT);
        }
        previous(info)
    }));
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

    /// Mode of a file made by `File::create` here (`0666 & !umask`): the reference.
    fn umask_mode(dir: &Path) -> u32 {
        let f = dir.join("reference");
        std::fs::File::create(&f).unwrap();
        std::fs::metadata(&f).unwrap().permissions().mode() & 0o777
    }

    #[test]
    fn atomic_write_honours_the_umask() {
        let root = tempfile::tempdir().unwrap();
        let f = root.path().join("r.json");
        write_atomic(&f, b"{}").unwrap();
        let mode = std::fs::metadata(&f).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, umask_mode(root.path()), "mode {mode:o}");
        // negative control: a plain temporary file has 0600 whatever the umask
        let plain = tempfile::NamedTempFile::new_in(root.path()).unwrap();
        let plain_mode = plain.as_file().metadata().unwrap().permissions().mode() & 0o777;
        assert_eq!(plain_mode, 0o600);
    }

    #[test]
    fn symlink_is_followed_not_replaced() {
        let root = tempfile::tempdir().unwrap();
        let real = root.path().join("real.json");
        std::fs::write(&real, "old").unwrap();
        let link = root.path().join("link.json");
        std::os::unix::fs::symlink("real.json", &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link must stay");
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        // a dangling link creates the file it names
        let dangling = root.path().join("dangling.json");
        std::os::unix::fs::symlink("made.json", &dangling).unwrap();
        write_atomic(&dangling, b"m").unwrap();
        assert!(std::fs::symlink_metadata(&dangling).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(root.path().join("made.json")).unwrap(), "m");
    }

    #[test]
    fn character_devices_are_written_through_and_directories_refused() {
        write_atomic(Path::new("/dev/null"), b"discarded").unwrap();
        let meta = std::fs::symlink_metadata("/dev/null").unwrap();
        assert!(meta.file_type().is_char_device(), "/dev/null must stay a device");
        let root = tempfile::tempdir().unwrap();
        let err = write_atomic(root.path(), b"x").unwrap_err().to_string();
        assert!(err.contains("is a directory"), "{err}");
    }

    #[test]
    fn an_input_is_never_overwritten() {
        let root = tempfile::tempdir().unwrap();
        let input = root.path().join("model.toml");
        std::fs::write(&input, "name = 'm'").unwrap();
        let link = root.path().join("alias.toml");
        std::os::unix::fs::symlink(&input, &link).unwrap();
        // negative control: before it is registered, the file can be replaced
        let other = root.path().join("other.toml");
        std::fs::write(&other, "x").unwrap();
        write_atomic(&other, b"y").unwrap();
        register_input(&input);
        for target in [&input, &link] {
            let err = write_atomic(target, b"report").unwrap_err().to_string();
            assert!(err.contains("refusing to overwrite"), "{err}");
        }
        assert_eq!(std::fs::read_to_string(&input).unwrap(), "name = 'm'");
        // a deleted input does not protect whatever file later reuses its inode number
        let gone = root.path().join("gone.toml");
        std::fs::write(&gone, "x").unwrap();
        register_input(&gone);
        std::fs::remove_file(&gone).unwrap();
        let reused = root.path().join("reused.json");
        for _ in 0..64 {
            write_atomic(&reused, b"r").unwrap();
        }
    }

    #[test]
    fn only_a_closed_stdout_is_a_broken_pipe() {
        assert!(is_broken_stdout("failed printing to stdout: Broken pipe (os error 32)"));
        // negative controls: other panics keep their message and backtrace
        assert!(!is_broken_stdout("failed printing to stdout: No space left on device (os error 28)"));
        assert!(!is_broken_stdout("index out of bounds: Broken pipe"));
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
