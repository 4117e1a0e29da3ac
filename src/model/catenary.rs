//! The inextensible catenary (paper eq. 1-4) in numerically stable form.
//!
//! A cable hangs in the vertical plane through its anchor (pulley exit) `a`
//! and its platform attachment `b`. In that plane `x` runs horizontally from
//! the anchor towards the attachment (`0 <= x <= span`), `z` is the world
//! height. The cable carries the horizontal tension `f_h > 0` (constant along
//! the cable) and, at the attachment, the vertical tension `f_v` (positive
//! when the cable pulls the platform up). `g_c` is the cable weight per metre.
//!
//! Paper eq. (1)-(3):
//! ```text
//! z(x) = f_h/g_c * (cosh(g_c/f_h (x + C1)) - C2)
//! C1   = f_h/g_c * asinh(-f_v/f_h) - span
//! C2   = cosh(g_c C1 / f_h) - g_c a_z / f_h
//! ```
//! and eq. (4), the arc length. Written as differences of `cosh`/`sinh` these
//! lose every digit when `g_c span / f_h` is small (a light or tight cable).
//! With `u = f_v/f_h`, `lambda = g_c span / f_h`, `A = asinh(u)` and the
//! identities `sinh(p) - sinh(q) = 2 cosh((p+q)/2) sinh((p-q)/2)` and
//! `cosh(p) - cosh(q) = 2 sinh((p+q)/2) sinh((p-q)/2)` they become
//! ```text
//! length        = span * sinhc(lambda/2) * cosh(A + lambda/2)      (eq. 4)
//! a_z - z(span) = span * sinhc(lambda/2) * sinh(A + lambda/2)      (eq. 1 at x = span)
//! ```
//! with `sinhc(y) = sinh(y)/y` evaluated by its Taylor series near 0. No
//! difference of nearly equal numbers remains, and as `g_c -> 0` they tend to
//! the straight cable: `length = span * sqrt(1 + u^2)`, drop `= span * u`.
//!
//! ```
//! use sagcal::model::Catenary;
//! // A massless cable is the straight line: length = span sqrt(1 + u^2), drop = span u (u = f_v / f_h).
//! let straight = Catenary {
//!     span_m: 30.0,
//!     horizontal_tension_n: 400.0,
//!     vertical_tension_n: 300.0,
//!     cable_weight_n_per_m: 0.0,
//! };
//! assert!((straight.length_m() - 37.5).abs() < 1e-12 && (straight.drop_m() - 22.5).abs() < 1e-12);
//! // A heavy cable agrees with the paper's own form, eq. (1)-(4) with the constants of eq. (2)-(3).
//! let heavy = Catenary { cable_weight_n_per_m: 0.71, ..straight };
//! let (anchor_z, k) = (48.0, 0.71 / 400.0);
//! let (c1, c2) = heavy.constants(anchor_z);
//! let z_attachment = (((30.0 + c1) * k).cosh() - c2) / k;
//! let arc = (((30.0 + c1) * k).sinh() - (c1 * k).sinh()) / k;
//! assert!((anchor_z - z_attachment - heavy.drop_m()).abs() < 1e-9);
//! assert!((arc.abs() - heavy.length_m()).abs() < 1e-9);
//! assert!(heavy.length_m() > straight.length_m());
//! ```

/// `sinh(y) / y`, accurate to a few ulp for every finite `y` (1 at `y = 0`).
pub fn sinhc(y: f64) -> f64 {
    if y.abs() < 1e-3 {
        let y2 = y * y;
        // Taylor series; the first omitted term is y^8/9! < 3e-30.
        1.0 + y2 / 6.0 * (1.0 + y2 / 20.0 * (1.0 + y2 / 42.0))
    } else {
        y.sinh() / y
    }
}

/// One cable's catenary in its vertical plane (paper Sec. III-B).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Catenary {
    /// Horizontal distance from the anchor to the attachment, `L_i` in the paper, metres.
    pub span_m: f64,
    /// Horizontal tension `f_h`, newtons (must be > 0).
    pub horizontal_tension_n: f64,
    /// Vertical tension at the platform attachment `f_v`, newtons (upward pull on the platform > 0).
    pub vertical_tension_n: f64,
    /// Cable weight per unit length `g_c = rho_c g`, newtons per metre (0 for a massless cable).
    pub cable_weight_n_per_m: f64,
}

impl Catenary {
    /// `u = f_v / f_h`: slope of the cable (descending towards the platform) at the attachment.
    fn attachment_slope(&self) -> f64 {
        self.vertical_tension_n / self.horizontal_tension_n
    }

    /// `lambda / 2 = g_c span / (2 f_h)`.
    fn half_lambda(&self) -> f64 {
        0.5 * self.cable_weight_n_per_m * self.span_m / self.horizontal_tension_n
    }

    /// Arc length of the cable from anchor to attachment (paper eq. 4), metres.
    pub fn length_m(&self) -> f64 {
        let half = self.half_lambda();
        self.span_m * sinhc(half) * (self.attachment_slope().asinh() + half).cosh()
    }

    /// Height of the anchor above the attachment, `a_z - z(span)` (paper eq. 1 at `x = span`), metres.
    pub fn drop_m(&self) -> f64 {
        let half = self.half_lambda();
        self.span_m * sinhc(half) * (self.attachment_slope().asinh() + half).sinh()
    }

    /// Height of the cable above the anchor at horizontal distance `x_m` from it, `z(x) - a_z`, metres.
    ///
    /// `z(x) - z(0) = f_h/g_c (cosh(B + g_c x/f_h) - cosh(B))` with
    /// `B = g_c C1 / f_h = -(A + lambda)`, in the stable product form
    /// `x * sinhc(y) * sinh(B + y)`, `y = g_c x / (2 f_h)`.
    pub fn height_above_anchor_m(&self, x_m: f64) -> f64 {
        let y = 0.5 * self.cable_weight_n_per_m * x_m / self.horizontal_tension_n;
        let b = -(self.attachment_slope().asinh() + 2.0 * self.half_lambda());
        x_m * sinhc(y) * (b + y).sinh()
    }

    /// Arc length from the anchor to horizontal distance `x_m`, metres.
    pub fn arc_length_to_m(&self, x_m: f64) -> f64 {
        let y = 0.5 * self.cable_weight_n_per_m * x_m / self.horizontal_tension_n;
        let b = -(self.attachment_slope().asinh() + 2.0 * self.half_lambda());
        x_m * sinhc(y) * (b + y).cosh()
    }

    /// Catenary constants `(C1 [m], C2 [-])` of eq. (2)-(3) for an anchor at height `anchor_z_m`.
    ///
    /// Only defined for `g_c > 0`; they are not needed by any computation
    /// (which use the stable forms) and exist to check against the paper.
    pub fn constants(&self, anchor_z_m: f64) -> (f64, f64) {
        let k = self.cable_weight_n_per_m / self.horizontal_tension_n;
        let c1 = (-self.attachment_slope()).asinh() / k - self.span_m;
        let c2 = (k * c1).cosh() - k * anchor_z_m;
        (c1, c2)
    }

    /// Vertical tension at the anchor end, `f_v + g_c * length`, newtons (upward pull on the pulley is its negative).
    pub fn anchor_vertical_tension_n(&self) -> f64 {
        self.vertical_tension_n + self.cable_weight_n_per_m * self.length_m()
    }

    /// Tension magnitude at the platform attachment, `sqrt(f_h^2 + f_v^2)`, newtons.
    pub fn attachment_tension_n(&self) -> f64 {
        self.horizontal_tension_n.hypot(self.vertical_tension_n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn massless_limit_is_straight_cable() {
        let cable = Catenary {
            span_m: 150.0,
            horizontal_tension_n: 600.0,
            vertical_tension_n: 80.0,
            cable_weight_n_per_m: 0.0,
        };
        let u = 80.0 / 600.0;
        assert!((cable.length_m() - 150.0 * (1.0f64 + u * u).sqrt()).abs() < 1e-12);
        assert!((cable.drop_m() - 150.0 * u).abs() < 1e-12);
    }

    #[test]
    fn stable_forms_match_paper_equations_where_those_are_well_conditioned() {
        let cable = Catenary {
            span_m: 170.0,
            horizontal_tension_n: 550.0,
            vertical_tension_n: 90.0,
            cable_weight_n_per_m: 0.71,
        };
        let anchor_z = 48.0;
        let (c1, c2) = cable.constants(anchor_z);
        let k = cable.cable_weight_n_per_m / cable.horizontal_tension_n;
        let z = |x: f64| ((k * (x + c1)).cosh() - c2) / k;
        let length = ((k * (cable.span_m + c1)).sinh() - (k * c1).sinh()) / k;
        assert!((z(0.0) - anchor_z).abs() < 1e-9);
        assert!((anchor_z - z(cable.span_m) - cable.drop_m()).abs() < 1e-9);
        assert!((length - cable.length_m()).abs() < 1e-9);
        assert!((z(60.0) - anchor_z - cable.height_above_anchor_m(60.0)).abs() < 1e-9);
        assert!((cable.height_above_anchor_m(cable.span_m) + cable.drop_m()).abs() < 1e-9);
        assert!((cable.arc_length_to_m(cable.span_m) - cable.length_m()).abs() < 1e-9);
    }

    #[test]
    fn sinhc_is_continuous_at_the_series_switch() {
        let below = sinhc(0.999_999_999e-3);
        let above = sinhc(1.000_000_001e-3);
        assert!((below - above).abs() < 1e-15);
        assert_eq!(sinhc(0.0), 1.0);
    }
}
