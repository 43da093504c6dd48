//! Long runs: a progress bar on stderr (only when stderr is a terminal,
//! not with `--quiet`, and only once a run has lasted about a second), and
//! output files written under a temporary name and renamed when complete,
//! so that an interrupted run leaves no half-written file.

use std::fs::File;
use std::io::{BufWriter, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Duration;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long a run may take before its progress shows.
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// A progress bar that stays hidden for the first second.
pub(crate) struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar drawn on stderr if `enabled` and stderr is a terminal.
    pub(crate) fn new(enabled: bool) -> Progress {
        let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("{msg:>14} [{elapsed_precise}] {wide_bar} {pos}/{len}")
                .expect("a valid template")
                .progress_chars("=> "),
        );
        if enabled && std::io::stderr().is_terminal() {
            let shown = bar.clone();
            std::thread::spawn(move || {
                std::thread::sleep(SHOW_AFTER);
                if !shown.is_finished() {
                    shown.set_draw_target(ProgressDrawTarget::stderr());
                    shown.enable_steady_tick(Duration::from_millis(200));
                }
            });
        }
        Progress { bar }
    }

    /// Starts a phase of `total` steps.
    pub(crate) fn phase(&self, name: &'static str, total: u64) {
        self.bar.set_message(name);
        self.bar.set_length(total);
        self.bar.set_position(0);
    }

    /// Advances the current phase.
    pub(crate) fn inc(&self, n: u64) {
        self.bar.inc(n);
    }

    /// Removes the bar.
    pub(crate) fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

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
}
