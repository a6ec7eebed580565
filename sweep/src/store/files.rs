//! The output directory's files: atomic writes (temporary file, sync, rename) and the advisory
//! lock that keeps two writers out of one directory.

use crate::error::SweepError;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// Writes `path` through `fill` into a temporary file in the same directory, synced, then
/// renamed into place; a failure removes the temporary file and leaves `path` as it was.
pub fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), SweepError> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let write = || -> std::io::Result<()> {
        let mut w = BufWriter::with_capacity(1 << 20, File::create(&tmp)?);
        fill(&mut w)?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, path)
    };
    write().map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        SweepError::io(path, e)
    })
}

/// The lock file of an output directory.
pub const LOCK: &str = ".cdpr-lock";

/// An advisory lock on an output directory, held while a run writes there: a second sweep,
/// merge or simulate into the same directory is refused before it starts, naming the holder
/// (two writers lost or mixed each other's files). The lock file is removed when the lock is
/// dropped, and the OS releases the lock of a process that dies.
pub struct DirLock {
    file: File,
    path: PathBuf,
}

impl DirLock {
    /// Takes the lock of `dir` for `what` (e.g. "sweep shard 0/2"), or says who holds it.
    pub fn acquire(dir: &Path, what: &str) -> Result<Self, SweepError> {
        let path = dir.join(LOCK);
        let io = |e| SweepError::io(&path, e);
        loop {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    let mut holder = String::new();
                    let _ = file.read_to_string(&mut holder);
                    return Err(SweepError::Busy {
                        dir: dir.display().to_string(),
                        holder: holder.trim().to_string(),
                    });
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(io(e)),
            }
            // The holder before us may have removed the file between our open and our lock:
            // then we hold a lock nobody else can see; take the lock of the file at the path.
            if !same_file(&file, &path) {
                continue;
            }
            file.set_len(0)
                .and_then(|_| {
                    file.write_all(format!("{what}, pid {}", std::process::id()).as_bytes())
                })
                .map_err(io)?;
            return Ok(Self { file, path });
        }
    }
}

impl Drop for DirLock {
    /// Removes the lock file while still holding the lock (see [`DirLock::acquire`]).
    fn drop(&mut self) {
        if same_file(&self.file, &self.path) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Whether `path` still names the open `file`.
fn same_file(file: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), std::fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (file, path);
        true
    }
}
