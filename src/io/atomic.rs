//! Output files that appear whole or not at all.
//!
//! Everything is written to a temporary file next to the target (same directory, hence same file
//! system, so the final rename is atomic), synced to disk, then renamed over the target. A run that
//! fails or is interrupted leaves the previous output untouched and no half-written file behind.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `contents` to `path` atomically, creating missing parent directories.
pub fn write_atomically(path: &Path, contents: &[u8]) -> io::Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(contents).map_err(|e| with_path(path, e))?;
    file.commit()
}

/// A file being written: [`AtomicFile::commit`] puts it in place; dropping it uncommitted deletes
/// what was written and leaves any existing file at the target as it was.
pub struct AtomicFile {
    target: PathBuf,
    temp: PathBuf,
    /// `None` once committed or abandoned.
    writer: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Starts writing `path`, creating missing parent directories.
    pub fn create(path: &Path) -> io::Result<Self> {
        let name = path.file_name().ok_or_else(|| {
            with_path(
                path,
                io::Error::new(io::ErrorKind::InvalidInput, "not a file name"),
            )
        })?;
        let dir = match path.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&dir).map_err(|e| with_path(&dir, e))?;

        // The process id and a counter keep concurrent writers (threads, several runs) apart;
        // create_new refuses to reuse a stale file from a crashed run.
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let mut attempts = 0;
        loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let mut temp_name = std::ffi::OsString::from(".");
            temp_name.push(name);
            temp_name.push(format!(".{}.{n}.tmp", std::process::id()));
            let temp = dir.join(temp_name);
            match OpenOptions::new().write(true).create_new(true).open(&temp) {
                Ok(file) => {
                    return Ok(Self {
                        target: path.to_path_buf(),
                        temp,
                        writer: Some(BufWriter::new(file)),
                    });
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists && attempts < 100 => {
                    attempts += 1;
                }
                Err(e) => return Err(with_path(&temp, e)),
            }
        }
    }

    /// Where the file will appear on commit.
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// Flushes, syncs and renames the file into place.
    pub fn commit(mut self) -> io::Result<()> {
        let Some(writer) = self.writer.take() else {
            return Err(with_path(
                &self.target,
                io::Error::other("already committed"),
            ));
        };
        let placed = writer
            .into_inner()
            .map_err(|e| with_path(&self.temp, e.into_error()))
            .and_then(|file| {
                // Without the sync, a crash right after the rename can leave an empty target on
                // some file systems: the rename reaches the disk before the data.
                file.sync_all().map_err(|e| with_path(&self.temp, e))
            })
            .and_then(|()| {
                std::fs::rename(&self.temp, &self.target).map_err(|e| with_path(&self.target, e))
            });
        if placed.is_err() {
            let _ = std::fs::remove_file(&self.temp);
        } else {
            sync_parent(&self.target);
        }
        placed
    }

    fn writer(&mut self) -> io::Result<&mut BufWriter<File>> {
        self.writer
            .as_mut()
            .ok_or_else(|| with_path(&self.target, io::Error::other("written after commit")))
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.writer()?.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.writer()?.write_all(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.writer()?.flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if let Some(writer) = self.writer.take() {
            // Nothing useful can be done with an error here: the output is being abandoned.
            drop(writer.into_parts());
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

/// Makes the rename itself durable. Best effort: some file systems refuse to sync a directory, and
/// the data is already safe in the renamed file.
fn sync_parent(path: &Path) {
    #[cfg(unix)]
    if let Some(dir) = path.parent() {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = path;
}

/// An I/O error that says which file it is about: the bare OS message ("Permission denied") does
/// not.
pub(crate) fn with_path(path: &Path, err: io::Error) -> io::Error {
    io::Error::new(err.kind(), format!("{}: {err}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("motorcal-atomic-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn commit_replaces_the_file_and_creates_directories() {
        let dir = scratch("commit");
        let path = dir.join("nested/out.txt");
        write_atomically(&path, b"old").unwrap();
        let mut f = AtomicFile::create(&path).unwrap();
        f.write_all(b"new contents").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        f.commit().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new contents");
        assert_eq!(entries(&dir.join("nested")), ["out.txt"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn dropping_uncommitted_keeps_the_old_file_and_no_temp() {
        let dir = scratch("drop");
        let path = dir.join("out.txt");
        write_atomically(&path, b"good").unwrap();
        {
            let mut f = AtomicFile::create(&path).unwrap();
            f.write_all(&[b'x'; 100_000]).unwrap();
        }
        assert_eq!(std::fs::read(&path).unwrap(), b"good");
        assert_eq!(entries(&dir), ["out.txt"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn errors_name_the_path() {
        let dir = scratch("errors");
        std::fs::create_dir_all(&dir).unwrap();
        let blocker = dir.join("file");
        std::fs::write(&blocker, b"").unwrap();
        // A regular file where a directory is needed.
        let err = write_atomically(&blocker.join("out.txt"), b"x").unwrap_err();
        assert!(err.to_string().contains("file"), "{err}");
        assert!(AtomicFile::create(Path::new("/")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
