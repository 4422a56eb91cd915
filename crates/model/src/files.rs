//! Reading input files defensively: only regular files (a FIFO, a device such as `/dev/zero`
//! or a directory is refused before it is opened, so nothing blocks or reads forever) and at
//! most a stated number of bytes.
use crate::ModelError;
use std::io::Read;
use std::path::Path;

/// Largest model file read (bytes): 16 MiB.
pub const MAX_MODEL_BYTES: u64 = 16 << 20;
/// Largest CSV file read (bytes): 512 MiB.
pub const MAX_CSV_BYTES: u64 = 512 << 20;

/// What a non-regular file is, in words.
fn kind_of(ft: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if ft.is_fifo() {
            return "a FIFO";
        }
        if ft.is_char_device() {
            return "a character device";
        }
        if ft.is_block_device() {
            return "a block device";
        }
        if ft.is_socket() {
            return "a socket";
        }
    }
    if ft.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

/// Checks that `path` is a regular file (symbolic links followed) without opening it.
pub fn check_regular(path: &Path) -> Result<u64, ModelError> {
    let ps = || path.display().to_string();
    let meta = std::fs::metadata(path).map_err(|source| ModelError::Io { path: ps(), source })?;
    if !meta.is_file() {
        return Err(ModelError::NotRegularFile { path: ps(), kind: kind_of(&meta.file_type()) });
    }
    Ok(meta.len())
}

/// Reads a regular file of at most `max_bytes` bytes as UTF-8 text.
pub fn read_regular(path: &Path, max_bytes: u64) -> Result<String, ModelError> {
    let ps = || path.display().to_string();
    let len = check_regular(path)?;
    if len > max_bytes {
        return Err(ModelError::FileTooLarge { path: ps(), bytes: len, limit: max_bytes });
    }
    let f = std::fs::File::open(path).map_err(|source| ModelError::Io { path: ps(), source })?;
    let mut bytes = Vec::with_capacity(len as usize);
    // a file that grows while it is read (or a /proc file reporting size 0) stops at the limit
    f.take(max_bytes + 1).read_to_end(&mut bytes).map_err(|source| ModelError::Io { path: ps(), source })?;
    if bytes.len() as u64 > max_bytes {
        return Err(ModelError::FileTooLarge { path: ps(), bytes: bytes.len() as u64, limit: max_bytes });
    }
    String::from_utf8(bytes).map_err(|e| ModelError::Io {
        path: ps(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidData, format!("not UTF-8 text ({e})")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directories_and_devices_are_refused_without_blocking() {
        let d = tempfile::tempdir().unwrap();
        assert!(matches!(read_regular(d.path(), 10), Err(ModelError::NotRegularFile { .. })));
        #[cfg(unix)]
        assert!(matches!(
            read_regular(Path::new("/dev/zero"), 10),
            Err(ModelError::NotRegularFile { kind: "a character device", .. })
        ));
        let f = d.path().join("big.txt");
        std::fs::write(&f, "0123456789ab").unwrap();
        assert!(matches!(read_regular(&f, 10), Err(ModelError::FileTooLarge { bytes: 12, limit: 10, .. })));
        assert_eq!(read_regular(&f, 12).unwrap(), "0123456789ab");
    }
}
