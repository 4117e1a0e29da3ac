//! Robust kernels `rho(s)` of the whitened squared residual norm `s = |r/sigma|^2`.
//!
//! | kernel | `rho(s)` | `rho'(s)` | behaviour |
//! |---|---|---|---|
//! | none | `s` | `1` | least squares |
//! | Huber(k) | `s` if `s <= k^2`, else `2k sqrt(s) - k^2` | `min(1, k/sqrt(s))` | linear tails |
//! | Cauchy(c) | `c^2 ln(1 + s/c^2)` | `1/(1 + s/c^2)` | logarithmic tails |
//!
//! (Triggs et al., *Bundle Adjustment: A Modern Synthesis*, 2000, Sec. 3;
//! Ceres `loss_function.h`.) The solver uses iteratively reweighted least
//! squares: the whitened residual and Jacobian are scaled by `sqrt(rho'(s))`.
//!
//! ```
//! use sagcal::graph::RobustKernel;
//! let huber = RobustKernel::parse("huber")?;
//! assert_eq!(huber, RobustKernel::Huber(1.345)); // the 95 %-efficiency default
//! // Least squares inside k sigmas, linear tails outside, continuous at s = k^2.
//! assert_eq!(huber.rho(1.0), 1.0);
//! let k2 = 1.345f64 * 1.345;
//! assert!((huber.rho(k2 * (1.0 + 1e-12)) - k2).abs() < 1e-9);
//! // The IRLS weight is rho'(s): check it by central differences for both kernels at 3 sigmas.
//! for kernel in [huber, RobustKernel::Cauchy(2.3849)] {
//!     let (s, h) = (9.0, 1e-5);
//!     let slope = (kernel.rho(s + h) - kernel.rho(s - h)) / (2.0 * h);
//!     assert!((slope - kernel.weight(s)).abs() < 1e-8);
//! }
//! assert!(RobustKernel::parse("cauchy:-1").is_err());
//! # Ok::<(), sagcal::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::error::ParseError;

/// A robust kernel.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kernel", content = "scale", rename_all = "lowercase")]
pub enum RobustKernel {
    /// Plain least squares.
    #[default]
    None,
    /// Huber with threshold `k` (in sigmas).
    Huber(f64),
    /// Cauchy with scale `c` (in sigmas).
    Cauchy(f64),
}

impl RobustKernel {
    /// `rho(s)`.
    pub fn rho(&self, s: f64) -> f64 {
        match *self {
            RobustKernel::None => s,
            RobustKernel::Huber(k) => {
                if s <= k * k {
                    s
                } else {
                    2.0 * k * s.sqrt() - k * k
                }
            }
            RobustKernel::Cauchy(c) => c * c * (s / (c * c)).ln_1p(),
        }
    }

    /// `rho'(s)`, the IRLS weight.
    pub fn weight(&self, s: f64) -> f64 {
        match *self {
            RobustKernel::None => 1.0,
            RobustKernel::Huber(k) => {
                if s <= k * k {
                    1.0
                } else {
                    k / s.sqrt()
                }
            }
            RobustKernel::Cauchy(c) => 1.0 / (1.0 + s / (c * c)),
        }
    }

    /// Parse `none`, `huber:K` or `cauchy:C` (K, C in sigmas; defaults 1.345 and 2.3849).
    pub fn parse(text: &str) -> Result<Self, ParseError> {
        let (name, scale) = match text.split_once(':') {
            Some((n, s)) => (n, Some(s)),
            None => (text, None),
        };
        let scale = |default: f64| -> Result<f64, ParseError> {
            match scale {
                None => Ok(default),
                Some(s) => match s.parse::<f64>() {
                    Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
                    _ => Err(ParseError::OutOfRange {
                        what: "robust kernel scale",
                        expected: "a positive number",
                        given: s.to_string(),
                    }),
                },
            }
        };
        match name {
            "none" => Ok(RobustKernel::None),
            "huber" => Ok(RobustKernel::Huber(scale(1.345)?)),
            "cauchy" => Ok(RobustKernel::Cauchy(scale(2.3849)?)),
            other => Err(ParseError::UnknownChoice {
                what: "robust kernel",
                given: other.to_string(),
                choices: " (none, huber[:k], cauchy[:c])".to_string(),
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_is_the_derivative_of_rho() {
        for kernel in [
            RobustKernel::None,
            RobustKernel::Huber(1.345),
            RobustKernel::Cauchy(2.0),
        ] {
            for s in [0.1, 1.0, 1.8, 4.0, 30.0] {
                let h = 1e-6 * s;
                let numeric = (kernel.rho(s + h) - kernel.rho(s - h)) / (2.0 * h);
                assert!((numeric - kernel.weight(s)).abs() < 1e-7, "{kernel:?} at {s}");
            }
        }
    }

    #[test]
    fn parse_kernels() {
        assert_eq!(RobustKernel::parse("huber:2").unwrap(), RobustKernel::Huber(2.0));
        assert_eq!(RobustKernel::parse("cauchy").unwrap(), RobustKernel::Cauchy(2.3849));
        assert!(RobustKernel::parse("tukey").is_err());
        assert!(RobustKernel::parse("huber:-1").is_err());
    }
}
