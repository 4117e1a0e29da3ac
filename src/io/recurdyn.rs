//! Loader for the RecurDyn finite-element log (placeholder, being written).
