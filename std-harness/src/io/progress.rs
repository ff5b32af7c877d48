//! Progress on long work (a streamed frame's sheets, the reference, a chart's sweep): an
//! `indicatif` bar on standard error, drawn only when standard error is a terminal,
//! so logs, pipes and CI see nothing. The bar is cleared when the work ends or fails (on drop), so
//! the command's own output and its one-line error stay as they were.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// The bar's layout for steps of `unit`: `LABEL [=====>    ] n/N UNIT (eta)`.
fn template(unit: &str) -> String {
    format!("{{prefix}} [{{bar:30}}] {{pos}}/{{len}} {unit} ({{eta}})")
}

/// One bar: `LABEL [=====>    ] n/N UNIT (eta)`.
#[derive(Debug)]
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar for `total` steps of `unit` (e.g. "sheets"); hidden unless stderr is a terminal.
    pub fn new(label: &str, total: usize, unit: &str) -> Self {
        let target = if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(Some(total as u64), target);
        // The template's shape is fixed: it parses, or the unit test below fails.
        if let Ok(style) = ProgressStyle::with_template(&template(unit)) {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_prefix(label.to_string());
        Progress { bar }
    }

    /// Whether anything is drawn (stderr is a terminal).
    pub fn is_visible(&self) -> bool {
        !self.bar.is_hidden()
    }

    /// `done` steps finished.
    pub fn set(&self, done: usize) {
        self.bar.set_position(done as u64);
    }

    /// One more step finished.
    pub fn step(&self) {
        self.bar.inc(1);
    }

    /// Runs `f` (which prints) with the bar lifted off the terminal, so lines and bar do not mix.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        self.bar.suspend(f)
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// A `progress(done, total)` callback for `label`'s sheets (the reference renderer and the
/// streamed sheet loop report this way): a [`Progress`] made on the first call.
pub fn sheets(label: &'static str) -> impl FnMut(usize, usize) {
    let mut bar: Option<Progress> = None;
    move |done, total| {
        bar.get_or_insert_with(|| Progress::new(label, total, "sheets"))
            .set(done);
        if done >= total {
            bar = None; // cleared
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_template_parses_and_a_test_run_draws_nothing() {
        let p = Progress::new("render", 3, "sheets");
        assert!(!p.is_visible(), "cargo test's stderr is not a terminal");
        p.step();
        p.set(3);
        assert_eq!(p.bar.length(), Some(3));
        assert_eq!(p.bar.position(), 3);
        // The template `Progress::new` uses parses, for any unit it is given.
        for unit in ["sheets", "configurations"] {
            assert!(
                ProgressStyle::with_template(&template(unit)).is_ok(),
                "{unit}"
            );
        }
    }
}
