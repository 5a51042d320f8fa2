//! The clock offset that best aligns the gyroscope with the robot's log (`evtac import --sync
//! imu`), for a rig without trigger wiring.
//!
//! The log commands a rate profile `c(t)`: each row's speed from its onset to its end, zero
//! during its stop and between motions (the accelerations the log does not describe are
//! symmetric about each edge, so they do not bias the fit). The gyroscope measures the rate's
//! magnitude `g(t) = |omega(t)|`. The offset `o` minimises `integral (g(t) - c(t - o))^2 dt`,
//! which, as long as every motion lies inside the recording, is the same as maximising the
//! correlation `C(o) = sum over rows of speed * integral of g over the row's motion moved by
//! o`: `integral g^2` and `integral c^2` do not depend on `o`. With the running integral of `g`
//! (linear between samples), `C` costs two lookups per motion, so the search is a coarse scan
//! over every offset that keeps the log inside the IMU's span, at a step shorter than any
//! motion (so the coarse best lies on the true peak), then scans ten times finer around the
//! best, down to [`FINEST_STEP_US`].
//!
//! A gyroscope bias moves that peak: in a ramp's first milliseconds `|ramp + bias|` is not
//! `|bias|` plus the ramp (it can even dip below `|bias|`), so `C` gets two maxima a few ms
//! either side of the true offset (2.6 ms off on a simulated session). A second search, within
//! 20 ms of the first, fits `|omega - bias|` instead, with each motion's bias taken from
//! the still segment before its onset that the labels take it from. The fit's residual, the RMS
//! of `g - c` over the log's span (bias included), says how well the log describes what the
//! gyroscope saw.
//!
//! The IMU is never held (it takes about 70 bytes a sample, 56 kB per second of session): the
//! fit reads it in passes, decoding the IMU packets only ([`imu_offset`]). A pass streams the
//! running integrals and evaluates them at the instants its scans ask for, in time order,
//! adding each offset's terms in the order the whole fit adds them, so the offset and the
//! residual are those of the IMU held whole ([`imu_offset_whole`]), bit for bit. What a pass
//! holds is a sum per offset it scans (the coarse scan's at most 200,001, one per 40 ms of the
//! time the recording runs past the log, not of its length) and, in the search without the
//! bias, the samples of the 150 ms bias windows it is in: nothing grows with the session but
//! the log itself. About seven passes: the IMU's span, the coarse scan, two for the four finer
//! scans (each pass also evaluates every offset the next scan could ask for), two for the
//! search without the bias, one for the residual.

use crate::robot_log::RobotLog;
use evtac_events::ImuSample;
use evtac_events::manifest::TrialMeta;
use evtac_labels::LabelConfig;
use evtac_labels::integration::{CumulativeTrapezoid, RunningTrapezoid};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};
use std::path::{Path, PathBuf};

/// The coarse scan's step, us: a tenth of the shortest motion the protocols command (20 deg
/// at 10 deg/s is 2 s; a stop cuts a motion into parts of at least 400 ms).
const COARSE_STEP_US: i64 = 40_000;

/// The most offsets the coarse scan tries; a longer slack between the log and the recording
/// makes the step longer.
const MAX_COARSE_STEPS: i64 = 200_000;

/// How far from the first fit the second, without the gyroscope's bias, looks, us: the first
/// is off by no more than the time a ramp takes to reach the bias (a few ms).
const REFINE_US: i64 = 20_000;

/// The last refinement's step, us.
pub const FINEST_STEP_US: i64 = 5;

/// Errors of an IMU synchronisation.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImuSyncError {
    /// The session could not be read.
    #[error(transparent)]
    Recording(#[from] evtac_formats::Error),
    /// The session has too few IMU samples to align anything.
    #[error(
        "{}: {samples} IMU sample(s): --sync imu aligns the gyroscope with the log (record the \
         IMU, or use --sync trigger or --clock-offset-us)",
        .session.display()
    )]
    NoImu {
        /// The session.
        session: PathBuf,
        /// Its IMU samples.
        samples: usize,
    },
    /// The log's motions span longer than the recording's IMU.
    #[error(
        "{}: its motions span {log_s:.3} s, longer than the {imu_s:.3} s of IMU in {}: the log \
         cannot lie inside the recording",
        .log.display(),
        .session.display()
    )]
    TooLong {
        /// The log.
        log: PathBuf,
        /// The session.
        session: PathBuf,
        /// The log's span, s.
        log_s: f64,
        /// The IMU's span, s.
        imu_s: f64,
    },
}

/// The offset found and how well it fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuFit {
    /// Recording time minus robot time, microseconds.
    pub offset_us: i64,
    /// RMS of the gyroscope's rate magnitude minus the commanded rate over the log's span at
    /// that offset, deg/s.
    pub residual_deg_s: f64,
}

/// The running integral of a series sampled at `(t_us, value)` (the labels' trapezoid, exact
/// for the series linear between samples, so the fit is smooth in the offset and not drawn to
/// the sample times), or `None` for an empty window, which contributes nothing. The callers'
/// times are sorted and deduplicated, so an empty window is the only error
/// [`CumulativeTrapezoid::new`] can give them.
struct Integral(Option<CumulativeTrapezoid>);

impl Integral {
    fn new(samples: &[(i64, f64)]) -> Self {
        let (t, y): (Vec<i64>, Vec<f64>) = samples.iter().copied().unzip();
        Self(CumulativeTrapezoid::new(&t, &y).ok())
    }

    /// The integral from `from` to `to` (flat outside the samples).
    fn between(&self, from: i64, to: i64) -> f64 {
        self.0.as_ref().map_or(0.0, |i| i.between(from, to))
    }
}

/// A piece of the commanded rate: `(from, to, speed)`, us on the robot's clock and deg/s.
type Piece = (i64, i64, f64);

/// The commanded rate's pieces.
fn commanded(log: &RobotLog) -> Vec<Piece> {
    log.rows
        .iter()
        .flat_map(|(_, t)| commanded_row(t))
        .collect()
}

/// One row's commanded rate: its speed from onset to end but during its stop.
fn commanded_row(t: &TrialMeta) -> Vec<Piece> {
    let v = t.speed_deg_s;
    match (t.stop_start_us, t.stop_end_us) {
        (Some(a), Some(b)) => vec![(t.motion_start_us, a, v), (b, t.motion_end_us, v)],
        _ => vec![(t.motion_start_us, t.motion_end_us, v)],
    }
}

/// `|w - bias|`, deg/s.
fn magnitude(w: [f64; 3], bias: [f64; 3]) -> f64 {
    let d: [f64; 3] = std::array::from_fn(|i| w[i] - bias[i]);
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// The offset in `[lo, hi]` where `f` is largest: a scan at `step`, then scans ten times finer
/// around the best, down to [`FINEST_STEP_US`].
fn search(f: &dyn Fn(i64) -> f64, lo: i64, hi: i64, step: i64) -> i64 {
    let steps = steps(step);
    let mut best = lo;
    for i in 0..steps.len() {
        let (from, to, step) = scan(&steps, i, best, (lo, hi));
        best = best_of(from, grid(from, to, step), f);
    }
    best
}

/// Scan `i` of [`search`] (`from`, `to`, `step`), after the best `best` of scan `i - 1`: the
/// whole of `[lo, hi]` at the coarsest step, then two of the previous steps either side of
/// the best at the next one.
fn scan(steps: &[i64], i: usize, best: i64, (lo, hi): (i64, i64)) -> (i64, i64, i64) {
    if i == 0 {
        (lo, hi, steps[0])
    } else {
        let wide = steps[i - 1];
        (
            (best - 2 * wide).max(lo),
            (best + 2 * wide).min(hi),
            steps[i],
        )
    }
}

/// Every IMU sample of the recording at `path`, in time order, one per timestamp (a sample
/// repeated across packets counted once).
pub fn read_imu(path: &Path) -> Result<Vec<evtac_events::ImuSample>, evtac_formats::Error> {
    let mut reader = evtac_formats::open(path)?;
    let mut samples = Vec::new();
    while let Some(chunk) = reader.next_chunk()? {
        samples.extend_from_slice(chunk.imu);
    }
    samples.sort_by_key(|s| s.t);
    samples.dedup_by_key(|s| s.t);
    Ok(samples)
}

/// Hands `visit` the samples of `chunk` that [`read_imu`] keeps, for a stream read in time
/// order: each after the last one seen (`last_t`), a sample repeated across packets once.
/// Whether they were in order: a sample going back in time is not handed out, and the caller
/// falls back to [`read_imu`], which sorts.
pub(crate) fn in_order(
    chunk: &[ImuSample],
    last_t: &mut Option<i64>,
    visit: &mut dyn FnMut(&ImuSample),
) -> bool {
    for s in chunk {
        match *last_t {
            Some(t) if s.t < t => return false,
            Some(t) if s.t == t => {}
            _ => {
                *last_t = Some(s.t);
                visit(s);
            }
        }
    }
    true
}

/// Where the fits may look: the offsets that keep the log inside the IMU's span, and the
/// log's own span (robot clock, us).
struct Bounds {
    lo: i64,
    hi: i64,
    log_from: i64,
    log_to: i64,
}

/// The [`Bounds`] of `log`'s `pieces` against the IMU `span` of `session`, or why there are
/// none (no IMU to speak of, an empty log, a log longer than the IMU).
fn bounds(
    session: &Path,
    log: &RobotLog,
    pieces: &[Piece],
    span: &Span,
) -> Result<Bounds, ImuSyncError> {
    let (Some(first), Some(last)) = (span.first, span.last) else {
        return Err(no_imu(session, 0));
    };
    let (Some(log_from), Some(log_to)) = (
        pieces.iter().map(|p| p.0).min(),
        pieces.iter().map(|p| p.1).max(),
    ) else {
        return Err(no_imu(session, span.samples));
    };
    if span.samples < 2 {
        return Err(no_imu(session, span.samples));
    }
    let (lo, hi) = (first - log_from, last - log_to);
    if lo > hi {
        return Err(ImuSyncError::TooLong {
            log: log.path.clone(),
            session: session.to_path_buf(),
            log_s: (log_to - log_from) as f64 * 1e-6,
            imu_s: (last - first) as f64 * 1e-6,
        });
    }
    Ok(Bounds {
        lo,
        hi,
        log_from,
        log_to,
    })
}

/// Each row's window for the search without the gyroscope's bias, the motion found at
/// offset `rough`: its bias taken where the labels take it, up to [`REFINE_US`] past its end.
fn rows(log: &RobotLog, rough: i64) -> Vec<Row> {
    let still = LabelConfig::default();
    log.rows
        .iter()
        .map(|(_, t)| {
            let onset = t.motion_start_us + rough;
            Row {
                bias_from: onset - still.still_lead_in_us(),
                bias_to: onset - still.bias_margin_us,
                end: t.motion_end_us + rough + REFINE_US,
                pieces: commanded_row(t),
            }
        })
        .collect()
}

/// Finds the offset of `log` (on the robot's clock) that best aligns its commanded rate with the
/// gyroscope of `session`, reading the IMU in passes (see the module docs); a session
/// whose IMU samples go back in time (several IMU streams) is read whole.
pub fn imu_offset(session: &Path, log: &RobotLog) -> Result<ImuFit, ImuSyncError> {
    match imu_offset_in_passes(session, log) {
        Ok(fit) => Ok(fit),
        Err(Stop::Failed(e)) => Err(e),
        Err(Stop::Unordered) => imu_offset_whole(session, log),
    }
}

/// Why a fit in passes stopped.
#[derive(Debug)]
enum Stop {
    /// An error to report.
    Failed(ImuSyncError),
    /// The IMU goes back in time: fit it whole instead.
    Unordered,
}

impl<E: Into<ImuSyncError>> From<E> for Stop {
    fn from(e: E) -> Self {
        Stop::Failed(e.into())
    }
}

/// What reads a pass's samples.
trait Sink {
    /// The next sample (in time order, one per timestamp).
    fn push(&mut self, s: &ImuSample);
    /// The samples have ended.
    fn finish(&mut self);
}

/// One pass over the IMU of `session` (decoding nothing else where the format allows),
/// handing every sample to every sink, then finishing them.
fn pass(session: &Path, sinks: &mut [&mut dyn Sink]) -> Result<(), Stop> {
    let mut reader = evtac_formats::open(session)?;
    reader.imu_only();
    let mut last_t = None;
    while let Some(chunk) = reader.next_chunk()? {
        let mut visit = |s: &ImuSample| sinks.iter_mut().for_each(|sink| sink.push(s));
        if !in_order(chunk.imu, &mut last_t, &mut visit) {
            return Err(Stop::Unordered);
        }
    }
    sinks.iter_mut().for_each(|sink| sink.finish());
    Ok(())
}

/// The IMU's first and last times and its samples (one per timestamp).
#[derive(Default)]
struct Span {
    first: Option<i64>,
    last: Option<i64>,
    samples: usize,
}

impl Sink for Span {
    fn push(&mut self, s: &ImuSample) {
        self.first.get_or_insert(s.t);
        self.last = Some(s.t);
        self.samples += 1;
    }

    fn finish(&mut self) {}
}

/// The neutral element `Iterator::sum` starts from (-0.0 in today's std), so that sums built
/// term by term are the whole fit's sums bit for bit.
fn zero() -> f64 {
    std::iter::empty::<f64>().sum()
}

/// Adds per-offset terms to per-offset sums in a fixed order (term `j` of every offset after
/// term `j - 1`), whatever order they complete in, as the whole fit's `.sum()` over its
/// pieces adds them. Terms that complete early wait (none do when the log's motions are in
/// time order and do not overlap).
struct OrderedSums {
    sums: Vec<f64>,
    next: Vec<usize>,
    waiting: HashMap<(usize, usize), f64>,
}

impl OrderedSums {
    fn new(offsets: usize) -> Self {
        Self {
            sums: vec![zero(); offsets],
            next: vec![0; offsets],
            waiting: HashMap::new(),
        }
    }

    /// Term `j` of offset `k`.
    fn add(&mut self, k: usize, j: usize, term: f64) {
        if j != self.next[k] {
            self.waiting.insert((k, j), term);
            return;
        }
        self.sums[k] += term;
        self.next[k] += 1;
        while let Some(term) = self.waiting.remove(&(k, self.next[k])) {
            self.sums[k] += term;
            self.next[k] += 1;
        }
    }
}

/// An instant where an integral is wanted: (time, offset index, piece index, whether the
/// piece's end), ordered by time.
type Query = (i64, usize, usize, bool);

/// The two ends' integrals of pieces moved by offsets, until both are known.
#[derive(Default)]
struct Ends(HashMap<(usize, usize), (Option<f64>, Option<f64>)>);

impl Ends {
    /// Records one end; both ends' values once the other is known.
    fn set(&mut self, k: usize, q: usize, end: bool, value: f64) -> Option<(f64, f64)> {
        let entry = self.0.entry((k, q)).or_default();
        if end {
            entry.1 = Some(value);
        } else {
            entry.0 = Some(value);
        }
        let (Some(a), Some(b)) = *entry else {
            return None;
        };
        self.0.remove(&(k, q));
        Some((a, b))
    }
}

/// `sum over pieces of v * integral of y over the piece moved by o` for each offset `o`, the
/// integral running from the session's first sample ([`Integral`] of every sample, streamed):
/// the correlation `C` for `y = |omega|`, and the integral of `g^2` with one piece.
struct Correlation<'a> {
    value: fn(&ImuSample) -> f64,
    pieces: &'a [Piece],
    /// The pieces' ends in time order: (time, piece, whether its end).
    ends: Vec<(i64, usize, bool)>,
    offsets: Vec<i64>,
    /// Each offset's next end to ask for, by time.
    queue: BinaryHeap<Reverse<(i64, usize)>>,
    cursor: Vec<usize>,
    integral: RunningTrapezoid,
    open: Ends,
    sums: OrderedSums,
}

impl<'a> Correlation<'a> {
    fn new(value: fn(&ImuSample) -> f64, pieces: &'a [Piece], offsets: Vec<i64>) -> Self {
        let mut ends: Vec<(i64, usize, bool)> = pieces
            .iter()
            .enumerate()
            .flat_map(|(j, &(a, b, _))| [(a, j, false), (b, j, true)])
            .collect();
        ends.sort_unstable();
        let queue = match ends.first() {
            Some(&(t, ..)) => offsets
                .iter()
                .enumerate()
                .map(|(k, &o)| Reverse((t + o, k)))
                .collect(),
            None => BinaryHeap::new(),
        };
        Self {
            value,
            pieces,
            cursor: vec![0; offsets.len()],
            sums: OrderedSums::new(offsets.len()),
            ends,
            offsets,
            queue,
            integral: RunningTrapezoid::default(),
            open: Ends::default(),
        }
    }

    /// Answers the queries before `next` (all of them at the end).
    fn answer(&mut self, next: Option<(i64, f64)>) {
        while let Some(&Reverse((t, k))) = self.queue.peek() {
            if next.is_some_and(|(tn, _)| t >= tn) {
                break;
            }
            self.queue.pop();
            let at = self.integral.at(t, next);
            let (_, j, end) = self.ends[self.cursor[k]];
            self.cursor[k] += 1;
            if let Some(&(te, ..)) = self.ends.get(self.cursor[k]) {
                self.queue.push(Reverse((te + self.offsets[k], k)));
            }
            if let Some((a, b)) = self.open.set(k, j, end, at) {
                self.sums.add(k, j, self.pieces[j].2 * (b - a));
            }
        }
    }

    /// The sums, by offset.
    fn values(&self) -> impl Iterator<Item = (i64, f64)> + '_ {
        self.offsets
            .iter()
            .copied()
            .zip(self.sums.sums.iter().copied())
    }
}

impl Sink for Correlation<'_> {
    fn push(&mut self, s: &ImuSample) {
        let y = (self.value)(s);
        self.answer(Some((s.t, y)));
        self.integral.push(s.t, y);
    }

    fn finish(&mut self) {
        self.answer(None);
    }
}

/// `|omega|`, deg/s.
fn rate(s: &ImuSample) -> f64 {
    magnitude(s.gyroscope.map(f64::from), [0.0; 3])
}

/// `|omega|^2`.
fn rate_squared(s: &ImuSample) -> f64 {
    let g = rate(s);
    g * g
}

/// One row of the log for the search without the gyroscope's bias: its window of samples
/// (from the bias's start to `end`), its bias's window, its pieces.
struct Row {
    bias_from: i64,
    bias_to: i64,
    end: i64,
    pieces: Vec<Piece>,
}

/// A row whose window the pass is in.
struct OpenRow {
    row: usize,
    /// The samples of the bias's window, until it is over.
    rest: Vec<ImuSample>,
    bias: Option<[f64; 3]>,
    integral: RunningTrapezoid,
    /// Its pieces' ends moved by every offset, in time order, and the next to answer.
    queries: Vec<Query>,
    next: usize,
    open: Ends,
    /// Each offset's terms, piece by piece.
    terms: Vec<f64>,
}

impl OpenRow {
    /// Answers the row's queries before `next`.
    fn answer(&mut self, next: Option<(i64, f64)>, rows: &[Row]) {
        let pieces = &rows[self.row].pieces;
        while let Some(&(t, k, q, end)) = self.queries.get(self.next) {
            if next.is_some_and(|(tn, _)| t >= tn) {
                break;
            }
            self.next += 1;
            if let Some((a, b)) = self.open.set(k, q, end, self.integral.at(t, next)) {
                self.terms[k * pieces.len() + q] = pieces[q].2 * (b - a);
            }
        }
    }

    /// A sample of the window once the bias is known.
    fn feed(&mut self, s: &ImuSample, rows: &[Row]) {
        let Some(bias) = self.bias else { return };
        let y = magnitude(s.gyroscope.map(f64::from), bias);
        self.answer(Some((s.t, y)), rows);
        self.integral.push(s.t, y);
    }

    /// The bias's window is over: its mean, as the whole fit takes it, then its samples.
    fn settle(&mut self, rows: &[Row]) {
        if self.bias.is_some() {
            return;
        }
        let rest = std::mem::take(&mut self.rest);
        self.bias = Some(std::array::from_fn(|i| {
            rest.iter().map(|s| f64::from(s.gyroscope[i])).sum::<f64>() / rest.len().max(1) as f64
        }));
        for s in &rest {
            self.feed(s, rows);
        }
    }
}

/// The search without each motion's bias, for a batch of offsets: each row's window is
/// integrated from its own start with its own bias, row by row as the pass reaches them (a
/// window's samples are held only for its bias's 150 ms).
struct Unbiased<'a> {
    rows: &'a [Row],
    /// Rows by window start, and the next to open.
    order: Vec<usize>,
    opened: usize,
    open: Vec<OpenRow>,
    offsets: Vec<i64>,
    sums: OrderedSums,
}

impl<'a> Unbiased<'a> {
    fn new(rows: &'a [Row], offsets: Vec<i64>) -> Self {
        let mut order: Vec<usize> = (0..rows.len()).collect();
        order.sort_by_key(|&r| (rows[r].bias_from, r));
        Self {
            rows,
            order,
            opened: 0,
            open: Vec::new(),
            sums: OrderedSums::new(offsets.len()),
            offsets,
        }
    }

    /// Opens the rows whose windows start at or before `t`.
    fn open_until(&mut self, t: i64) {
        while let Some(&r) = self.order.get(self.opened) {
            let row = &self.rows[r];
            if row.bias_from > t {
                break;
            }
            self.opened += 1;
            let mut queries: Vec<Query> = Vec::new();
            for (k, &o) in self.offsets.iter().enumerate() {
                for (q, &(a, b, _)) in row.pieces.iter().enumerate() {
                    queries.push((a + o, k, q, false));
                    queries.push((b + o, k, q, true));
                }
            }
            queries.sort_unstable();
            self.open.push(OpenRow {
                row: r,
                rest: Vec::new(),
                bias: None,
                integral: RunningTrapezoid::default(),
                queries,
                next: 0,
                open: Ends::default(),
                terms: vec![0.0; self.offsets.len() * row.pieces.len()],
            });
        }
    }

    /// Closes the open row at `i`: its last queries, then its terms into the sums.
    fn close(&mut self, i: usize) {
        let mut row = self.open.swap_remove(i);
        row.settle(self.rows);
        row.answer(None, self.rows);
        let n = self.rows[row.row].pieces.len();
        // Term `j` of an offset is piece `j - first` of row `row.row`, counting the pieces of
        // the rows before it.
        let first: usize = self.rows[..row.row].iter().map(|r| r.pieces.len()).sum();
        for k in 0..self.offsets.len() {
            for q in 0..n {
                self.sums.add(k, first + q, row.terms[k * n + q]);
            }
        }
    }
}

impl Sink for Unbiased<'_> {
    fn push(&mut self, s: &ImuSample) {
        self.open_until(s.t);
        let mut i = 0;
        while i < self.open.len() {
            let row = &mut self.open[i];
            let Row { bias_to, end, .. } = self.rows[row.row];
            if row.bias.is_none() && s.t <= bias_to {
                row.rest.push(*s);
            } else if s.t <= end {
                row.settle(self.rows);
                row.feed(s, self.rows);
            } else {
                self.close(i);
                continue;
            }
            i += 1;
        }
    }

    fn finish(&mut self) {
        self.open_until(i64::MAX);
        while !self.open.is_empty() {
            self.close(self.open.len() - 1);
        }
    }
}

/// The steps of [`search`]'s scans, coarsest first.
fn steps(step: i64) -> Vec<i64> {
    let mut step = step.max(FINEST_STEP_US);
    let mut steps = vec![step];
    while step > FINEST_STEP_US {
        step = (step / 10).max(FINEST_STEP_US);
        steps.push(step);
    }
    steps
}

/// The offsets from `from` to `to` at `step`.
fn grid(from: i64, to: i64, step: i64) -> impl Iterator<Item = i64> {
    std::iter::successors(Some(from), move |o| Some(o + step)).take_while(move |&o| o <= to)
}

/// The first offset of `from`'s scan where `value` is largest (`from` when none is larger
/// than minus infinity), as [`search`]'s scans choose.
fn best_of(from: i64, offsets: impl Iterator<Item = i64>, value: impl Fn(i64) -> f64) -> i64 {
    let mut best = (f64::NEG_INFINITY, from);
    for o in offsets {
        let c = value(o);
        if c > best.0 {
            best = (c, o);
        }
    }
    best.1
}

/// The most offsets of one scan whose next, finer scans are evaluated in the same pass (all
/// of those it could lead to: at most 41 scans of 41 offsets).
const AHEAD: usize = 64;

/// [`search`], evaluating the offsets in batches, one pass over the IMU each (`values`): the
/// same scans, in two passes per two finer scans (a scan's batch holds the next scan's offsets
/// for each of its own, so the next scan needs no pass of its own).
fn search_in_passes(
    values: &mut dyn FnMut(Vec<i64>) -> Result<HashMap<i64, f64>, Stop>,
    lo: i64,
    hi: i64,
    step: i64,
) -> Result<i64, Stop> {
    let steps = steps(step);
    let scan = |i: usize, best: i64| scan(&steps, i, best, (lo, hi));
    let (mut best, mut i) = (lo, 0);
    while i < steps.len() {
        let (from, to, step) = scan(i, best);
        let mut batch: Vec<i64> = grid(from, to, step).collect();
        let ahead = i + 1 < steps.len() && batch.len() <= AHEAD;
        if ahead {
            let next: Vec<i64> = batch
                .iter()
                .flat_map(|&o| {
                    let (from, to, step) = scan(i + 1, o);
                    grid(from, to, step)
                })
                .collect();
            batch.extend(next);
            batch.sort_unstable();
            batch.dedup();
        }
        let got = values(batch)?;
        let value = |o: i64| got.get(&o).copied().unwrap_or(f64::NAN);
        best = best_of(from, grid(from, to, step), value);
        i += 1;
        if ahead {
            let (from, to, step) = scan(i, best);
            best = best_of(from, grid(from, to, step), value);
            i += 1;
        }
    }
    Ok(best)
}

/// [`imu_offset_whole`]'s fit, reading the IMU in passes and holding none of it: one for its
/// span, one for the coarse scan (a sum per offset, at most [`MAX_COARSE_STEPS`]), two for
/// each two finer scans (the finer scans' offsets evaluated in the same pass as the scan
/// before them), the same again without the bias, and one for the residual. Each pass streams
/// the running integrals that [`Integral`] would hold whole and evaluates them where the
/// scans ask, in time order, adding the terms in the whole fit's order: the offset and the
/// residual are the whole fit's, bit for bit (tested against it).
fn imu_offset_in_passes(session: &Path, log: &RobotLog) -> Result<ImuFit, Stop> {
    let mut span = Span::default();
    pass(session, &mut [&mut span])?;
    let pieces = commanded(log);
    let Bounds {
        lo,
        hi,
        log_from,
        log_to,
    } = bounds(session, log, &pieces, &span)?;
    let mut correlation = |offsets: Vec<i64>| -> Result<HashMap<i64, f64>, Stop> {
        let mut c = Correlation::new(rate, &pieces, offsets);
        pass(session, &mut [&mut c])?;
        Ok(c.values().collect())
    };
    let step = COARSE_STEP_US.max((hi - lo) / MAX_COARSE_STEPS);
    let rough = search_in_passes(&mut correlation, lo, hi, step)?;
    // Again without each motion's gyroscope bias, taken where the labels take it.
    let rows = rows(log, rough);
    let mut unbiased = |offsets: Vec<i64>| -> Result<HashMap<i64, f64>, Stop> {
        let mut u = Unbiased::new(&rows, offsets);
        pass(session, &mut [&mut u])?;
        Ok(u.offsets.iter().copied().zip(u.sums.sums).collect())
    };
    let best = search_in_passes(
        &mut unbiased,
        (rough - REFINE_US).max(lo),
        (rough + REFINE_US).min(hi),
        REFINE_US / 20,
    )?;
    let mut c = Correlation::new(rate, &pieces, vec![best]);
    let whole_log = [(log_from, log_to, 1.0)];
    let mut g2 = Correlation::new(rate_squared, &whole_log, vec![best]);
    pass(session, &mut [&mut c, &mut g2])?;
    Ok(fit(
        &pieces,
        (log_from, log_to),
        best,
        c.sums.sums[0],
        g2.sums.sums[0],
    ))
}

/// The fit at offset `best`: its residual from the correlation there and the integral of
/// `g^2` over the log's span moved by it.
fn fit(pieces: &[Piece], (log_from, log_to): (i64, i64), best: i64, c: f64, g2: f64) -> ImuFit {
    let span = (log_to - log_from) as f64 * 1e-6;
    let c2: f64 = pieces
        .iter()
        .map(|&(a, b, v)| v * v * (b - a) as f64 * 1e-6)
        .sum();
    let sse = (g2 - 2.0 * c + c2).max(0.0);
    ImuFit {
        offset_us: best,
        residual_deg_s: (sse / span.max(1e-6)).sqrt(),
    }
}

/// The fit with the whole IMU in memory (about 70 bytes a sample, 56 kB per second of
/// session): what [`imu_offset`] computes in passes, read whole for a session whose IMU
/// samples go back in time, and the reference the passes are tested against.
pub fn imu_offset_whole(session: &Path, log: &RobotLog) -> Result<ImuFit, ImuSyncError> {
    let samples_3d = read_imu(session)?;
    let samples: Vec<(i64, f64)> = samples_3d
        .iter()
        .map(|s| (s.t, magnitude(s.gyroscope.map(f64::from), [0.0; 3])))
        .collect();
    let span = Span {
        first: samples.first().map(|s| s.0),
        last: samples.last().map(|s| s.0),
        samples: samples.len(),
    };
    let pieces = commanded(log);
    let within = bounds(session, log, &pieces, &span)?;
    let (lo, hi, log_span) = (within.lo, within.hi, (within.log_from, within.log_to));
    let rate = Integral::new(&samples);
    let correlation = |o: i64| -> f64 {
        pieces
            .iter()
            .map(|&(a, b, v)| v * rate.between(a + o, b + o))
            .sum()
    };
    let step = COARSE_STEP_US.max((hi - lo) / MAX_COARSE_STEPS);
    let rough = search(&correlation, lo, hi, step);
    // Again without each motion's gyroscope bias, taken where the labels take it.
    let rows: Vec<(Integral, Vec<Piece>)> = rows(log, rough)
        .into_iter()
        .map(|row| {
            let around = &samples_3d[samples_3d.partition_point(|s| s.t < row.bias_from)
                ..samples_3d.partition_point(|s| s.t <= row.end)];
            let rest: Vec<_> = around.iter().filter(|s| s.t <= row.bias_to).collect();
            let bias: [f64; 3] = std::array::from_fn(|i| {
                rest.iter().map(|s| f64::from(s.gyroscope[i])).sum::<f64>()
                    / rest.len().max(1) as f64
            });
            let magnitudes: Vec<(i64, f64)> = around
                .iter()
                .map(|s| (s.t, magnitude(s.gyroscope.map(f64::from), bias)))
                .collect();
            (Integral::new(&magnitudes), row.pieces)
        })
        .collect();
    let unbiased = |o: i64| -> f64 {
        rows.iter()
            .flat_map(|(rate, pieces)| {
                pieces
                    .iter()
                    .map(move |&(a, b, v)| v * rate.between(a + o, b + o))
            })
            .sum()
    };
    let best = search(
        &unbiased,
        (rough - REFINE_US).max(lo),
        (rough + REFINE_US).min(hi),
        REFINE_US / 20,
    );
    let squares: Vec<(i64, f64)> = samples.iter().map(|&(t, g)| (t, g * g)).collect();
    let g2 = Integral::new(&squares).between(log_span.0 + best, log_span.1 + best);
    let c = correlation(best);
    Ok(fit(&pieces, log_span, best, c, g2))
}

fn no_imu(session: &Path, samples: usize) -> ImuSyncError {
    ImuSyncError::NoImu {
        session: session.to_path_buf(),
        samples,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_events::Resolution;
    use evtac_formats::EventWriter;

    /// A deterministic pseudo-random stream in [0, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A session of `rows` trapezoidal motions (some with a stop) `offset` after a log listing
    /// them in `order`, sampled every 1250 us with jitter, a bias and noise, written in packets
    /// of uneven sizes with a sample repeated across some of them; `lead_s` of IMU before the
    /// log and after it.
    fn session(dir: &Path, seed: u64, rows: usize, lead_s: i64, reversed: bool) -> RobotLog {
        let mut state = seed.max(1);
        let mut motions = Vec::new();
        let mut t = lead_s * 1_000_000;
        for k in 0..rows {
            let speed = [2.0, 4.0, 10.0][k % 3];
            let start = t + (uniform(&mut state) * 2e6) as i64 + 500_000;
            let end = start + (20.0 / speed * 1e6) as i64;
            let stop = (k % 2 == 1).then(|| {
                let a = start + (end - start) / 3;
                (a, a + 500_000)
            });
            let end = end + stop.map_or(0, |(a, b)| b - a);
            motions.push((start, end, stop, speed));
            t = end;
        }
        let mut text = String::from(
            "trial,direction_deg,speed_deg_s,depth_mm,total_deg,motion_start_us,motion_end_us,\
             stop_start_us,stop_end_us,stop_deg\n",
        );
        let mut listed: Vec<usize> = (0..rows).collect();
        if reversed {
            listed.reverse();
        }
        for &k in &listed {
            let (start, end, stop, speed) = motions[k];
            let (a, b) = stop.map_or((String::new(), String::new()), |(a, b)| {
                (a.to_string(), b.to_string())
            });
            let stop_deg = if stop.is_some() { "6.5" } else { "" };
            text += &format!("m{k},0,{speed},1.5,20,{start},{end},{a},{b},{stop_deg}\n");
        }
        let log_path = dir.join(format!("log{seed}.csv"));
        std::fs::write(&log_path, text).unwrap();
        let log = RobotLog::read(&log_path, 0).unwrap();
        let offset = 1_234_567 + seed as i64 * 1013;
        let rate = |t: i64| -> f64 {
            let t = t - offset;
            let ramp = |x: i64| (x as f64 * 1e-6 * 200.0).clamp(0.0, 1.0);
            motions
                .iter()
                .map(|&(a, b, stop, v)| {
                    let moving = ramp(t - a).min(ramp(b - t));
                    let held = stop.map_or(1.0, |(p, q)| 1.0 - ramp(t - p).min(ramp(q - t)));
                    v * moving * held
                })
                .sum()
        };
        let span = t + 2 * lead_s * 1_000_000;
        let mut imu = Vec::new();
        let mut ts = 0;
        while ts < span + offset {
            let noise = uniform(&mut state) - 0.5;
            imu.push(ImuSample {
                t: ts,
                gyroscope: [0.3 + 0.1 * noise as f32, rate(ts) as f32, -0.2],
                ..ImuSample::default()
            });
            ts += 1250 + (uniform(&mut state) * 40.0) as i64 - 20;
        }
        let path = dir.join(format!("s{seed}.aedat4"));
        let mut w = EventWriter::create(&path, Some(Resolution::new(640, 480)), None).unwrap();
        let mut i = 0;
        while i < imu.len() {
            let j = (i + 37 + (uniform(&mut state) * 3000.0) as usize).min(imu.len());
            // Every other packet repeats the last sample of the one before it.
            let from = if i > 0 && j % 2 == 0 { i - 1 } else { i };
            w.write_imu(&imu[from..j]).unwrap();
            i = j;
        }
        w.finish().unwrap();
        log
    }

    /// The fit in passes is the whole fit, offset and residual bit for bit: logs in and out of
    /// time order, with stops, a slack short enough for the coarse scan to look ahead and long
    /// enough not to, samples repeated across packets.
    #[test]
    fn the_fit_in_passes_is_the_whole_fit_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        for (seed, rows, lead_s, reversed) in [
            (1, 3, 1, false),
            (2, 5, 4, true),
            (3, 4, 0, true),
            (4, 6, 3, false),
        ] {
            let log = session(dir.path(), seed, rows, lead_s, reversed);
            let path = dir.path().join(format!("s{seed}.aedat4"));
            let whole = imu_offset_whole(&path, &log).unwrap();
            let passes = imu_offset_in_passes(&path, &log).unwrap();
            assert_eq!(passes.offset_us, whole.offset_us, "seed {seed}");
            assert_eq!(
                passes.residual_deg_s.to_bits(),
                whole.residual_deg_s.to_bits(),
                "seed {seed}: {passes:?} {whole:?}"
            );
            assert_eq!(imu_offset(&path, &log).unwrap(), whole);
            let truth = 1_234_567 + seed as i64 * 1013;
            assert!((whole.offset_us - truth).abs() < 1000, "{whole:?} {truth}");
        }
    }

    /// Samples going back in time stop a pass (the fit then reads the IMU whole); repeated
    /// ones are handed out once.
    #[test]
    fn a_pass_hands_out_samples_in_order_once() {
        let at = |t| ImuSample {
            t,
            ..ImuSample::default()
        };
        let mut last = None;
        let mut seen = Vec::new();
        let mut visit = |s: &ImuSample| seen.push(s.t);
        assert!(in_order(&[at(1), at(2), at(2)], &mut last, &mut visit));
        assert!(in_order(&[at(2), at(5)], &mut last, &mut visit));
        assert!(!in_order(&[at(6), at(4)], &mut last, &mut visit));
        assert_eq!(seen, [1, 2, 5, 6]);
    }

    /// A session whose gyroscope turns at each motion's trapezoidal rate (200 deg/s^2 ramps)
    /// `offset` after the log says, plus a bias; the fit finds the offset.
    #[test]
    fn finds_the_offset_of_trapezoids_under_a_bias() {
        let dir = tempfile::tempdir().unwrap();
        let log_path = dir.path().join("log.csv");
        let text = "trial,direction_deg,speed_deg_s,depth_mm,total_deg,motion_start_us,\
                    motion_end_us\na,0,10,1.5,20,1000000,3050000\nb,0,4,1.5,20,5000000,10020000\n";
        std::fs::write(&log_path, text).unwrap();
        let log = RobotLog::read(&log_path, 0).unwrap();
        let offset = 1_234_567;
        let rate = |t: i64| -> f64 {
            let t = t - offset;
            let trapezoid = |a: i64, b: i64, v: f64| {
                let ramp = v / 200.0;
                let (x, y) = ((t - a) as f64 * 1e-6, (b - t) as f64 * 1e-6);
                if x < 0.0 || y < 0.0 {
                    0.0
                } else {
                    v * (x / ramp).min(y / ramp).min(1.0)
                }
            };
            trapezoid(1_000_000, 3_050_000, 10.0) + trapezoid(5_000_000, 10_020_000, 4.0)
        };
        let imu: Vec<ImuSample> = (0..16_000)
            .map(|k| {
                let t = k * 1250;
                ImuSample {
                    t,
                    gyroscope: [0.3, rate(t) as f32, -0.2],
                    ..ImuSample::default()
                }
            })
            .collect();
        let session = dir.path().join("s.aedat4");
        let mut w = EventWriter::create(&session, Some(Resolution::new(640, 480)), None).unwrap();
        w.write_imu(&imu).unwrap();
        w.finish().unwrap();
        let fit = imu_offset(&session, &log).unwrap();
        // Within a fifth of the 1250 us sample period: the samples' phase at the edges (the
        // same at every edge here) is what is left.
        assert!((fit.offset_us - offset).abs() <= 250, "{fit:?}");
        assert!(fit.residual_deg_s < 1.0, "{fit:?}");

        // A log longer than the recording cannot fit.
        let long = RobotLog::parse(
            &text.replace("10020000", "30000000"),
            Path::new("log.csv"),
            0,
        )
        .unwrap();
        let err = imu_offset(&session, &long).unwrap_err().to_string();
        // Nor can a session without IMU.
        let silent = dir.path().join("silent.aedat4");
        EventWriter::create(&silent, Some(Resolution::new(640, 480)), None)
            .unwrap()
            .finish()
            .unwrap();
        let none = imu_offset(&silent, &log).unwrap_err().to_string();
        assert!(none.contains("silent.aedat4: 0 IMU sample(s)"), "{none}");
        assert!(
            err.starts_with("log.csv: its motions span 29.000 s, longer than the 19.999"),
            "{err}"
        );
    }
}
