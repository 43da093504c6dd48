//! What every command writes: output files under a temporary name,
//! renamed into place when complete (an interrupted or failed run leaves
//! no half-written file), the report on stdout, the time of each phase,
//! and panics turned into errors that say they are bugs.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::panic;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow};

/// The temporary file being written, removed if the run is interrupted.
static PARTIAL: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Removes the partial output (if any) when the user interrupts the run,
/// then exits with the conventional status 130.
pub(crate) fn clean_up_on_interrupt() {
    // a second installation (in tests) fails harmlessly
    let _ = ctrlc::set_handler(|| {
        if let Some(p) = PARTIAL.lock().unwrap_or_else(|e| e.into_inner()).take() {
            let _ = std::fs::remove_file(p);
        }
        std::process::exit(130);
    });
}

/// An output file written under a temporary name beside it and renamed
/// into place by [`Output::commit`]; dropped without a commit, it removes
/// the temporary file.
pub(crate) struct Output {
    path: PathBuf,
    tmp: PathBuf,
    file: Option<BufWriter<File>>,
}

impl Output {
    /// Creates the temporary file for `path`.
    pub(crate) fn create(path: &Path) -> Result<Output> {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "output".into());
        let tmp = path.with_file_name(format!(".{name}.{}.partial", std::process::id()));
        let file =
            File::create(&tmp).with_context(|| format!("could not write {}", path.display()))?;
        *PARTIAL.lock().unwrap_or_else(|e| e.into_inner()) = Some(tmp.clone());
        Ok(Output {
            path: path.to_path_buf(),
            tmp,
            file: Some(BufWriter::with_capacity(1 << 20, file)),
        })
    }

    /// The writer.
    pub(crate) fn writer(&mut self) -> &mut BufWriter<File> {
        self.file.as_mut().expect("not committed yet")
    }

    /// Flushes the file and renames it into place.
    pub(crate) fn commit(mut self) -> Result<()> {
        let ctx = || format!("could not write {}", self.path.display());
        let file = self.file.take().expect("not committed yet");
        file.into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_data())
            .with_context(ctx)?;
        std::fs::rename(&self.tmp, &self.path).with_context(ctx)?;
        PARTIAL.lock().unwrap_or_else(|e| e.into_inner()).take();
        Ok(())
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
            PARTIAL.lock().unwrap_or_else(|e| e.into_inner()).take();
        }
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer().write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.writer().flush()
    }
}

/// Wall time of each phase, in order.
#[derive(Default)]
pub(crate) struct Phases(pub(crate) Vec<(&'static str, Duration)>);

impl Phases {
    /// Runs `f`, its time added to phase `name` (a new phase the first
    /// time).
    pub(crate) fn run<T>(&mut self, name: &'static str, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        self.add(name, start.elapsed());
        out
    }

    /// `t` added to phase `name` (a new phase the first time).
    pub(crate) fn add(&mut self, name: &'static str, t: Duration) {
        match self.0.iter_mut().find(|(n, _)| *n == name) {
            Some((_, d)) => *d += t,
            None => self.0.push((name, t)),
        }
    }
}

/// Runs `f`, turning a panic into an error that says it is a bug (the
/// kernel panics only on broken internal invariants) and asks for a
/// report with `inputs`.
pub(crate) fn guarded<T>(inputs: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
    static LAST: Mutex<Option<String>> = Mutex::new(None);
    let previous = panic::take_hook();
    panic::set_hook(Box::new(|info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "(no message)".to_string());
        let at = info
            .location()
            .map(|l| format!(" ({}:{})", l.file(), l.line()))
            .unwrap_or_default();
        *LAST.lock().unwrap_or_else(|e| e.into_inner()) = Some(format!("{message}{at}"));
    }));
    let result = panic::catch_unwind(panic::AssertUnwindSafe(f));
    panic::set_hook(previous);
    result.unwrap_or_else(|_| {
        let detail = LAST
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take()
            .unwrap_or_default();
        Err(anyhow!(
            "internal error: {detail}; this is a bug, not a problem with the input, and nothing \
             was written — please report it with {inputs}"
        ))
    })
}

/// Writes to stdout; a closed pipe (`shadow csg ... --stats | head`) is
/// not an error.
pub(crate) fn emit(text: &str) -> Result<()> {
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
    {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(e).context("could not write to stdout")
        }
        _ => Ok(()),
    }
}

/// Writes `contents` to `path` through an [`Output`].
pub(crate) fn write_file(path: &Path, contents: &[u8]) -> Result<()> {
    let mut o = Output::create(path)?;
    o.write_all(contents)
        .with_context(|| format!("could not write {}", path.display()))?;
    o.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_appears_only_when_committed() {
        let dir = std::env::temp_dir().join(format!("shadow-out-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.json");
        let _ = std::fs::remove_file(&path);
        {
            let mut o = Output::create(&path).unwrap();
            o.write_all(b"half").unwrap();
            // dropped: nothing is left, not even the temporary file
        }
        assert!(!path.exists());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        let mut o = Output::create(&path).unwrap();
        o.write_all(b"whole").unwrap();
        o.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "whole");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn guarded_turns_a_panic_into_an_error() {
        let e = guarded("both input files", || -> Result<()> {
            panic!("inconsistent sub-hyperplanes")
        })
        .unwrap_err();
        let s = e.to_string();
        assert!(
            s.starts_with("internal error: inconsistent sub-hyperplanes ("),
            "{s}"
        );
        assert!(s.contains("output.rs:"), "{s}");
        assert!(s.ends_with("please report it with both input files"), "{s}");
        assert_eq!(guarded("x", || Ok(7)).unwrap(), 7);
    }
}
