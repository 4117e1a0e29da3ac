//! Variables and their values.
//!
//! ```
//! use nalgebra::{DVector, Vector3, Vector6};
//! use sagcal::graph::{Values, VariableValue};
//! use sagcal::model::PlatformPose;
//! let mut values = Values::new();
//! let pose = values.insert("pose 1", VariableValue::Pose(PlatformPose::from_position(Vector3::new(0.0, 0.0, 10.0))));
//! let anchor = values.insert("anchor 1", VariableValue::Vector(DVector::from_vec(vec![-125.0, -110.0, 48.0])));
//! assert_eq!((values.tangent_dim(pose), values.tangent_dim(anchor)), (6, 3));
//! // A vector retracts additively, a pose along its tangent [dtheta, dp].
//! let moved = values.variable(anchor).value.retract(&[1.0, 0.0, -0.5]);
//! values.set(anchor, moved);
//! assert_eq!(values.vector(anchor).as_slice(), &[-124.0, -110.0, 47.5]);
//! let lifted = values.variable(pose).value.retract(Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 2.0).as_slice());
//! values.set(pose, lifted);
//! assert_eq!(values.pose(pose).position_m.z, 12.0);
//! values.set_fixed(anchor, true); // the solver holds it
//! assert!(values.variable(anchor).fixed && !values.variable(pose).fixed);
//! ```

use std::sync::atomic::{AtomicU64, Ordering};

use nalgebra::{DVector, Vector6};

use crate::model::pose::{PlatformPose, POSE_TANGENT_DIM};

/// Index of a variable in a [`Values`] container.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct VariableId(pub usize);

/// The value of one variable.
#[derive(Debug, Clone, PartialEq)]
pub enum VariableValue {
    /// A platform pose (tangent dimension 6, see [`PlatformPose::retract`]).
    Pose(PlatformPose),
    /// A Euclidean vector (anchor, tension, offset, ...), retracted additively.
    Vector(DVector<f64>),
}

impl VariableValue {
    /// Dimension of the tangent space.
    pub fn tangent_dim(&self) -> usize {
        match self {
            VariableValue::Pose(_) => POSE_TANGENT_DIM,
            VariableValue::Vector(v) => v.len(),
        }
    }

    /// Move along `delta` (length [`tangent_dim`](Self::tangent_dim)).
    pub fn retract(&self, delta: &[f64]) -> Self {
        match self {
            VariableValue::Pose(pose) => VariableValue::Pose(pose.retract(&Vector6::from_column_slice(delta))),
            VariableValue::Vector(v) => VariableValue::Vector(v + DVector::from_column_slice(delta)),
        }
    }

    /// [`VariableValue::retract`] in place (the same arithmetic, no allocation).
    pub fn retract_in_place(&mut self, delta: &[f64]) {
        match self {
            VariableValue::Pose(pose) => *pose = pose.retract(&Vector6::from_column_slice(delta)),
            VariableValue::Vector(v) => {
                for (x, d) in v.iter_mut().zip(delta) {
                    *x += d;
                }
            }
        }
    }
}

/// One variable: a name for reports, its value, and whether the solver may move it.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// E.g. `anchor 2` or `pose 17`.
    pub name: String,
    /// Current value.
    pub value: VariableValue,
    /// Held constant by the solver.
    pub fixed: bool,
}

/// All variables of a graph.
#[derive(Debug, Clone)]
pub struct Values {
    variables: Vec<Variable>,
    /// See [`Values::stamp`].
    stamp: u64,
}

/// The source of [`Values::stamp`]s: never the same number twice in a process.
static NEXT_STAMP: AtomicU64 = AtomicU64::new(1);

fn fresh_stamp() -> u64 {
    NEXT_STAMP.fetch_add(1, Ordering::Relaxed)
}

impl Default for Values {
    fn default() -> Self {
        Self {
            variables: Vec::new(),
            stamp: fresh_stamp(),
        }
    }
}

/// Equal variables (names, values, fixed flags); the stamps do not enter.
impl PartialEq for Values {
    fn eq(&self, other: &Self) -> bool {
        self.variables == other.variables
    }
}

impl Values {
    /// An empty container.
    pub fn new() -> Self {
        Self::default()
    }

    /// A number that changes whenever the container may have changed: every
    /// method that takes `&mut self` draws a new one (from a process-wide
    /// counter), a clone keeps its original's, and [`Values::copy_from`]
    /// takes its source's. Equal stamps therefore mean equal contents, which
    /// lets an evaluation shared by several factors
    /// ([`crate::graph::SharedEvaluation`]) be recognised without comparing
    /// its inputs.
    pub fn stamp(&self) -> u64 {
        self.stamp
    }

    /// Add a variable, returning its id.
    pub fn insert(&mut self, name: impl Into<String>, value: VariableValue) -> VariableId {
        self.stamp = fresh_stamp();
        self.variables.push(Variable {
            name: name.into(),
            value,
            fixed: false,
        });
        VariableId(self.variables.len() - 1)
    }

    /// Number of variables.
    pub fn len(&self) -> usize {
        self.variables.len()
    }

    /// Whether there are no variables.
    pub fn is_empty(&self) -> bool {
        self.variables.is_empty()
    }

    /// The variable `id`.
    pub fn variable(&self, id: VariableId) -> &Variable {
        &self.variables[id.0]
    }

    /// All variables in id order.
    pub fn iter(&self) -> impl Iterator<Item = (VariableId, &Variable)> {
        self.variables.iter().enumerate().map(|(i, v)| (VariableId(i), v))
    }

    /// Hold `id` constant (or release it).
    pub fn set_fixed(&mut self, id: VariableId, fixed: bool) {
        self.stamp = fresh_stamp();
        self.variables[id.0].fixed = fixed;
    }

    /// Overwrite every variable with `other`'s (names, values, fixed flags),
    /// reusing this set's allocations where the shapes agree.
    pub fn copy_from(&mut self, other: &Values) {
        self.stamp = other.stamp;
        if self.variables.len() != other.variables.len() {
            self.variables.clone_from(&other.variables);
            return;
        }
        for (mine, theirs) in self.variables.iter_mut().zip(&other.variables) {
            mine.name.clone_from(&theirs.name);
            mine.fixed = theirs.fixed;
            match (&mut mine.value, &theirs.value) {
                (VariableValue::Vector(a), VariableValue::Vector(b)) if a.len() == b.len() => a.copy_from(b),
                (mine, theirs) => mine.clone_from(theirs),
            }
        }
    }

    /// The value of `id`, to change in place.
    pub fn value_mut(&mut self, id: VariableId) -> &mut VariableValue {
        self.stamp = fresh_stamp();
        &mut self.variables[id.0].value
    }

    /// Replace the value of `id`.
    pub fn set(&mut self, id: VariableId, value: VariableValue) {
        self.stamp = fresh_stamp();
        self.variables[id.0].value = value;
    }

    /// The pose stored in `id` (panics if `id` is not a pose: a programming error).
    pub fn pose(&self, id: VariableId) -> &PlatformPose {
        match &self.variables[id.0].value {
            VariableValue::Pose(p) => p,
            VariableValue::Vector(_) => panic!("variable {} is not a pose", self.variables[id.0].name),
        }
    }

    /// The vector stored in `id` (panics if `id` is a pose: a programming error).
    pub fn vector(&self, id: VariableId) -> &DVector<f64> {
        match &self.variables[id.0].value {
            VariableValue::Vector(v) => v,
            VariableValue::Pose(_) => panic!("variable {} is not a vector", self.variables[id.0].name),
        }
    }

    /// Tangent dimension of `id`.
    pub fn tangent_dim(&self, id: VariableId) -> usize {
        self.variables[id.0].value.tangent_dim()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every `&mut self` method draws a new stamp, a clone and a copy carry
    /// their source's, and two containers never share one otherwise.
    #[test]
    fn stamps_change_with_every_mutation_and_only_then() {
        let mut a = Values::new();
        assert_ne!(a.stamp(), Values::new().stamp());
        let mut seen = vec![a.stamp()];
        let mut changed = |values: &Values| {
            assert!(!seen.contains(&values.stamp()), "a stamp reused");
            seen.push(values.stamp());
        };
        let x = a.insert("x", VariableValue::Vector(DVector::from_vec(vec![1.0])));
        changed(&a);
        a.set(x, VariableValue::Vector(DVector::from_vec(vec![2.0])));
        changed(&a);
        a.value_mut(x).retract_in_place(&[0.5]);
        changed(&a);
        a.set_fixed(x, true);
        changed(&a);
        let (stamp, _) = (a.stamp(), a.vector(x));
        assert_eq!(a.stamp(), stamp, "reading changes nothing");
        let b = a.clone();
        assert_eq!((b.stamp(), &b), (a.stamp(), &a));
        let mut c = Values::new();
        c.copy_from(&a);
        assert_eq!((c.stamp(), &c), (a.stamp(), &a));
        c.set(x, VariableValue::Vector(DVector::from_vec(vec![9.0])));
        assert_ne!(c.stamp(), a.stamp());
        assert_ne!(c, a);
        // Equality is by content, not by stamp.
        let mut d = Values::new();
        d.insert("x", VariableValue::Vector(DVector::from_vec(vec![2.5])));
        d.set_fixed(x, true);
        assert_eq!(d, a);
        assert_ne!(d.stamp(), a.stamp());
    }
}
