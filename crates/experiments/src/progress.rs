//! [`Progress`]: how the library reports a long run stage by stage (libraries never print; the
//! binary shows bars), and [`Quiet`], which shows nothing.

use crate::stage::Stage;

/// Progress of a long run, reported by the library and shown by the binary (libraries never
/// print). Every method has a do-nothing default.
pub trait Progress: Sync {
    /// `stage` starts with `total` units of work.
    fn stage(&self, stage: Stage, total: u64) {
        let _ = (stage, total);
    }
    /// `n` units of the current stage are done.
    fn advance(&self, n: u64) {
        let _ = n;
    }
    /// `n` units of the current stage were found done by an earlier run and skipped: they count
    /// as done, but took no time, so an ETA must not learn its pace from them.
    fn skipped(&self, n: u64) {
        self.advance(n);
    }
    /// One unit of the current stage is finished: found done by an earlier run when `skipped`
    /// ([`Progress::skipped`]), else done now ([`Progress::advance`]).
    fn finished(&self, skipped: bool) {
        if skipped {
            self.skipped(1)
        } else {
            self.advance(1)
        }
    }
    /// A one-line status message (e.g. the latest epoch's loss).
    fn message(&self, text: &str) {
        let _ = text;
    }
}

/// A [`Progress`] that shows nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Quiet;

impl Progress for Quiet {}
