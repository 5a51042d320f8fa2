//! The one error type of `evtac-repr`: bad configurations, bad frames and bad input streams.

/// Everything that can go wrong while building representations.
///
/// Each message names the offending value and the limit it broke, so a caller can print it as is.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReprError {
    /// A configuration field is out of its valid range.
    #[error("invalid representation config: {field} = {value} ({reason})")]
    InvalidConfig {
        /// The field, e.g. `tau_ms`.
        field: &'static str,
        /// The value given, formatted.
        value: String,
        /// What the field must satisfy.
        reason: &'static str,
    },
    /// Pooling needs a frame whose width and height are multiples of the 8-pixel cell.
    #[error(
        "frame {width}x{height} cannot be pooled: width and height must be non-zero multiples of 8"
    )]
    FrameNotPoolable {
        /// Frame width in pixels.
        width: u16,
        /// Frame height in pixels.
        height: u16,
    },
    /// An event lies outside the frame (events must already be cropped to the frame).
    #[error(
        "event {index} at t={t} us lies outside the {width}x{height} frame (x={x}, y={y} must be smaller than width={width}, height={height})"
    )]
    EventOutOfFrame {
        /// Index of the event in the slice passed in.
        index: usize,
        /// Its timestamp in microseconds.
        t: i64,
        /// Its column.
        x: u16,
        /// Its row.
        y: u16,
        /// Frame width.
        width: u16,
        /// Frame height.
        height: u16,
    },
    /// Events must arrive in non-decreasing time order, across chunks too.
    #[error("event {index} is out of time order: t={t} us comes after an event at t={previous} us")]
    EventOutOfOrder {
        /// Index of the event in the slice passed in.
        index: usize,
        /// Its timestamp in microseconds.
        t: i64,
        /// The latest timestamp seen before it.
        previous: i64,
    },
    /// Sample times must be non-decreasing (also relative to prepared times).
    #[error("sample time {t} us is before the previous sample (or prepared) time {previous} us")]
    SampleTimeBackwards {
        /// The sample time asked for.
        t: i64,
        /// The previous sample (or prepared) time.
        previous: i64,
    },
    /// A mask's size differs from the frame it is applied to.
    #[error("mask is {mask_width}x{mask_height} but the frame is {width}x{height}")]
    MaskSize {
        /// Mask width.
        mask_width: u16,
        /// Mask height.
        mask_height: u16,
        /// Frame width.
        width: u16,
        /// Frame height.
        height: u16,
    },
    /// `push_with_roi` got a crop whose size differs from the extractor's frame.
    #[error("ROI is {roi_width}x{roi_height} but the extractor's frame is {width}x{height}")]
    RoiSize {
        /// ROI width.
        roi_width: u16,
        /// ROI height.
        roi_height: u16,
        /// Frame width.
        width: u16,
        /// Frame height.
        height: u16,
    },
    /// A buffer's length does not match the frame it describes.
    #[error("{what} has {len} values but a {width}x{height} frame needs {expected}")]
    BufferLength {
        /// What the buffer is, e.g. `mask pixels`.
        what: &'static str,
        /// Its length.
        len: usize,
        /// The length needed.
        expected: usize,
        /// Frame width.
        width: u16,
        /// Frame height.
        height: u16,
    },
    /// `FeatureExtractor::new_with_masks` got a different number of masks than configs.
    #[error("{masks} masks given for {configs} configs (give one per config, `None` for no mask)")]
    MaskCount {
        /// Number of masks given.
        masks: usize,
        /// Number of configs given.
        configs: usize,
    },
    /// `FeatureExtractor` needs at least one config.
    #[error("no representation config given (at least one is needed)")]
    NoConfig,
}
