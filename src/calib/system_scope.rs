//! The linear system shared by the solves of one calibration.
//!
//! A calibration solves several graphs of one structure (the relaxed and the
//! full catenary stage of a start, the fits with and without the orientation
//! prior, the covariance at each solution) and the pattern analysis of each
//! ([`crate::solver::LinearSystem::new`]) is most of a small solve's setup.
//! The public entry points open a [`Scope`]; inside it, on the scope's
//! thread, every stage and covariance takes its system from one
//! [`SystemCache`], which hands back the kept system only to a graph of the
//! same structure (bit for bit the same result). When the outermost scope
//! closes the system is dropped, so nothing stays allocated between calls.
//! Solves outside a scope, or on other threads, build their own system.

use std::cell::RefCell;

use crate::solver::SystemCache;

thread_local! {
    /// Open scopes on this thread and their cache.
    static SHARED: RefCell<(usize, SystemCache)> = RefCell::new((0, SystemCache::default()));
}

/// While alive, solves on this thread share one [`SystemCache`].
pub(crate) struct Scope(());

impl Scope {
    /// Open a scope (scopes nest; the cache lives until the outermost closes).
    pub(crate) fn enter() -> Scope {
        SHARED.with(|shared| shared.borrow_mut().0 += 1);
        Scope(())
    }
}

impl Drop for Scope {
    fn drop(&mut self) {
        SHARED.with(|shared| {
            let mut shared = shared.borrow_mut();
            shared.0 -= 1;
            if shared.0 == 0 {
                shared.1.clear();
            }
        });
    }
}

/// Run `f` with the scope's cache, or with a cache of its own outside a
/// scope (or if the cache is in use further up this thread's stack).
pub(crate) fn with_system_cache<R>(f: impl FnOnce(&mut SystemCache) -> R) -> R {
    SHARED.with(|shared| match shared.try_borrow_mut() {
        Ok(mut shared) if shared.0 > 0 => f(&mut shared.1),
        _ => f(&mut SystemCache::default()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calib::factors::PosePriorFactor;
    use crate::graph::{FactorGraph, RobustKernel, VariableValue};
    use crate::model::PlatformPose;
    use nalgebra::Vector3;

    /// The cache is kept inside nested scopes and dropped when the outermost closes.
    #[test]
    fn the_outermost_scope_drops_the_system() {
        let mut graph = FactorGraph::new();
        let at = PlatformPose::from_position(Vector3::new(1.0, 2.0, 3.0));
        let pose = graph.values.insert("pose", VariableValue::Pose(at));
        graph.factors.push(Box::new(PosePriorFactor::new(
            pose,
            &at,
            0.01,
            Some(0.02),
            RobustKernel::None,
        )));
        let analyse = || {
            with_system_cache(|cache| {
                cache
                    .system(&graph.values, &graph.factors, &graph.local_groups)
                    .map(|s| s.dim)
            })
        };
        let kept = || SHARED.with(|s| !s.borrow().1.is_empty());
        assert_eq!(analyse(), Ok(6));
        assert!(!kept(), "outside a scope nothing is kept");
        {
            let _outer = Scope::enter();
            assert_eq!(analyse(), Ok(6));
            assert!(kept());
            {
                let _inner = Scope::enter();
                assert_eq!(analyse(), Ok(6));
            }
            assert!(kept(), "the inner scope's end keeps the outer's system");
        }
        assert!(!kept(), "the outermost scope's end drops it");
    }
}
