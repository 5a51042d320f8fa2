//! The MLP contact-angle regressor: model, training loop, checkpoints, prediction and metrics.
