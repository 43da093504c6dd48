//! Long runs: a progress bar on stderr (only when stderr is a terminal,
//! not with `--quiet`, and only once a run has lasted about a second).

use std::io::IsTerminal;
use std::time::Duration;

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
}

impl bsp_shadows::shadow_file::Progress for Progress {
    fn phase(&self, name: &'static str, steps: u64) {
        Progress::phase(self, name, steps);
    }
    fn advance(&self, steps: u64) {
        self.inc(steps);
    }
}

/// Dropping the bar removes it (before the report is printed, where a
/// command drops it on purpose).
impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
