//! What a reproduction shows, from its [`evtac_experiments::results::Results`]: `report.md`
//! (tables with the paper's numbers beside ours, the values evtac chose, stage times),
//! `results.json` and the PNG figures ([`write()`]), and `evtac render`'s animations of a
//! recording ([`render`]). Both draw with one plotting stack ([`plots`]: the embedded font,
//! colours, canvases and charts), so a rendered frame is the report's Fig. 2 at another time.
//!
//! - [`write()`] and [`markdown()`]: the report's files and its Markdown, section by section (the
//!   learned-fusion verdicts in `markdown/fusion.rs`, the label check in `markdown/labels.rs`).
//! - [`plots`]: one figure family per submodule.
//! - [`render`]: frames of a recording as GIF, MP4 or PNG sheet.
//! - [`sensitivity`]: the sensitivity study's summary, table and tornado figure.
//!
//! The crate reads results; it runs nothing. `evtac reproduce` runs the pipeline
//! (`evtac-experiments`), then calls [`write()`].
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let text = std::fs::read_to_string("out/results.json")?;
//! let results: evtac_experiments::results::Results = serde_json::from_str(&text)?;
//! // report.md, results.json and figures/*.png in `out2`.
//! let figures = evtac_report::write("out2".as_ref(), &results)?;
//! println!("{} figures", figures.len());
//! # Ok(())
//! # }
//! ```

mod markdown;
pub mod plots;
pub mod render;
pub mod sensitivity;

pub use markdown::{
    CHOICES_TITLE, Error, FIGURES, PAPER_EXP2_STATIC, PAPER_TABLE, Verdict, exp1_stats,
    exp1_verdicts, markdown, write,
};
