//! The dataset manifest `trials.csv`: one row per trial with its conditions and phases.
