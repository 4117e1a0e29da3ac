//! Kineto-statics (placeholder, being written).
