//! Data simulators. [`closed_form`] uses sagcal's own catenary model (no model
//! mismatch: what the Cramer-Rao bound describes).
//! [`discretised`]: an independent check, elastic lumped-mass chains over swivelling pulleys.

pub mod closed_form;
pub mod discretised;
