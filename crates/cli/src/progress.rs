//! Progress bars on stderr, shown only when stderr is a terminal (so logs and CI stay clean).

use evtac_experiments::progress::Progress;
use evtac_experiments::stage::Stage;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// A progress bar over `len` units of `unit` (e.g. "bytes", "trials"), hidden when stderr is not
/// a terminal.
pub fn bar(len: u64, message: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if !std::io::stderr().is_terminal() {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    bar.set_style(
        ProgressStyle::with_template(
            "{msg:>12} [{elapsed_precise}] {wide_bar} {pos}/{len} (eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(message.to_string());
    bar
}

/// A byte-counting progress bar for reading a file of `len` bytes.
pub fn bytes(len: u64, message: &str) -> ProgressBar {
    let bar = bar(len, message);
    bar.set_style(
        ProgressStyle::with_template(
            "{msg:>12} [{elapsed_precise}] {wide_bar} {bytes}/{total_bytes} ({bytes_per_sec}, eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// A group of bars drawn together on stderr, hidden when stderr is not a terminal.
pub fn multi() -> MultiProgress {
    if std::io::stderr().is_terminal() {
        MultiProgress::new()
    } else {
        MultiProgress::with_draw_target(ProgressDrawTarget::hidden())
    }
}

/// Progress bars for library stages: one bar per stage, replaced when the next starts, plus any
/// bars added with [`Bars::add`] (drawn together, hidden when stderr is not a terminal).
pub struct Bars {
    multi: indicatif::MultiProgress,
    bar: std::sync::Mutex<Option<indicatif::ProgressBar>>,
}

impl Default for Bars {
    fn default() -> Self {
        Self {
            multi: multi(),
            bar: std::sync::Mutex::new(None),
        }
    }
}

impl Progress for Bars {
    fn stage(&self, stage: Stage, total: u64) {
        if let Ok(mut b) = self.bar.lock() {
            if let Some(old) = b.take() {
                old.finish_and_clear();
                self.multi.remove(&old);
            }
            let name = stage.to_string();
            *b = Some(self.multi.add(bar(total, &name)));
        }
    }
    fn advance(&self, n: u64) {
        if let Ok(b) = self.bar.lock()
            && let Some(b) = b.as_ref()
        {
            b.inc(n);
        }
    }
    fn message(&self, text: &str) {
        self.multi.suspend(|| eprintln!("{text}"));
    }
}

impl Bars {
    /// Draws `bar` with the stage bars (e.g. an overall one).
    pub fn add(&self, bar: indicatif::ProgressBar) -> indicatif::ProgressBar {
        self.multi.add(bar)
    }

    /// Clears the bars.
    pub fn finish(&self) {
        if let Ok(mut b) = self.bar.lock()
            && let Some(old) = b.take()
        {
            old.finish_and_clear();
        }
        let _ = self.multi.clear();
    }
}
