//! Prophesee EVT 2.0 and EVT 3.0 raw files (with their `%` text header).
