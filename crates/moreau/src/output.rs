//! Output files that are never left half-written: everything is written to a temporary file
//! in the destination directory and renamed into place only when complete.
use anyhow::{Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

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

/// A directory whose files appear all together or not at all: files are written into a
/// hidden staging directory next to `out` and moved into `out` by [`StagedDir::commit`].
/// Dropping without commit removes the staging directory.
pub struct StagedDir {
    out: PathBuf,
    stage: Option<tempfile::TempDir>,
}

impl StagedDir {
    pub fn new(out: &Path) -> Result<Self> {
        let parent = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create directory {}", parent.display()))?;
        let stage = tempfile::Builder::new()
            .prefix(".moreau-staging-")
            .tempdir_in(parent)
            .with_context(|| format!("cannot create a staging directory in {}", parent.display()))?;
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
        Ok(())
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
