//! Files written whole or not at all: under a temporary name beside the
//! file, renamed into place when complete. A failed or interrupted run
//! leaves no half-written file, and an existing file of the same name is
//! kept until the new one is complete. The file is on disk before it is
//! renamed; a long one is written back in parts as it grows (a thread
//! syncs what was written so far), so that the last wait is short.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporary files being written, for [`remove_unfinished`].
static UNFINISHED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn unfinished() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    UNFINISHED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary file not yet committed or dropped: for a
/// handler of Ctrl-C or SIGTERM that ends the process without unwinding.
pub fn remove_unfinished() {
    for p in unfinished().drain(..) {
        let _ = std::fs::remove_file(p);
    }
}

/// A file written under a temporary name beside `path` (`.NAME.PID.partial`)
/// and renamed into place by [`AtomicFile::commit`]; dropped without a
/// commit, it removes the temporary file.
///
/// ```
/// use std::io::Write;
/// let path = std::env::temp_dir().join(format!("atomic-doc-{}.txt", std::process::id()));
/// let mut f = shadow_scene::AtomicFile::create(&path).unwrap();
/// write!(f, "whole").unwrap();
/// assert!(!path.exists());
/// f.commit().unwrap();
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "whole");
/// std::fs::remove_file(&path).unwrap();
/// ```
#[derive(Debug)]
pub struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    file: Option<BufWriter<File>>,
    /// Bytes written so far, and how many of them the last write-back
    /// started on.
    written: u64,
    flushed: u64,
    /// The write-back to disk of the file's first part, on a thread of its
    /// own while the rest is written.
    writeback: Option<std::thread::JoinHandle<io::Result<()>>>,
}

/// Bytes written between two starts of a file's write-back to disk
/// ([`AtomicFile`]): the commit's own flush then waits for the last part
/// only (a 41 MB JSON of fragments waited 36 ms for all of it).
#[cfg(not(test))]
const WRITEBACK_STEP: u64 = 16 << 20;
#[cfg(test)]
const WRITEBACK_STEP: u64 = 64 << 10;

impl AtomicFile {
    /// Creates the temporary file for `path`.
    pub fn create(path: &Path) -> io::Result<AtomicFile> {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "output".into());
        let tmp = path.with_file_name(format!(".{name}.{}.partial", std::process::id()));
        let file = File::create(&tmp)?;
        unfinished().push(tmp.clone());
        Ok(AtomicFile {
            path: path.to_path_buf(),
            tmp,
            file: Some(BufWriter::with_capacity(1 << 20, file)),
            written: 0,
            flushed: 0,
            writeback: None,
        })
    }

    /// The file's name once committed.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn writer(&mut self) -> &mut BufWriter<File> {
        self.file.as_mut().expect("not committed yet")
    }

    /// Starts writing what reached the file so far back to disk, on a
    /// thread of its own, once the last such start is done and
    /// [`WRITEBACK_STEP`] bytes have been written since; its error, if
    /// any, is the commit's.
    fn start_writeback(&mut self) -> io::Result<()> {
        if self.written - self.flushed < WRITEBACK_STEP
            || self.writeback.as_ref().is_some_and(|h| !h.is_finished())
        {
            return Ok(());
        }
        self.finish_writeback()?;
        self.flushed = self.written;
        // (a handle or a thread that cannot be had leaves the work to the
        // commit)
        let Ok(file) = self.writer().get_ref().try_clone() else {
            return Ok(());
        };
        self.writeback = std::thread::Builder::new()
            .name("atomic-file-writeback".into())
            .spawn(move || file.sync_data())
            .ok();
        Ok(())
    }

    /// Waits for the write-back started last, with its outcome.
    fn finish_writeback(&mut self) -> io::Result<()> {
        match self.writeback.take().map(std::thread::JoinHandle::join) {
            None => Ok(()),
            Some(Ok(done)) => done,
            Some(Err(_)) => Err(io::Error::other("the write-back thread panicked")),
        }
    }

    /// Flushes the file to disk and renames it into place.
    pub fn commit(mut self) -> io::Result<()> {
        let file = self.file.take().expect("not committed yet");
        let done = file
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| self.finish_writeback().map(|()| f))
            .and_then(|f| f.sync_data())
            .and_then(|()| std::fs::rename(&self.tmp, &self.path));
        if done.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        unfinished().retain(|p| *p != self.tmp);
        done
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
            unfinished().retain(|p| *p != self.tmp);
        }
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.writer().write(buf)?;
        self.written += n as u64;
        self.start_writeback()?;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.writer().flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dropped_file_leaves_nothing_and_keeps_the_old_one() {
        let dir = std::env::temp_dir().join(format!("atomic-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.txt");
        std::fs::write(&path, "old").unwrap();
        {
            let mut f = AtomicFile::create(&path).unwrap();
            f.write_all(b"half").unwrap();
            assert!(unfinished().contains(&f.tmp));
        }
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        let mut f = AtomicFile::create(&path).unwrap();
        f.write_all(b"new").unwrap();
        let tmp = f.tmp.clone();
        f.commit().unwrap();
        assert!(!unfinished().contains(&tmp));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_long_file_is_written_back_in_parts_and_whole() {
        let dir = std::env::temp_dir().join(format!("atomic-long-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("long.txt");
        let line: Vec<u8> = (0..1000u32).map(|i| b'a' + (i % 26) as u8).collect();
        let mut f = AtomicFile::create(&path).unwrap();
        let mut starts = 0;
        for _ in 0..(5 * WRITEBACK_STEP as usize / line.len()) {
            f.write_all(&line).unwrap();
            starts += usize::from(f.writeback.is_some() && f.flushed == f.written);
        }
        assert!(starts >= 1, "no write-back started");
        let (written, tmp) = (f.written, f.tmp.clone());
        f.commit().unwrap();
        assert!(!tmp.exists());
        let back = std::fs::read(&path).unwrap();
        assert_eq!(back.len() as u64, written);
        assert!(back.chunks(line.len()).all(|c| c == &line[..]));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
