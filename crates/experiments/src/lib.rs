//! Datasets, splits, sampling, feature caches, the paper's experiments and the report.
