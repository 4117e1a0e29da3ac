//! Data simulators. [`closed_form`] uses sagcal's own catenary model (no model
//! mismatch: what the Cramer-Rao bound describes).

pub mod closed_form;
