//! Which instruction set the hand-written kernels run: the one dispatch of
//! the crate, and its switch.
//!
//! The solver (`solver::simd`) and the factor weighing of `graph` have
//! kernels compiled for AVX2 beside their portable code (the x86-64
//! baseline, SSE2). Both compute every value by the same operations in the
//! same order, with no fused multiply-add, so the two paths give the same
//! results bit for bit; the AVX2 one is only faster. Every call site asks
//! [`avx2`] which to run, and nothing else in the crate tests the CPU.
//!
//! The switch is the environment variable `SAGCAL_SIMD`, read once, at the
//! first kernel call of the process:
//!
//! | value | path |
//! |---|---|
//! | unset, empty or `auto` | AVX2 where the CPU has it, else portable |
//! | `portable` | portable, whatever the CPU |
//! | `avx2` | AVX2; on a CPU without it the portable path still runs (an AVX2 instruction there would be undefined behaviour), and the tests of the AVX2 kernels fail instead of skipping |
//!
//! Any other value is an error: the command and the Python package refuse
//! it before any work ([`check_switch`]: exit 2, or a `ValueError` on
//! import); a library caller that skips the check gets a panic naming the
//! variable at the first kernel call. `make test` runs the solver's and the calibration's tests a
//! second time with `SAGCAL_SIMD=portable`, so both paths are tested on a
//! machine with AVX2.
//!
//! The module is a leaf that every layer may name (`tests/layout.rs`):
//! `graph` sits below `solver` and cannot name `solver::simd`, yet its
//! four-row weighing must follow the same switch.
//!
//! ```
//! use sagcal::simd::{active, avx2, SimdPath};
//! // The path in use, for a log line or a benchmark's label.
//! println!("kernels: {}", active());
//! assert_eq!(avx2(), active() == SimdPath::Avx2);
//! ```

use std::sync::OnceLock;

use crate::error::ParseError;

/// The environment variable that chooses the path.
pub const SWITCH: &str = "SAGCAL_SIMD";

/// What the switch asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimdRequest {
    /// AVX2 where the CPU has it (the default).
    Auto,
    /// The portable code, whatever the CPU.
    Portable,
    /// The AVX2 kernels (the tests of the kernels fail on a CPU without AVX2).
    Avx2,
}

impl SimdRequest {
    /// The request of a value of [`SWITCH`] (`None`: unset); an error names
    /// the variable and the accepted values.
    pub fn parse(value: Option<&str>) -> Result<Self, ParseError> {
        match value.map(str::trim) {
            None | Some("") | Some("auto") => Ok(Self::Auto),
            Some("portable") => Ok(Self::Portable),
            Some("avx2") => Ok(Self::Avx2),
            Some(other) => Err(ParseError::UnknownVariable {
                variable: SWITCH,
                given: other.to_string(),
                choices: "portable, avx2 or auto",
            }),
        }
    }
}

/// The path the kernels run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimdPath {
    /// The x86-64 baseline code (SSE2; any code on other architectures).
    Portable,
    /// The kernels compiled for AVX2.
    Avx2,
}

impl std::fmt::Display for SimdPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SimdPath::Portable => "portable",
            SimdPath::Avx2 => "avx2",
        })
    }
}

/// The switch and the path it gives, decided once per process.
static CHOICE: OnceLock<(SimdRequest, SimdPath)> = OnceLock::new();

/// The switch's value and the path, read and decided on the first call.
/// After it, one atomic load: the hot loops call [`avx2`] once per factor.
#[inline]
fn choice() -> (SimdRequest, SimdPath) {
    match CHOICE.get() {
        Some(&choice) => choice,
        None => decide(),
    }
}

/// [`choice`]'s first call: read the switch, test the CPU (out of line, so
/// that the callers stay small enough to inline).
#[cold]
#[inline(never)]
fn decide() -> (SimdRequest, SimdPath) {
    *CHOICE.get_or_init(|| {
        let value = std::env::var(SWITCH).ok();
        let request = SimdRequest::parse(value.as_deref()).unwrap_or_else(|error| panic!("{error}"));
        (request, path_for(request, cpu_has_avx2()))
    })
}

/// The path for `request` on a CPU with or without AVX2.
fn path_for(request: SimdRequest, has_avx2: bool) -> SimdPath {
    match request {
        SimdRequest::Auto | SimdRequest::Avx2 if has_avx2 => SimdPath::Avx2,
        _ => SimdPath::Portable,
    }
}

/// The switch as set in this process's environment, checked: the front
/// ends call it before any work, so that a mistyped value is a clear error
/// (the kernels themselves could only panic on it).
pub fn check_switch() -> Result<SimdRequest, ParseError> {
    SimdRequest::parse(std::env::var(SWITCH).ok().as_deref())
}

/// Whether this CPU runs AVX2 (std caches the answer).
pub fn cpu_has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// What the switch asks for.
pub fn requested() -> SimdRequest {
    choice().0
}

/// The path the kernels run in this process.
pub fn active() -> SimdPath {
    choice().1
}

/// Whether the kernels run their AVX2 path: the dispatch of every call site.
/// `true` only where the CPU has AVX2, so an `unsafe` call of a function
/// compiled for AVX2 behind it is sound.
#[inline]
pub fn avx2() -> bool {
    choice().1 == SimdPath::Avx2
}

/// Whether a test of the AVX2 kernels runs them: `true` on the AVX2 path;
/// `false`, with a line on stderr, when the switch asks for the portable
/// path or (`auto`) the CPU has no AVX2; a panic when the switch asks for
/// AVX2 on a CPU without it, so that such a machine fails the tests instead
/// of passing them untested.
#[cfg(test)]
pub(crate) fn avx2_under_test() -> bool {
    match (requested(), avx2()) {
        (_, true) => true,
        (SimdRequest::Avx2, false) => panic!("{SWITCH}=avx2 asks for the AVX2 kernels, but this CPU has no AVX2"),
        (SimdRequest::Portable, false) => {
            eprintln!("skipped: {SWITCH}=portable");
            false
        }
        (SimdRequest::Auto, false) => {
            eprintln!("skipped: this CPU has no AVX2");
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_switch_reads_its_three_values_and_refuses_others() {
        assert_eq!(SimdRequest::parse(None), Ok(SimdRequest::Auto));
        assert_eq!(SimdRequest::parse(Some("")), Ok(SimdRequest::Auto));
        assert_eq!(SimdRequest::parse(Some("auto")), Ok(SimdRequest::Auto));
        assert_eq!(SimdRequest::parse(Some("portable")), Ok(SimdRequest::Portable));
        assert_eq!(SimdRequest::parse(Some(" avx2\n")), Ok(SimdRequest::Avx2));
        let error = SimdRequest::parse(Some("sse2")).unwrap_err();
        assert_eq!(
            error.to_string(),
            "SAGCAL_SIMD=\"sse2\": expected portable, avx2 or auto"
        );
    }

    #[test]
    fn avx2_runs_only_where_asked_for_and_present() {
        for has_avx2 in [false, true] {
            let expected = if has_avx2 { SimdPath::Avx2 } else { SimdPath::Portable };
            assert_eq!(path_for(SimdRequest::Auto, has_avx2), expected);
            assert_eq!(path_for(SimdRequest::Avx2, has_avx2), expected);
            assert_eq!(path_for(SimdRequest::Portable, has_avx2), SimdPath::Portable);
        }
    }

    /// This process follows its switch; `SAGCAL_SIMD=avx2` on a CPU without
    /// AVX2 fails here (and in every test of the kernels).
    #[test]
    fn this_process_follows_the_switch() {
        match requested() {
            SimdRequest::Portable => assert_eq!(active(), SimdPath::Portable),
            SimdRequest::Avx2 => {
                assert!(
                    cpu_has_avx2(),
                    "{SWITCH}=avx2 asks for the AVX2 kernels, but this CPU has no AVX2"
                );
                assert_eq!(active(), SimdPath::Avx2);
            }
            SimdRequest::Auto => assert_eq!(avx2(), cpu_has_avx2()),
        }
        assert_eq!(avx2_under_test(), avx2());
    }
}
