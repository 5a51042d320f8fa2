//! Event representations: static (dv-processing-compatible exponential decay), dynamic
//! (sliding-window count) and combined (pixel-wise OR), 8x8-pooled to 900 features.
