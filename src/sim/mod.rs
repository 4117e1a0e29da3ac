//! Data simulators. [`closed_form`] uses sagcal's own catenary model (no model
//! mismatch: what the Cramer-Rao bound describes).
//! [`discretised`]: an independent check, elastic lumped-mass chains over swivelling pulleys.
//! [`effects`]: data with effects the closed-form model lacks, through [`discretised`].

pub mod closed_form;
pub mod discretised;
pub mod effects;
