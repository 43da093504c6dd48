//! What every command writes: output files under a temporary name,
//! renamed into place when complete (an interrupted or failed run leaves
//! no half-written file), the report on stdout, the time of each phase,
//! and panics turned into errors that say they are bugs.

use std::io::Write;
use std::panic;
use std::path::Path;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow};
use shadow_scene::AtomicFile;

/// Removes the unfinished outputs when the user interrupts the run
/// (Ctrl-C) or it is told to stop (SIGTERM, as from `timeout`), then exits
/// with the conventional status 130.
pub(crate) fn clean_up_on_interrupt() {
    // a second installation (in tests) fails harmlessly
    let _ = ctrlc::set_handler(|| {
        shadow_scene::remove_unfinished();
        std::process::exit(130);
    });
}

/// An output file written whole or not at all ([`AtomicFile`]), its
/// errors naming it.
pub(crate) struct Output(AtomicFile);

impl Output {
    /// Creates the temporary file for `path`.
    pub(crate) fn create(path: &Path) -> Result<Output> {
        let f = AtomicFile::create(path)
            .with_context(|| format!("could not write {}", path.display()))?;
        Ok(Output(f))
    }

    /// Flushes the file and renames it into place.
    pub(crate) fn commit(self) -> Result<()> {
        let path = self.0.path().to_path_buf();
        self.0
            .commit()
            .with_context(|| format!("could not write {}", path.display()))
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
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

/// A note or warning on stderr, unless `quiet`.
pub(crate) fn note(quiet: bool, text: &str) {
    if !quiet {
        eprintln!("{text}");
    }
}

/// A duration in milliseconds.
pub(crate) fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Drops `value` on a thread of its own: a command's large structures (a
/// 100k-face scene's polygons take milliseconds to free, one by one) need
/// not hold up its exit, which returns the process's memory whole.
pub(crate) fn drop_in_background<T: Send + 'static>(value: T) {
    // (where no thread can be started, the value is dropped here)
    let _ = std::thread::Builder::new().spawn(move || drop(value));
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

/// Writes `path` whole or not at all.
pub(crate) fn write_file(path: &Path, contents: &[u8]) -> Result<()> {
    write_files(&[(path, contents)])
}

/// Writes every file whole, or none of them: each is written under its
/// temporary name first, and only when all are written are they renamed
/// into place.
pub(crate) fn write_files(files: &[(&Path, &[u8])]) -> Result<()> {
    let mut outs = Vec::with_capacity(files.len());
    for &(path, contents) in files {
        let mut o = Output::create(path)?;
        o.write_all(contents)
            .with_context(|| format!("could not write {}", path.display()))?;
        outs.push(o);
    }
    outs.into_iter().try_for_each(Output::commit)
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
