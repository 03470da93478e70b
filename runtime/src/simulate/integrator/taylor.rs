//! Taylor's method: the step is the truncated Taylor series of the motion
//! itself (the model's generated [`crate::Dynamics::taylor_series`]), its
//! order and length chosen from the tolerance as Jorba & Zou propose
//! (*A software package for the numerical integration of ODEs by means of
//! high-order Taylor methods*, Exp. Math. 14, 2005, §3.2), and the step's
//! polynomial is its dense output.

use crate::libm;
use crate::taylor::{MAX_ORDER, Series};

/// Taylor's method of the order the tolerance asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Taylor {
    /// The tolerance, absolute for components below 1 and relative above
    /// (Jorba & Zou's ε; the default is the unit roundoff of f64).
    pub tolerance: f64,
    /// Largest step allowed.
    pub max_step: f64,
}

impl Default for Taylor {
    fn default() -> Self {
        Self {
            tolerance: f64::EPSILON / 2.0,
            max_step: f64::INFINITY,
        }
    }
}

impl Taylor {
    /// Whether the settings are usable.
    pub fn valid(&self) -> bool {
        self.tolerance > 0.0 && self.tolerance < 1.0 && self.max_step > 0.0
    }

    /// The order: ⌈−½ ln ε + 1⌉ (Jorba & Zou, eq. 3.8), at least 2 and at
    /// most [`MAX_ORDER`] − 1 (the step size reads the coefficients of
    /// order p − 1 and p).
    pub fn order(&self) -> usize {
        let p = libm::ceil(-0.5 * libm::log(self.tolerance) + 1.0);
        (p as usize).clamp(2, MAX_ORDER)
    }

    /// The step for the series `s` of order p (Jorba & Zou, eq. 3.9, with
    /// the safety factor exp(−0.7/(p − 1)) heyoka uses):
    /// h = ρ/e² · exp(−0.7/(p − 1)), ρ = min over j ∈ {p − 1, p} of
    /// (max(1, ‖x₀‖∞)/‖xⱼ‖∞)^(1/j), the norms over every coordinate and
    /// velocity. A series whose last two orders vanish (a polynomial
    /// motion) takes the longest step.
    pub fn step<const N: usize>(&self, s: &Series<N>) -> f64 {
        let p = s.order;
        let norm = |j: usize| {
            let mut m: f64 = 0.0;
            for i in 0..N {
                m = m.max(libm::fabs(s.q[i][j])).max(libm::fabs(s.v[i][j]));
            }
            m
        };
        let scale = norm(0).max(1.0);
        // In logarithms: ln h = ln ρ − 2 − 0.7/(p − 1), two logarithms and
        // one exponential per step.
        let log_radius = |j: usize| {
            let x = norm(j);
            if x == 0.0 {
                f64::INFINITY
            } else {
                libm::log(scale / x) / j as f64
            }
        };
        let log_rho = log_radius(p - 1).min(log_radius(p));
        if log_rho == f64::INFINITY {
            return self.max_step;
        }
        libm::exp(log_rho - 2.0 - 0.7 / (p - 1) as f64).min(self.max_step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::taylor::CAPACITY;

    #[test]
    fn order_from_tolerance() {
        let t = Taylor::default();
        assert_eq!(t.order(), 20);
        let loose = Taylor {
            tolerance: 1e-6,
            ..t
        };
        assert_eq!(loose.order(), 8);
    }

    /// For x(t) = 1/(1 − t) (x₀ = 1, all coefficients 1) the radius of
    /// convergence is 1, and the step is 1/e² times the safety factor.
    #[test]
    fn step_from_the_radius_of_convergence() {
        let t = Taylor::default();
        let mut s = Series::<1>::at(&[1.0], &[1.0]);
        s.order = t.order();
        s.q[0] = [1.0; CAPACITY];
        s.v[0] = core::array::from_fn(|k| (k + 1) as f64);
        let h = t.step(&s);
        let p = s.order as f64;
        // ‖x_j‖ = j + 1 (the velocity's): ρ = min((1/p)^(1/(p−1)), (1/(p+1))^(1/p)).
        let rho = libm::pow(1.0 / p, 1.0 / (p - 1.0)).min(libm::pow(1.0 / (p + 1.0), 1.0 / p));
        let e2 = core::f64::consts::E * core::f64::consts::E;
        let want = rho / e2 * libm::exp(-0.7 / (p - 1.0));
        assert!(libm::fabs(h - want) <= 1e-15 * want);
        // A polynomial motion: no limit but the longest step.
        let mut line = Series::<1>::at(&[0.0], &[1.0]);
        line.q[0][1] = 1.0;
        line.order = 20;
        assert_eq!(t.step(&line), f64::INFINITY);
    }
}
