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
    /// A character device or FIFO: written through (`/dev/null`, a named pipe).
    Stream,
    /// A descriptor of this process named by path (`/dev/stdout`, `/dev/fd/N`,
    /// `/proc/self/fd/N`): written through that descriptor, whatever it is open on (a file
    /// the shell redirected stdout to is appended to, not replaced).
    Descriptor(i32),
}

/// The descriptor number a path names when it is `/dev/stdout`, `/dev/stderr`, `/dev/fd/N`,
/// `/proc/self/fd/N` or `/proc/PID/fd/N` of this process.
fn own_descriptor(p: &Path) -> Option<i32> {
    let s = p.to_str()?;
    match s {
        "/dev/stdout" => return Some(1),
        "/dev/stderr" => return Some(2),
        _ => {}
    }
    let pid = format!("/proc/{}/fd/", std::process::id());
    let n = s.strip_prefix("/dev/fd/").or_else(|| s.strip_prefix("/proc/self/fd/")).or_else(|| s.strip_prefix(&pid))?;
    n.parse().ok()
}

/// Follows symlinks from `path` (a dangling link names the file it would create) and
/// classifies the result; refuses directories, block devices and sockets.
fn resolve_target(path: &Path) -> Result<Target> {
    use std::os::unix::ffi::OsStrExt;
    if path.as_os_str().as_bytes().ends_with(b"/") {
        bail!("output {} ends with '/', which names a directory: give a file path", path.display());
    }
    let mut p = path.to_path_buf();
    // MAX_LINKS links, then the file they lead to
    for _ in 0..=MAX_LINKS {
        if let Some(fd) = own_descriptor(&p) {
            return Ok(Target::Descriptor(fd));
        }
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

/// Refuses, before the work, an output file that [`write_atomic`] would refuse only after it:
/// an input of the command, a directory, block device or socket (through links), or a file
/// whose nearest existing directory cannot be written (probed with an unnamed temporary file,
/// gone when closed). Character devices, FIFOs and descriptors are written through and pass.
pub fn check_writable(path: &Path) -> Result<()> {
    refuse_input(path)?;
    let Target::File(file) = resolve_target(path)? else { return Ok(()) };
    probe_nearest_directory(path, &file)
}

/// [`check_writable`] for an output folder ([`StagedDir`]): refuses a path that names
/// something other than a directory, and a folder whose nearest existing ancestor cannot be
/// written, before the work.
pub fn check_directory_writable(out: &Path) -> Result<()> {
    refuse_non_directory(out)?;
    // the nearest existing directory above a file inside `out`: `out` itself when it exists
    probe_nearest_directory(out, &out.join("probe"))
}

/// Probes the nearest existing directory above `file` (the writer creates the missing ones
/// below it) with an unnamed temporary file, gone when closed; `path` names the output.
fn probe_nearest_directory(path: &Path, file: &Path) -> Result<()> {
    let here = Path::new(".");
    let mut dir = file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(here);
    while dir != here && std::fs::symlink_metadata(dir).is_err() {
        dir = dir.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(here);
    }
    if !dir.is_dir() {
        bail!("output {}: {} is not a directory", path.display(), dir.display());
    }
    tempfile::tempfile_in(dir)
        .with_context(|| format!("output {}: cannot write into {}", path.display(), dir.display()))?;
    Ok(())
}

/// Writes `bytes` through this process's descriptor `fd` (standard output and error through
/// their handles, so the output follows what the command printed before; any other by
/// appending to what the path opens).
fn write_descriptor(fd: i32, path: &Path, bytes: &[u8]) -> Result<()> {
    let cannot = || format!("cannot write {}", path.display());
    match fd {
        1 => {
            let mut out = std::io::stdout().lock();
            out.write_all(bytes).and_then(|_| out.flush()).with_context(cannot)
        }
        2 => std::io::stderr().lock().write_all(bytes).with_context(cannot),
        _ => std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .and_then(|mut f| f.write_all(bytes))
            .with_context(cannot),
    }
}

/// How long an output FIFO may wait for its reader to appear before it is refused.
pub const FIFO_READER_WAIT: std::time::Duration = std::time::Duration::from_secs(5);

/// Opens a character device or FIFO for writing. A FIFO is opened without blocking: with no
/// reader, a plain open(2) would wait forever, so it is retried for `wait` ([`FIFO_READER_WAIT`])
/// and then refused; once a reader is seen, the FIFO is opened for ordinary blocking writes.
fn open_stream(path: &Path, wait: std::time::Duration) -> Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    let cannot = || format!("cannot open {} for writing", path.display());
    if !std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo()) {
        return std::fs::OpenOptions::new().write(true).open(path).with_context(cannot);
    }
    let deadline = std::time::Instant::now() + wait;
    loop {
        match std::fs::OpenOptions::new().write(true).custom_flags(libc::O_NONBLOCK).open(path) {
            Ok(probe) => {
                // a reader is there: the blocking open returns at once (the probe keeps the
                // FIFO open on our side meanwhile)
                let f = std::fs::OpenOptions::new().write(true).open(path).with_context(cannot);
                drop(probe);
                return f;
            }
            Err(e) if e.raw_os_error() == Some(libc::ENXIO) => {
                if std::time::Instant::now() >= deadline {
                    bail!(
                        "output {} is a FIFO with no reader (waited {} s): start its reader first or give a file path",
                        path.display(),
                        wait.as_secs_f64()
                    );
                }
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            Err(e) => return Err(e).with_context(cannot),
        }
    }
}

/// Writes `bytes` to `path`: atomically for a regular file (temporary file + rename in the
/// same directory, mode `0666 & !umask`), through for a character device or FIFO; see the
/// module doc for what is refused.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    refuse_input(path)?;
    let file = match resolve_target(path)? {
        Target::Stream => {
            let mut f = open_stream(path, FIFO_READER_WAIT)?;
            return f.write_all(bytes).with_context(|| format!("cannot write {}", path.display()));
        }
        Target::Descriptor(fd) => return write_descriptor(fd, path, bytes),
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

/// What a panic message of the standard library says about the standard streams.
#[derive(Debug, PartialEq)]
enum StreamFailure {
    /// Standard output closed by its reader (`| head`): end quietly, as Unix tools do.
    BrokenStdout,
    /// Standard output failed otherwise (`> /dev/full`: no space left): one line, status 1.
    Stdout(String),
    /// Standard error failed: nothing can be said; status 1.
    Stderr,
}

fn stream_failure(message: &str) -> Option<StreamFailure> {
    if let Some(reason) = message.strip_prefix("failed printing to stdout: ") {
        return Some(if reason.contains("Broken pipe") {
            StreamFailure::BrokenStdout
        } else {
            StreamFailure::Stdout(reason.to_string())
        });
    }
    message.starts_with("failed printing to stderr").then_some(StreamFailure::Stderr)
}

/// Installs a panic hook under which a closed standard output (`moreau validate m.toml | head
/// -c 10`) ends the process quietly with [`BROKEN_PIPE_EXIT`] instead of a panic message and a
/// backtrace, and a standard output that cannot be written otherwise (`> /dev/full`) ends it
/// with a one-line error and status 1; every other panic goes to the previous hook.
pub fn exit_quietly_on_broken_pipe() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        match stream_failure(message) {
            Some(StreamFailure::BrokenStdout) => {
                cleanup_now();
                std::process::exit(BROKEN_PIPE_EXIT);
            }
            Some(StreamFailure::Stdout(reason)) => {
                cleanup_now();
                let _ = writeln!(std::io::stderr(), "error: cannot write to standard output: {reason}");
                std::process::exit(1);
            }
            Some(StreamFailure::Stderr) => {
                cleanup_now();
                std::process::exit(1);
            }
            None => previous(info),
        }
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

/// Why a directory lock was not taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    #[error(
        "{dir} is in use by another {what} ({holder}; lock file {lock}): wait for it to finish or choose another --out"
    )]
    Held { dir: PathBuf, what: &'static str, holder: String, lock: PathBuf },
    #[error("cannot write {path}: {reason}")]
    Io { path: PathBuf, reason: String },
}

/// An exclusive lock on an output directory: a second run into the same directory refuses,
/// naming the holder, instead of interleaving or replacing the first run's files. The lock
/// file (`.NAME.lock` inside the directory) holds the holder's process id; the operating
/// system releases the lock when the holder exits (even when killed), and the file is removed
/// when the run ends or is interrupted.
pub struct DirLock {
    path: PathBuf,
    _file: std::fs::File,
}

impl DirLock {
    /// Locks `dir` (created if missing) under the lock file `.NAME.lock`; `what` names the
    /// kind of run in the refusal ("sweep", "moreau run").
    pub fn acquire(dir: &Path, name: &str, what: &'static str) -> Result<Self, LockError> {
        use std::io::{Read, Seek};
        let path = dir.join(format!(".{name}.lock"));
        let werr = |e: std::io::Error| LockError::Io { path: path.clone(), reason: e.to_string() };
        std::fs::create_dir_all(dir).map_err(|e| LockError::Io { path: dir.to_path_buf(), reason: e.to_string() })?;
        for _ in 0..100 {
            let mut f = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(werr)?;
            match f.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    let mut holder = String::new();
                    let _ = f.read_to_string(&mut holder);
                    let holder = holder.trim();
                    return Err(LockError::Held {
                        dir: dir.to_path_buf(),
                        what,
                        holder: if holder.is_empty() { "pid unknown".into() } else { holder.to_string() },
                        lock: path.clone(),
                    });
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(werr(e)),
            }
            // the previous holder may have removed the file between our open and lock
            if !same_file(&f, &path) {
                continue;
            }
            f.set_len(0).map_err(werr)?;
            f.seek(std::io::SeekFrom::Start(0)).map_err(werr)?;
            f.write_all(format!("pid {}", std::process::id()).as_bytes()).map_err(werr)?;
            let _ = f.flush();
            register_cleanup(&path);
            return Ok(Self { path, _file: f });
        }
        Err(LockError::Io { path, reason: "the lock file keeps being replaced".into() })
    }
}

fn same_file(f: &std::fs::File, path: &Path) -> bool {
    match (f.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
        _ => false,
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        // removed while still locked; the lock goes with the file handle right after
        let _ = std::fs::remove_file(&self.path);
        unregister_cleanup(&self.path);
    }
}

/// The list of files a run wrote into its output directory (one name a line), read by the
/// next run into the same directory to remove what it does not write again.
pub const MANIFEST: &str = ".moreau-outputs";
/// Name of the lock of a directory that a run replaces as a whole (`diagnose`, `simulate`):
/// one name for every command, so two of them into one directory exclude each other.
const RUN_LOCK: &str = "moreau";

/// A directory whose files appear all together or not at all: files are written into a
/// hidden staging directory next to `out` (`.moreau-staging-PID-XXXXXX`) and moved into
/// `out` by [`StagedDir::commit`]. Dropping without commit, or an interruption, removes the
/// staging directory; stale ones of interrupted runs are removed when the next one starts.
///
/// [`StagedDir::replacing`] makes the run own its directory: it is locked from creation to
/// commit, and the commit removes the files of the previous run there (listed in
/// [`MANIFEST`]) that this run does not write again, so a folder never mixes two runs' files
/// (`zoom-3.svg` of an earlier diagnosis beside a new report). Files the user put there
/// (not in the manifest) are never touched.
pub struct StagedDir {
    out: PathBuf,
    stage: Option<tempfile::TempDir>,
    lock: Option<DirLock>,
    /// `out` did not exist before [`StagedDir::replacing`] created it for its lock: removed
    /// again (if still empty) when the run ends without a commit.
    created: bool,
}

impl StagedDir {
    /// A staged directory for a fixed set of files (each commit replaces the same names).
    pub fn new(out: &Path) -> Result<Self> {
        refuse_non_directory(out)?;
        Self::stage_beside(out)
    }
    /// The staging directory next to `out` (stale ones of interrupted runs removed first).
    fn stage_beside(out: &Path) -> Result<Self> {
        let parent = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create directory {}", parent.display()))?;
        remove_stale_staging(parent);
        let stage = tempfile::Builder::new()
            .prefix(&format!("{STAGING_PREFIX}{}-", std::process::id()))
            .tempdir_in(parent)
            .with_context(|| format!("cannot create a staging directory in {}", parent.display()))?;
        register_cleanup(stage.path());
        Ok(Self { out: out.to_path_buf(), stage: Some(stage), lock: None, created: false })
    }
    /// A staged directory that replaces the previous run's files in `out` and holds `out`'s
    /// lock until it is committed or dropped: create it before the work starts.
    pub fn replacing(out: &Path) -> Result<Self> {
        refuse_non_directory(out)?;
        let created = !out.exists();
        let lock = DirLock::acquire(out, RUN_LOCK, "moreau run")?;
        let mut staged = Self::stage_beside(out)?;
        staged.lock = Some(lock);
        staged.created = created;
        Ok(staged)
    }
    /// Path of a file inside the staging directory.
    pub fn path(&self, name: &str) -> PathBuf {
        self.stage.as_ref().expect("not committed yet").path().join(name)
    }
    /// Moves every staged file into the output directory (each by an atomic rename); for a
    /// [`StagedDir::replacing`] directory, then removes the previous run's files that were
    /// not written again and records this run's files in the manifest.
    pub fn commit(mut self) -> Result<()> {
        let stage = self.stage.take().expect("commit once");
        std::fs::create_dir_all(&self.out)
            .with_context(|| format!("cannot create directory {}", self.out.display()))?;
        let mut names = Vec::new();
        for entry in std::fs::read_dir(stage.path())? {
            names.push(entry?.file_name());
        }
        names.sort();
        for name in &names {
            let dest = self.out.join(name);
            refuse_input(&dest)?;
            if std::fs::symlink_metadata(&dest).is_ok_and(|m| m.is_dir()) {
                bail!("cannot write {}: a directory is in its place (nothing was written)", dest.display());
            }
        }
        for name in &names {
            let dest = self.out.join(name);
            std::fs::rename(stage.path().join(name), &dest)
                .with_context(|| format!("cannot move {} into place", dest.display()))?;
        }
        if self.lock.is_some() {
            self.replace_manifest(&names)?;
        }
        unregister_cleanup(stage.path());
        self.created = false;
        Ok(())
    }
    /// Removes the files of the previous manifest that are not in `names`, then writes the
    /// manifest of `names`. Only plain file names in `out` are removed (no path separators,
    /// no directories, nothing through a symlink).
    fn replace_manifest(&self, names: &[std::ffi::OsString]) -> Result<()> {
        let manifest = self.out.join(MANIFEST);
        let previous = std::fs::read_to_string(&manifest).unwrap_or_default();
        let now: Vec<&str> = names.iter().filter_map(|n| n.to_str()).collect();
        for old in previous.lines().filter(|l| !l.is_empty() && !now.contains(l)) {
            let plain = !old.contains('/') && old != "." && old != ".." && old != MANIFEST;
            let path = self.out.join(old);
            if plain && std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_file()) && refuse_input(&path).is_ok() {
                let _ = std::fs::remove_file(&path);
            }
        }
        let mut text = now.join("\n");
        text.push('\n');
        write_atomic(&manifest, text.as_bytes())
    }
}

/// Refuses an output directory path that names something other than a directory.
fn refuse_non_directory(out: &Path) -> Result<()> {
    match std::fs::metadata(out) {
        Ok(m) if !m.is_dir() => {
            bail!("output {} is not a directory: refusing to replace it (give a directory path)", out.display())
        }
        _ => Ok(()),
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if let Some(st) = &self.stage {
            unregister_cleanup(st.path());
        }
        drop(self.lock.take());
        if self.created {
            let _ = std::fs::remove_dir(&self.out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
        v.sort();
        v
    }

    /// One run's files into `out`: `names` with contents `text`.
    fn replacing_run(out: &Path, names: &[&str], text: &str) {
        let st = StagedDir::replacing(out).unwrap();
        for n in names {
            std::fs::write(st.path(n), text).unwrap();
        }
        st.commit().unwrap();
    }

    #[test]
    fn a_replacing_run_removes_only_the_previous_runs_files() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("diag");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("notes.txt"), "the user's").unwrap();
        replacing_run(&out, &["report.md", "zoom-1.svg", "zoom-2.svg"], "first");
        replacing_run(&out, &["report.md", "zoom-1.svg"], "second");
        assert_eq!(files(&out), [MANIFEST, "notes.txt", "report.md", "zoom-1.svg"]);
        assert_eq!(std::fs::read_to_string(out.join("report.md")).unwrap(), "second");
        assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "the user's");
        // a manifest entry naming a path outside the directory removes nothing there
        let outside = root.path().join("keep.txt");
        std::fs::write(&outside, "k").unwrap();
        std::fs::write(out.join(MANIFEST), "../keep.txt\nnotes.txt\n").unwrap();
        replacing_run(&out, &["report.md"], "third");
        assert!(outside.exists());
        assert!(!out.join("notes.txt").exists(), "a listed plain name is the previous run's");
        // negative control: a fixed-set stage (sweep tables) leaves other names alone
        let fixed = root.path().join("fixed");
        for names in [&["a.csv", "b.csv"][..], &["a.csv"][..]] {
            let st = StagedDir::new(&fixed).unwrap();
            for n in names {
                std::fs::write(st.path(n), "x").unwrap();
            }
            st.commit().unwrap();
        }
        assert_eq!(files(&fixed), ["a.csv", "b.csv"]);
    }

    #[test]
    fn a_replaced_directory_is_locked_until_commit() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("sim");
        let first = StagedDir::replacing(&out).unwrap();
        let err = StagedDir::replacing(&out).err().expect("a second run must be refused").to_string();
        assert!(err.contains("in use by another moreau run"), "{err}");
        assert!(err.contains(&format!("pid {}", std::process::id())), "{err}");
        drop(first);
        assert!(!out.exists(), "a run that made its directory and failed removes it again");
        // negative control: once the first run is over, the directory is free
        replacing_run(&out, &["trajectory.csv"], "t");
        let again = StagedDir::replacing(&out);
        assert!(again.is_ok());
        // a regular file in the place of the directory is refused before any work
        let file = root.path().join("file");
        std::fs::write(&file, "x").unwrap();
        let err = StagedDir::replacing(&file).err().unwrap().to_string();
        assert!(err.contains("is not a directory"), "{err}");
    }

    #[test]
    fn a_fifo_is_written_through_its_reader_and_refused_without_one() {
        let root = tempfile::tempdir().unwrap();
        let fifo = root.path().join("pipe");
        let status = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(status.success());
        let wait = std::time::Duration::from_millis(200);
        let err = open_stream(&fifo, wait).unwrap_err().to_string();
        assert!(err.contains("FIFO with no reader"), "{err}");
        let reader_path = fifo.clone();
        let reader = std::thread::spawn(move || std::fs::read(&reader_path).unwrap());
        // negative control of the refusal: with a reader the same open succeeds
        let mut f = open_stream(&fifo, std::time::Duration::from_secs(10)).unwrap();
        f.write_all(b"through").unwrap();
        drop(f);
        assert_eq!(reader.join().unwrap(), b"through");
        assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO stays");
    }

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
    fn outputs_are_checked_before_the_work() {
        let root = tempfile::tempdir().unwrap();
        let file = root.path().join("notes.txt");
        std::fs::write(&file, "x").unwrap();
        let slash = format!("{}/new.json/", root.path().display());
        for (path, why) in [
            (slash.as_str(), "ends with '/'"),
            (root.path().to_str().unwrap(), "is a directory"),
            (&format!("{}/x.json", file.display()), "is not a directory"),
        ] {
            let err = check_writable(Path::new(path)).unwrap_err().to_string();
            assert!(err.contains(why), "{path}: {err}");
        }
        let err = check_directory_writable(&file).unwrap_err().to_string();
        assert!(err.contains("is not a directory"), "{err}");
        // negative controls: a new file, a new nested folder (relative too), /dev/null
        check_writable(&root.path().join("a/b/new.json")).unwrap();
        check_writable(Path::new("no-such-dir/below/new.json")).unwrap();
        check_directory_writable(Path::new("no-such-dir/below/out")).unwrap();
        check_writable(Path::new("/dev/null")).unwrap();
        check_directory_writable(&root.path().join("new/folder")).unwrap();
        check_directory_writable(root.path()).unwrap();
    }

    #[test]
    fn own_descriptors_are_written_through_not_replaced() {
        for (path, fd) in [("/dev/stdout", 1), ("/dev/stderr", 2), ("/dev/fd/7", 7), ("/proc/self/fd/1", 1)] {
            assert!(matches!(resolve_target(Path::new(path)), Ok(Target::Descriptor(n)) if n == fd), "{path}");
        }
        let mine = format!("/proc/{}/fd/3", std::process::id());
        assert_eq!(own_descriptor(Path::new(&mine)), Some(3));
        // negative controls: another process's descriptor, a file named like one
        assert_eq!(own_descriptor(Path::new("/proc/1/fd/1")), None);
        assert_eq!(own_descriptor(Path::new("/tmp/dev/stdout")), None);
        // a symlink to /dev/stdout is followed to it
        let root = tempfile::tempdir().unwrap();
        let link = root.path().join("out.json");
        std::os::unix::fs::symlink("/dev/stdout", &link).unwrap();
        assert!(matches!(resolve_target(&link), Ok(Target::Descriptor(1))));
    }

    #[test]
    fn a_directory_in_place_of_a_staged_file_stops_the_commit_before_any_move() {
        let root = tempfile::tempdir().unwrap();
        let out = root.path().join("diag");
        std::fs::create_dir_all(out.join("report.json")).unwrap();
        let st = StagedDir::replacing(&out).unwrap();
        for n in ["a.png", "report.json", "z.svg"] {
            std::fs::write(st.path(n), "x").unwrap();
        }
        let err = st.commit().unwrap_err().to_string();
        assert!(err.contains("a directory is in its place"), "{err}");
        assert_eq!(files(&out), ["report.json"], "nothing moved");
        // negative control: without the directory the same commit goes through
        std::fs::remove_dir(out.join("report.json")).unwrap();
        replacing_run(&out, &["a.png", "report.json"], "x");
        assert_eq!(files(&out), [MANIFEST, "a.png", "report.json"]);
    }

    #[test]
    fn stream_failures_are_told_apart_from_other_panics() {
        use StreamFailure::*;
        assert_eq!(stream_failure("failed printing to stdout: Broken pipe (os error 32)"), Some(BrokenStdout));
        assert_eq!(
            stream_failure("failed printing to stdout: No space left on device (os error 28)"),
            Some(Stdout("No space left on device (os error 28)".into()))
        );
        assert_eq!(stream_failure("failed printing to stderr: No space left on device (os error 28)"), Some(Stderr));
        // negative control: other panics keep their message and backtrace
        assert_eq!(stream_failure("index out of bounds: Broken pipe"), None);
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
