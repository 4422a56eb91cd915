//! The output writer against hostile targets: the bytes choose what the output path names
//! (nothing, a file, links of every kind, a directory, a FIFO with a reader, a socket, an input
//! of the command, `/dev/null`, a path below a file), the file name and the content; the
//! target checks what [`crate::output::write_atomic`] promises and panics when it is broken:
//! a link, FIFO, socket, device or directory stays what it was, an input keeps its content, a
//! written file holds exactly the content, nothing else is left in the directory.
//!
//! Everything happens in a fresh temporary directory; the only path outside it ever written
//! is `/dev/null` (directly or through a link).
use crate::output::{forget_inputs, register_input, write_atomic};
use std::ffi::OsStr;
use std::io::Read;
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::{symlink, FileTypeExt, OpenOptionsExt};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Content written, at most (a FIFO's buffer holds it without a reader thread).
const MAX_CONTENT: usize = 4096;
/// `O_NONBLOCK` of Linux (x86, arm): a FIFO's read end opens without waiting for a writer.
const O_NONBLOCK: i32 = 0o4000;

/// The registry of inputs is process-wide: targets that register or forget inputs hold this.
pub(super) static REGISTRY: Mutex<()> = Mutex::new(());

/// What the output path names before the write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Nothing,
    File,
    LinkToFile,
    Dangling,
    LinkLoop,
    LinkChain(usize),
    Directory,
    LinkToDirectory,
    Fifo,
    Socket,
    Input,
    LinkToInput,
    DevNull,
    LinkToDevNull,
    BelowFile,
}

impl Kind {
    fn of(b: u8, depth: u8) -> Self {
        match b % 15 {
            0 => Kind::Nothing,
            1 => Kind::File,
            2 => Kind::LinkToFile,
            3 => Kind::Dangling,
            4 => Kind::LinkLoop,
            5 => Kind::LinkChain(1 + depth as usize % 45),
            6 => Kind::Directory,
            7 => Kind::LinkToDirectory,
            8 => Kind::Fifo,
            9 => Kind::Socket,
            10 => Kind::Input,
            11 => Kind::LinkToInput,
            12 => Kind::DevNull,
            13 => Kind::LinkToDevNull,
            _ => Kind::BelowFile,
        }
    }
}

/// What kind of file `p` is, links not followed (`None`: nothing there).
fn kind_of(p: &Path) -> Option<&'static str> {
    let t = std::fs::symlink_metadata(p).ok()?.file_type();
    Some(if t.is_symlink() {
        "symlink"
    } else if t.is_file() {
        "file"
    } else if t.is_dir() {
        "directory"
    } else if t.is_fifo() {
        "fifo"
    } else if t.is_socket() {
        "socket"
    } else if t.is_char_device() {
        "char device"
    } else {
        "other"
    })
}

fn names(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok()).map(|e| PathBuf::from(e.file_name())).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// The output's file name: the fuzz bytes when they make one path component, else `out`.
fn file_name(bytes: &[u8]) -> PathBuf {
    let ok = !bytes.is_empty()
        && bytes.len() <= 200
        && !bytes.iter().any(|b| *b == b'/' || *b == 0)
        && bytes != b"."
        && bytes != b"..";
    PathBuf::from(if ok { OsStr::from_bytes(bytes) } else { OsStr::new("out") })
}

/// Byte 0 chooses the kind, byte 1 the depth of a link chain, byte 2 the length of the file
/// name taken from the following bytes (0: `out`); the rest is the content.
pub fn write_output(data: &[u8]) {
    let _registry = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    let Some((&k, rest)) = data.split_first() else { return };
    let (depth, rest) = rest.split_first().map_or((0, rest), |(d, r)| (*d, r));
    let (len, rest) = rest.split_first().map_or((0, rest), |(l, r)| (*l as usize % 32, r));
    let (name, content) = rest.split_at(len.min(rest.len()));
    let content = &content[..content.len().min(MAX_CONTENT)];
    let kind = Kind::of(k, depth);
    if kind == Kind::DevNull {
        return write_dev_null(Path::new("/dev/null"), content);
    }
    let Ok(root) = super::scratch() else { return };
    let Some(scene) = Scene::make(root.path(), name) else { return };
    let Some(held) = scene.arrange(kind) else {
        forget_inputs();
        return; // e.g. a socket path longer than sun_path, or no mkfifo here
    };
    let path = if kind == Kind::BelowFile { scene.target.join("out") } else { scene.target.clone() };
    let before = kind_of(&scene.target);
    let r = write_atomic(&path, content);
    forget_inputs();
    let what = format!("{kind:?} target {}: {r:?}", path.display());
    scene.check(kind, before, &r, content, held, &what);
}

/// The content a target holds before the write.
const OLD: &[u8] = b"old content";

/// The scratch layout of one case: the output's directory `d` holding only `target`, and
/// `fx` holding what links point to (`real`, the end of a chain).
struct Scene {
    fx: PathBuf,
    d: PathBuf,
    target: PathBuf,
    real: PathBuf,
}

/// What a case keeps open while the output is written: a FIFO's reader, a socket's listener.
struct Held {
    reader: Option<std::fs::File>,
    _listener: Option<std::os::unix::net::UnixListener>,
}

impl Scene {
    /// The layout under `root` with its two directories made (`None` where they cannot be),
    /// the target named by the fuzz bytes `name` ([`file_name`]).
    fn make(root: &Path, name: &[u8]) -> Option<Self> {
        let (fx, d) = (root.join("fx"), root.join("d"));
        if std::fs::create_dir(&fx).is_err() || std::fs::create_dir(&d).is_err() {
            return None;
        }
        Some(Scene { target: d.join(file_name(name)), real: fx.join("real"), fx, d })
    }

    /// Puts a target of `kind` in place; `None` where the system refuses it.
    fn arrange(&self, kind: Kind) -> Option<Held> {
        let (fx, target, real) = (&self.fx, &self.target, &self.real);
        let mut held = Held { reader: None, _listener: None };
        let set_up = match kind {
            Kind::Nothing => Ok(()),
            Kind::File | Kind::BelowFile => std::fs::write(target, OLD),
            Kind::LinkToFile => std::fs::write(real, OLD).and_then(|_| symlink("../fx/real", target)),
            Kind::Dangling => symlink("../fx/made", target),
            Kind::LinkLoop => symlink("../fx/b", target)
                .and_then(|_| symlink("c", fx.join("b")))
                .and_then(|_| symlink("b", fx.join("c"))),
            Kind::LinkChain(n) => {
                // target -> fx/l1 -> fx/l2 -> ... -> fx/l(n-1) -> fx/real: n links
                let first = if n == 1 { "../fx/real".to_string() } else { "../fx/l1".to_string() };
                let mut r = std::fs::write(real, OLD).and_then(|_| symlink(first, target));
                for i in 1..n {
                    let to = if i + 1 == n { "real".to_string() } else { format!("l{}", i + 1) };
                    r = r.and_then(|_| symlink(&to, fx.join(format!("l{i}"))));
                }
                r
            }
            Kind::Directory => std::fs::create_dir(target).and_then(|_| std::fs::write(target.join("keep"), OLD)),
            Kind::LinkToDirectory => std::fs::create_dir(fx.join("dir")).and_then(|_| symlink("../fx/dir", target)),
            Kind::Fifo => {
                let made = std::process::Command::new("mkfifo").arg(target).status().is_ok_and(|s| s.success());
                if !made {
                    return None;
                }
                std::fs::OpenOptions::new()
                    .read(true)
                    .custom_flags(O_NONBLOCK)
                    .open(target)
                    .map(|r| held.reader = Some(r))
            }
            Kind::Socket => std::os::unix::net::UnixListener::bind(target).map(|l| held._listener = Some(l)),
            Kind::Input => std::fs::write(target, OLD).map(|_| register_input(target)),
            Kind::LinkToInput => {
                std::fs::write(real, OLD).and_then(|_| symlink("../fx/real", target)).map(|_| register_input(real))
            }
            Kind::LinkToDevNull => symlink("/dev/null", target),
            Kind::DevNull => unreachable!("written through by write_dev_null"),
        };
        set_up.ok().map(|_| held)
    }

    /// What the write `r` of `content` must have done to a target of `kind` (of file kind
    /// `before`): the target keeps its kind (a new file appears only where there was nothing),
    /// nothing else is left beside it, and the content went where the kind says, or the write
    /// was refused.
    fn check(&self, kind: Kind, before: Option<&str>, r: &anyhow::Result<()>, content: &[u8], held: Held, what: &str) {
        let (fx, target, real) = (&self.fx, &self.target, &self.real);
        let after = kind_of(target);
        match kind {
            Kind::Nothing => assert_eq!(after, Some("file"), "{what}"),
            _ => assert_eq!(after, before, "{what}: the target changed kind"),
        }
        assert_eq!(names(&self.d), vec![PathBuf::from(target.file_name().unwrap_or_default())], "{what}: files left");
        let read = |p: &Path| std::fs::read(p).unwrap_or_default();
        match kind {
            Kind::Nothing | Kind::File => {
                assert!(r.is_ok(), "{what}");
                assert_eq!(read(target), content, "{what}");
            }
            Kind::LinkToFile => {
                assert!(r.is_ok(), "{what}");
                assert_eq!(read(real), content, "{what}");
            }
            Kind::Dangling => {
                assert!(r.is_ok(), "{what}");
                assert_eq!(read(&fx.join("made")), content, "{what}");
            }
            Kind::LinkChain(n) if n <= 40 => {
                assert!(r.is_ok(), "{what}");
                assert_eq!(read(real), content, "{what}");
            }
            Kind::LinkChain(_) => {
                assert!(r.is_err(), "{what}: a chain of more than 40 links must be refused");
                assert_eq!(read(real), OLD, "{what}");
            }
            Kind::LinkLoop | Kind::Socket | Kind::LinkToDirectory | Kind::BelowFile => {
                assert!(r.is_err(), "{what}");
            }
            Kind::Directory => {
                assert!(r.is_err(), "{what}");
                assert_eq!(names(target), vec![PathBuf::from("keep")], "{what}");
                assert_eq!(read(&target.join("keep")), OLD, "{what}");
            }
            Kind::Fifo => {
                assert!(r.is_ok(), "{what}");
                let mut got = Vec::new();
                if let Some(mut rd) = held.reader {
                    let _ = rd.read_to_end(&mut got);
                }
                assert_eq!(got, content, "{what}: the reader of the FIFO");
            }
            Kind::Input => {
                assert!(r.is_err(), "{what}: an input must not be overwritten");
                assert_eq!(read(target), OLD, "{what}");
            }
            Kind::LinkToInput => {
                assert!(r.is_err(), "{what}: an input must not be overwritten through a link");
                assert_eq!(read(real), OLD, "{what}");
            }
            Kind::LinkToDevNull => {
                assert!(r.is_ok(), "{what}");
                assert_eq!(kind_of(Path::new("/dev/null")), Some("char device"), "{what}");
            }
            Kind::DevNull => unreachable!("written through by write_dev_null"),
        }
    }
}

/// `/dev/null` itself: written through, still the device afterwards.
fn write_dev_null(p: &Path, content: &[u8]) {
    let r = write_atomic(p, content);
    assert!(r.is_ok(), "/dev/null: {r:?}");
    assert_eq!(kind_of(p), Some("char device"), "/dev/null was replaced");
}
