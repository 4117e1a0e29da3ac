//! A linear system kept for the next solve of a graph with the same
//! structure.
//!
//! [`LinearSystem::new`] (the pattern of `H`, the elimination's layout, each
//! factor's runs) depends only on the graph's structure: the variables'
//! tangent dimensions and whether each is fixed, every factor's variable
//! list, and the local groups. A calibration solves several graphs of one
//! structure (its stages, then the covariance at the solution), so it keeps
//! the system in a [`SystemCache`]: a graph whose structure key equals the
//! kept one's gets that system back (its numeric factorisation is redone by
//! every solve, so nothing numeric carries over); any other graph gets a new
//! one. Results are bit for bit those of a fresh system (test).

use super::linear_system::LinearSystem;
use crate::error::SolverError;
use crate::graph::{Factor, Values, VariableId};

/// At most one linear system and the structure it was built for.
#[derive(Default)]
pub struct SystemCache {
    kept: Option<(Vec<usize>, LinearSystem)>,
}

impl SystemCache {
    /// The system for this structure: the kept one if it was built for the
    /// same structure, else a new one (which is then kept).
    pub fn system(
        &mut self,
        values: &Values,
        factors: &[Box<dyn Factor>],
        local_groups: &[Vec<VariableId>],
    ) -> Result<&mut LinearSystem, SolverError> {
        let key = structure_key(values, factors, local_groups);
        let kept = match self.kept.take() {
            Some((kept_key, system)) if kept_key == key => (kept_key, system),
            _ => (key, LinearSystem::new(values, factors, local_groups)?),
        };
        Ok(&mut self.kept.insert(kept).1)
    }

    /// Whether a system is kept.
    pub fn is_empty(&self) -> bool {
        self.kept.is_none()
    }

    /// Drop the kept system.
    pub fn clear(&mut self) {
        self.kept = None;
    }
}

/// Everything [`LinearSystem::new`] reads, as one list of integers: the
/// variable count, each variable's tangent dimension and fixed flag, every
/// factor's variable indices, every local group's variable indices (each
/// list preceded by its length, so two structures never share a key).
fn structure_key(values: &Values, factors: &[Box<dyn Factor>], local_groups: &[Vec<VariableId>]) -> Vec<usize> {
    let slots: usize = factors.iter().map(|f| f.variables().len() + 1).sum();
    let mut key =
        Vec::with_capacity(3 + values.len() + slots + local_groups.iter().map(|g| g.len() + 1).sum::<usize>());
    key.push(values.len());
    key.extend(
        values
            .iter()
            .map(|(_, v)| 2 * v.value.tangent_dim() + usize::from(v.fixed)),
    );
    key.push(factors.len());
    for factor in factors {
        let variables = factor.variables();
        key.push(variables.len());
        key.extend(variables.iter().map(|v| v.0));
    }
    key.push(local_groups.len());
    for group in local_groups {
        key.push(group.len());
        key.extend(group.iter().map(|v| v.0));
    }
    key
}
