//! Taylor's method: the step is the truncated Taylor series of the motion
//! itself (the model's generated [`crate::TaylorSeries::taylor_series`]), its
//! order and length chosen from the tolerance as Jorba & Zou propose
//! (*A software package for the numerical integration of ODEs by means of
//! high-order Taylor methods*, Exp. Math. 14, 2005, §3.2), and the step's
//! polynomial is its dense output.

use crate::libm;
use crate::simulate::thresholds::SERIES_SAMPLES;
use crate::taylor::{CAPACITY, Coefficients, MAX_ORDER, Series, SeriesWork};

/// A step's work besides the series of the motion and of the walls, the
/// state on the step and the root search's samples, in multiply-adds, for
/// [`Taylor::order_for`]'s cost model: the step size, the report of the
/// energy and residuals, the bookkeeping. Fitted to the per-step times of
/// `ball_wall_euler` at fixed orders 20 to 31 (100 impacts, best of 5 runs:
/// 1.75 to 3.21 µs per step, linear in the modelled work with an
/// intercept of 980).
const STEP_OVERHEAD: f64 = 1000.0;

/// Taylor's method of the order the tolerance asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Taylor {
    /// The tolerance, absolute for components below 1 and relative above
    /// (Jorba & Zou's ε; the default is the unit roundoff of f64), in
    /// [[`Taylor::MIN_TOLERANCE`], 1).
    pub tolerance: f64,
    /// A fixed order (2 to [`MAX_ORDER`]) instead of the one the tolerance
    /// asks for. The step is then the last two terms below the tolerance
    /// (see [`Taylor::step`]), so an order above the tolerance's takes
    /// longer steps: where the radius of convergence, not the tolerance,
    /// bounds the step (near a coordinate singularity, say), fewer steps at
    /// more work per step.
    pub fixed_order: Option<usize>,
    /// Largest step allowed.
    pub max_step: f64,
}

impl Default for Taylor {
    fn default() -> Self {
        Self {
            tolerance: f64::EPSILON / 2.0,
            fixed_order: None,
            max_step: f64::INFINITY,
        }
    }
}

impl Taylor {
    /// The smallest tolerance: 10⁻²⁶, whose order ⌈−½ ln ε + 1⌉ (Jorba &
    /// Zou, eq. 3.8) is [`MAX_ORDER`] (that order covers ε down to
    /// e⁻⁶⁰ ≈ 8.8e-27). Below it no order the series can reach would keep
    /// the step near ρ/e²: the steps would shrink like ε^(1/MAX_ORDER), to
    /// ρ·10⁻¹⁰ at ε = 10⁻³⁰⁰, and a run would never end.
    pub const MIN_TOLERANCE: f64 = 1e-26;

    /// Whether the settings are usable: the tolerance in
    /// [[`Taylor::MIN_TOLERANCE`], 1), the largest step positive, a fixed
    /// order from 2 to [`MAX_ORDER`].
    pub fn valid(&self) -> bool {
        self.tolerance >= Self::MIN_TOLERANCE
            && self.tolerance < 1.0
            && self.max_step > 0.0
            && self
                .fixed_order
                .is_none_or(|p| (2..=MAX_ORDER).contains(&p))
    }

    /// The order the tolerance asks for: the fixed order if one is set, else
    /// ⌈−½ ln ε + 1⌉ (Jorba & Zou, eq. 3.8), at least 2 and at most
    /// [`MAX_ORDER`] (the step size reads the coefficients of order p − 1
    /// and p). The simulator steps at [`Taylor::order_for`] the model, this
    /// or higher.
    pub fn order(&self) -> usize {
        let p = match self.fixed_order {
            Some(p) => p,
            None => libm::ceil(-0.5 * libm::log(self.tolerance) + 1.0) as usize,
        };
        p.clamp(2, MAX_ORDER)
    }

    /// The order for a model whose series cost `work` per order, with `n`
    /// coordinates and `walls` walls: the [`fixed_order`](Self::fixed_order)
    /// if one is set, else [`Taylor::order`] where the work is unknown, else
    /// the order from [`Taylor::order`] up to [`MAX_ORDER`] whose steps
    /// cost least per unit of time. A step of order p costs the series of
    /// the motion and of the walls to p, the state on it (2n(p + 1)
    /// multiply-adds), the root search's samples of each wall's polynomial
    /// and 1 000 more for the rest of a step (the step size, the report,
    /// the bookkeeping); its length is the one [`Taylor::step`] takes for
    /// a series whose coefficients fall like ρ⁻ᵏ: ρ·e⁻² at the
    /// tolerance's order, ρ·ε^(1/p) (the last two terms below the
    /// tolerance) above it, both with the safety factor. Jorba & Zou's
    /// order balances the series' cost, which grows like p², against the
    /// step; where the rest of the step weighs too, as in a small model, a
    /// higher order pays.
    pub fn order_for(&self, work: Option<SeriesWork>, n: usize, walls: usize) -> usize {
        let least = self.order();
        let Some(work) = work.filter(|_| self.fixed_order.is_none()) else {
            return least;
        };
        let log_eps = libm::log(self.tolerance);
        let per_time = |p: usize| {
            let orders = (p + 1) as f64;
            let step = work.motion.multiply_adds(p)
                + work.walls.multiply_adds(p + 1)
                + (2 * n) as f64 * orders
                + (walls * SERIES_SAMPLES * 2) as f64 * orders
                + STEP_OVERHEAD;
            let mut log_h = log_eps / p as f64;
            if p == least {
                log_h = log_h.min(-2.0);
            }
            step / libm::exp(log_h - 0.7 / (p - 1) as f64)
        };
        let mut best = (per_time(least), least);
        for p in least + 1..=MAX_ORDER {
            let c = per_time(p);
            if c < best.0 {
                best = (c, p);
            }
        }
        best.1
    }

    /// The order of the first lower-order trial of a run (see
    /// [`crate::simulate`]'s Taylor steps), the lowest there is: a trial
    /// that falls short is followed by the full series, whose coefficients
    /// tell the lowest order that would have stepped as far, so the trials
    /// need no guess of their own. At order 2 the step is about ε/‖q̇‖ (its
    /// last two terms are q̇ and q̈), so the first trial of a moving state
    /// falls short, at the cost of a series to order 2.
    pub const FIRST_TRIAL_ORDER: usize = 2;

    /// The step for the series `s` of order p, the shorter of Jorba & Zou's
    /// two estimates (§3.2): the last two terms below the tolerance,
    /// h = min over j ∈ {p − 1, p} of (ε max(1, ‖x₀‖∞)/‖xⱼ‖∞)^(1/j), and
    /// the asymptotic h = ρ/e² (eq. 3.9, ρ = min over j of
    /// (max(1, ‖x₀‖∞)/‖xⱼ‖∞)^(1/j)), both with the safety factor
    /// exp(−0.7/(p − 1)) heyoka uses; the norms are over every coordinate
    /// and velocity. At the order the tolerance asks for the asymptotic step
    /// is the shorter; at a lower order (a trial's) the first one is. The
    /// asymptotic step is Jorba & Zou's for the order the tolerance asks
    /// for, so with a [`fixed_order`](Self::fixed_order) only the first
    /// estimate bounds the step. A series whose last two orders vanish (a
    /// polynomial motion) takes the longest step.
    pub fn step<const N: usize>(&self, s: &Series<N>) -> f64 {
        Plan::new(*self).step(s)
    }
}

/// Taylor's settings with what every step reads worked out once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Plan {
    pub method: Taylor,
    /// [`Taylor::order`], or [`Taylor::order_for`] the model.
    pub order: usize,
    log_tolerance: f64,
    /// ln of the asymptotic step's factor, e⁻², or +∞ where only the
    /// truncation bounds the step (a fixed order).
    log_asymptotic: f64,
}

impl Plan {
    /// At the order the tolerance asks for ([`Taylor::order`]).
    pub fn new(method: Taylor) -> Self {
        Self {
            method,
            order: method.order(),
            log_tolerance: libm::log(method.tolerance),
            log_asymptotic: match method.fixed_order {
                Some(_) => f64::INFINITY,
                None => -2.0,
            },
        }
    }

    /// At the order [`Taylor::order_for`] picks for a model; above the
    /// tolerance's order, only the last two terms bound the step, as at a
    /// fixed order.
    pub fn fitted(self, work: Option<SeriesWork>, n: usize, walls: usize) -> Self {
        let order = self.method.order_for(work, n, walls);
        Self {
            order,
            log_asymptotic: if order > self.order {
                f64::INFINITY
            } else {
                self.log_asymptotic
            },
            ..self
        }
    }

    /// [`Taylor::step`].
    pub fn step<const N: usize>(&self, s: &Series<N>) -> f64 {
        self.length(&self.reach(s, s.order))
    }

    /// What the step estimates read off the series `s` truncated at order
    /// p (2 ≤ p ≤ `s.order`): ‖x₀‖∞, ‖x_{p−1}‖∞ and ‖xₚ‖∞, in one pass; a
    /// NaN is passed over (the state evaluated on the step catches it). The
    /// coefficients up to p are the same whatever order the series was
    /// computed to, so a longer series tells what a shorter one would have
    /// done.
    pub fn reach<const N: usize>(&self, s: &Series<N>, p: usize) -> Reach {
        let mut norms = [0.0f64; 3];
        for i in 0..N {
            for (m, j) in norms.iter_mut().zip([0, p - 1, p]) {
                for x in [libm::fabs(s.q[i][j]), libm::fabs(s.v[i][j])] {
                    if x > *m {
                        *m = x;
                    }
                }
            }
        }
        Reach {
            p,
            scale: norms[0].max(1.0),
            last: [norms[1], norms[2]],
        }
    }

    /// What the step estimates read off one more series along the step, a
    /// wall's f of order p (2 ≤ p ≤ its order), in the terms of `r`: a
    /// root of f is searched only where f's own series converges, so its
    /// last two terms bound the step as the motion's do, with f's own scale
    /// max(1, |f₀|). `r` then covers an instant only where both did; NaN
    /// is passed over as in [`Plan::reach`].
    pub fn tighten(&self, r: &mut Reach, f: &Coefficients) {
        debug_assert!(r.p >= 2 && r.p < CAPACITY);
        let p = r.p;
        // ‖fⱼ‖τʲ ≤ ε max(1, |f₀|) is ‖fⱼ‖ (scale / max(1, |f₀|)) τʲ ≤ ε scale.
        let ratio = r.scale / libm::fabs(f[0]).max(1.0);
        for (m, j) in r.last.iter_mut().zip([p - 1, p]) {
            let x = libm::fabs(f[j]) * ratio;
            if x > *m {
                *m = x;
            }
        }
    }

    /// The step's length (see [`Taylor::step`]).
    pub fn length(&self, r: &Reach) -> f64 {
        let (log_eps, asymptotic) = (self.log_tolerance, self.log_asymptotic);
        // In logarithms: ln h = ln ρⱼ + min(ln ε / j, −2) − 0.7/(p − 1)
        // (without the −2 at a fixed order), a logarithm per order read and
        // one exponential per step.
        let log_step = |j: usize, x: f64| {
            if x == 0.0 {
                f64::INFINITY
            } else {
                let j = j as f64;
                libm::log(r.scale / x) / j + (log_eps / j).min(asymptotic)
            }
        };
        let p = r.p;
        let log_h = log_step(p - 1, r.last[0]).min(log_step(p, r.last[1]));
        if log_h == f64::INFINITY {
            return self.method.max_step;
        }
        libm::exp(log_h - 0.7 / (p - 1) as f64).min(self.method.max_step)
    }

    /// Whether τ ≥ 0 is within the step, τ ≤ [`Plan::length`], decided
    /// without its logarithms and exponential: for each j ∈ {p − 1, p},
    /// τ ≤ hⱼ is ‖xⱼ‖ (τ e^(0.7/(p−1)))ʲ ≤ max(1, ‖x₀‖) ε, and where the
    /// asymptotic bound applies also ‖xⱼ‖ (τ e^(0.7/(p−1)))ʲ e²ʲ ≤
    /// max(1, ‖x₀‖) (its factor is e⁻², the one finite value
    /// `log_asymptotic` takes). Where the power leaves the normal range of
    /// f64 the length itself decides.
    pub fn covers(&self, r: &Reach, tau: f64) -> bool {
        debug_assert!(self.log_asymptotic == -2.0 || self.log_asymptotic == f64::INFINITY);
        if tau.is_nan() || tau > self.method.max_step {
            return false;
        }
        if tau == 0.0 {
            return true;
        }
        let p = r.p;
        let u = tau * UNSAFETY[p];
        let below = powi(u, p - 1);
        for (j, x, power) in [(p - 1, r.last[0], below), (p, r.last[1], below * u)] {
            if x == 0.0 {
                continue;
            }
            if !(f64::MIN_POSITIVE..f64::INFINITY).contains(&power) {
                return tau <= self.length(r);
            }
            // x is positive (NaN is passed over in the norms), so the term
            // is a number or +∞.
            let term = x * power;
            if term > r.scale * self.method.tolerance {
                return false;
            }
            if self.log_asymptotic < f64::INFINITY && term * E_2J[j] > r.scale {
                return false;
            }
        }
        true
    }

    /// A length at least [`Plan::length`], without logarithms: the
    /// truncation estimate of order p (or p − 1 where xₚ vanishes) without
    /// the safety factor, rounded up to a power of two. Infinite where both
    /// orders vanish, as the step is then (unless `max_step` bounds it).
    pub fn beyond(&self, r: &Reach) -> f64 {
        let (j, x) = if r.last[1] != 0.0 {
            (r.p, r.last[1])
        } else {
            (r.p - 1, r.last[0])
        };
        if x == 0.0 {
            return self.method.max_step;
        }
        let y = r.scale * self.method.tolerance / x;
        if !(f64::MIN_POSITIVE..f64::INFINITY).contains(&y) {
            return self.method.max_step;
        }
        // y < 2^(e+1), so y^(1/j) < 2^⌈(e+1)/j⌉.
        let e = libm::ilogb(y) + 1;
        let j = j as i32;
        let k = -((-e).div_euclid(j));
        libm::scalbn(1.0, k).min(self.method.max_step)
    }
}

/// What [`Plan::length`] and [`Plan::covers`] read off a series truncated
/// at order p.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Reach {
    p: usize,
    /// max(1, ‖x₀‖∞).
    scale: f64,
    /// ‖x_{p−1}‖∞ and ‖xₚ‖∞.
    last: [f64; 2],
}

/// xⁿ by squaring.
fn powi(mut x: f64, mut n: usize) -> f64 {
    let mut acc = 1.0;
    while n > 0 {
        if n & 1 == 1 {
            acc *= x;
        }
        x *= x;
        n >>= 1;
    }
    acc
}

/// e^(0.7/(p − 1)) at order p (from 2), the inverse of the safety factor.
const UNSAFETY: [f64; CAPACITY] = {
    let mut t = [1.0; CAPACITY];
    let mut p = 2;
    while p < CAPACITY {
        // Σ xᵏ/k! for x ≤ 0.7: 30 terms are exact to rounding.
        let x = 0.7 / (p - 1) as f64;
        let (mut term, mut sum, mut k) = (1.0, 1.0, 1);
        while k < 30 {
            term *= x / k as f64;
            sum += term;
            k += 1;
        }
        t[p] = sum;
        p += 1;
    }
    t
};

/// e^(2j) for j up to [`MAX_ORDER`].
const E_2J: [f64; CAPACITY] = {
    let mut t = [1.0; CAPACITY];
    let mut j = 1;
    while j < CAPACITY {
        t[j] = t[j - 1] * (core::f64::consts::E * core::f64::consts::E);
        j += 1;
    }
    t
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_from_tolerance() {
        let t = Taylor::default();
        assert_eq!(t.order(), 20);
        let loose = Taylor {
            tolerance: 1e-6,
            ..t
        };
        assert_eq!(loose.order(), 8);
        let fixed = Taylor {
            fixed_order: Some(28),
            ..loose
        };
        assert_eq!(fixed.order(), 28);
        assert!(fixed.valid());
        // The smallest tolerance asks for the highest order; a smaller one
        // (or none, or NaN) is refused.
        let finest = Taylor {
            tolerance: Taylor::MIN_TOLERANCE,
            ..t
        };
        assert!(finest.valid());
        assert!(-0.5 * libm::log(Taylor::MIN_TOLERANCE) + 1.0 <= MAX_ORDER as f64);
        assert_eq!(finest.order(), MAX_ORDER);
        for tolerance in [Taylor::MIN_TOLERANCE / 2.0, 1e-300, 0.0, 1.0, f64::NAN] {
            let bad = Taylor { tolerance, ..t };
            assert!(!bad.valid(), "tolerance {tolerance:e}");
        }
        for p in [0, 1, MAX_ORDER + 1] {
            let bad = Taylor {
                fixed_order: Some(p),
                ..t
            };
            assert!(!bad.valid(), "order {p}");
        }
    }

    /// The order from the series' work: the tolerance's where the work is
    /// unknown or the order fixed; higher the lighter the series, down to
    /// the tolerance's + 1 for a heavy one (at the tolerance's order the
    /// step is capped at ρ/e²); the cheapest per unit of time by the model
    /// it states.
    #[test]
    fn order_from_the_series_work() {
        use crate::taylor::Work;
        let t = Taylor::default();
        let work = |convolutions: usize, operations: usize| SeriesWork {
            motion: Work {
                operations,
                convolutions,
            },
            walls: Work {
                operations: 1,
                convolutions: 0,
            },
        };
        assert_eq!(t.order_for(None, 6, 1), 20);
        let fixed = Taylor {
            fixed_order: Some(22),
            ..t
        };
        assert_eq!(fixed.order_for(Some(work(0, 0)), 6, 1), 22);
        // ball_wall_euler's q̈ (12 convolutions in 23 operations), whose
        // measured time per unit of motion is least at orders 24 to 28.
        assert_eq!(t.order_for(Some(work(12, 23)), 5, 1), 26);
        // A constant q̈: only the step's other work, which grows like p.
        assert_eq!(t.order_for(Some(work(0, 0)), 6, 1), MAX_ORDER);
        let mut last = MAX_ORDER;
        for c in [0, 10, 100, 1000, 100_000] {
            let p = t.order_for(Some(work(c, 2 * c)), 6, 1);
            assert!(p <= last && p > t.order(), "{c} convolutions: order {p}");
            last = p;
        }
        assert_eq!(last, 21);
        // Lighter at a looser tolerance.
        let loose = Taylor {
            tolerance: 1e-10,
            ..t
        };
        let p = loose.order_for(Some(work(12, 23)), 5, 1);
        assert!(p > loose.order() && p < 26, "{p}");
        // The plan above the tolerance's order steps by the truncation
        // estimate alone.
        let plan = Plan::new(t).fitted(Some(work(11, 34)), 5, 1);
        assert_eq!(plan.order, 26);
        assert_eq!(plan.log_asymptotic, f64::INFINITY);
        assert_eq!(Plan::new(t).fitted(None, 5, 1), Plan::new(t));
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
        // At a lower order the last two terms bound the step:
        // h = min over j ∈ {7, 8} of (ε/‖x_j‖)^(1/j), shorter than ρ/e².
        s.order = 8;
        let eps = t.tolerance;
        let h8 = t.step(&s);
        let trunc = libm::pow(eps / 8.0, 1.0 / 7.0).min(libm::pow(eps / 9.0, 1.0 / 8.0));
        let want = trunc * libm::exp(-0.7 / 7.0);
        assert!(libm::fabs(h8 - want) <= 1e-14 * want, "{h8} {want}");
        let rho8 = libm::pow(1.0 / 8.0, 1.0 / 7.0).min(libm::pow(1.0 / 9.0, 1.0 / 8.0));
        assert!(h8 < rho8 / e2 * libm::exp(-0.7 / 7.0));
        // A fixed order above the tolerance's: the last two terms alone, so
        // the step is longer than ρ/e² (the tolerance's order would cap it
        // there).
        s.order = 30;
        let fixed = Taylor {
            fixed_order: Some(30),
            ..t
        };
        let h30 = fixed.step(&s);
        let trunc = libm::pow(eps / 30.0, 1.0 / 29.0).min(libm::pow(eps / 31.0, 1.0 / 30.0));
        let want = trunc * libm::exp(-0.7 / 29.0);
        assert!(libm::fabs(h30 - want) <= 1e-14 * want, "{h30} {want}");
        let rho30 = libm::pow(1.0 / 30.0, 1.0 / 29.0).min(libm::pow(1.0 / 31.0, 1.0 / 30.0));
        assert!(h30 > 2.0 * rho30 / e2 * libm::exp(-0.7 / 29.0));
        assert!(t.step(&s) < 1.0001 * rho30 / e2 * libm::exp(-0.7 / 29.0));
        // A polynomial motion: no limit but the longest step.
        let mut line = Series::<1>::at(&[0.0], &[1.0]);
        line.q[0][1] = 1.0;
        line.order = 20;
        assert_eq!(t.step(&line), f64::INFINITY);
    }

    /// A wall's series bounds the step as the motion's does: tightened by
    /// it, the step is the shorter of the motion's and the one f's series
    /// alone would allow in its own scale, max(1, |f₀|), and `covers`
    /// agrees; a wall whose series ends below order p − 1 (a flight's f of
    /// degree 2) changes nothing.
    #[test]
    fn wall_series_bound_the_step() {
        for plan in [
            Plan::new(Taylor::default()),
            Plan::new(Taylor {
                fixed_order: Some(25),
                ..Taylor::default()
            }),
        ] {
            let p = plan.order;
            // The motion x(t) = 1/(1 − t): radius of convergence 1.
            let mut s = Series::<1>::at(&[1.0], &[1.0]);
            s.order = p;
            s.q[0] = [1.0; CAPACITY];
            s.v[0] = core::array::from_fn(|k| (k + 1) as f64);
            let motion = plan.reach(&s, p);
            for (f0, radius) in [(3.0, 0.1), (0.25, 0.1), (1e3, 10.0), (-2.0, 0.01)] {
                // f = f₀/(1 − t/radius): fₖ = f₀ radius⁻ᵏ.
                let f: Coefficients = core::array::from_fn(|k| f0 * libm::pow(radius, -(k as f64)));
                let mut tightened = motion;
                plan.tighten(&mut tightened, &f);
                let mut alone = Series::<1>::at(&[f0], &[0.0]);
                alone.order = p;
                alone.q[0] = f;
                alone.v[0] = [0.0; CAPACITY];
                let wall = plan.reach(&alone, p);
                let (h, hm, hw) = (
                    plan.length(&tightened),
                    plan.length(&motion),
                    plan.length(&wall),
                );
                assert!(
                    (h - hm.min(hw)).abs() <= 1e-14 * h,
                    "{f0} {radius}: {h} {hm} {hw}"
                );
                assert_eq!(radius < 1.0, hw < hm, "{f0} {radius}: {hm} {hw}");
                for x in [0.5, 0.999, 1.001, 2.0] {
                    assert_eq!(plan.covers(&tightened, x * h), x < 1.0, "{f0} {radius} {x}");
                }
            }
            let mut flight = [0.0; CAPACITY];
            flight[..3].copy_from_slice(&[0.5, -1.0, 3.0]);
            let mut r = motion;
            plan.tighten(&mut r, &flight);
            assert_eq!(r, motion);
        }
    }

    /// Whether an instant is within the step, decided by powers, agrees
    /// with the step's length from logarithms at every order, with and
    /// without the asymptotic bound and a largest step, for norms from
    /// 1e-30 to 1e30 and instants from 1e-6 to 10⁶ times the step (those
    /// within 1e-12 of it either way, where rounding may decide, left
    /// out); and the cheap window is never shorter than the step.
    #[test]
    fn covers_agrees_with_the_length() {
        let mut uniform = crate::simulate::uniform(0x2545_f491_4f6c_dd1du64);
        let plans = [
            Plan::new(Taylor::default()),
            Plan::new(Taylor {
                fixed_order: Some(25),
                ..Taylor::default()
            }),
            Plan::new(Taylor {
                tolerance: 1e-10,
                max_step: 0.3,
                ..Taylor::default()
            }),
        ];
        let mut checked = 0;
        for plan in plans {
            for p in 2..=MAX_ORDER {
                for case in 0..40 {
                    let mut norm = || libm::pow(10.0, 60.0 * uniform() - 30.0);
                    let last = match case % 8 {
                        0 => [0.0, norm()],
                        1 => [norm(), 0.0],
                        _ => [norm(), norm()],
                    };
                    let r = Reach {
                        p,
                        scale: 1.0f64.max(libm::pow(10.0, 4.0 * uniform())),
                        last,
                    };
                    let h = plan.length(&r);
                    assert!(plan.beyond(&r) >= h, "{r:?}: {h}");
                    assert!(plan.covers(&r, 0.0));
                    let tau = h * libm::pow(10.0, 12.0 * uniform() - 6.0);
                    if (tau / h - 1.0).abs() < 1e-12 {
                        continue;
                    }
                    assert_eq!(plan.covers(&r, tau), tau <= h, "{r:?}: τ {tau}, h {h}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 3000, "{checked}");
        // Both last orders zero: every instant up to the largest step.
        let r = Reach {
            p: 10,
            scale: 1.0,
            last: [0.0, 0.0],
        };
        assert!(plans[0].covers(&r, 1e300));
        assert!(plans[2].covers(&r, 0.3) && !plans[2].covers(&r, 0.31));
        assert_eq!(plans[0].beyond(&r), f64::INFINITY);
        // An infinite norm: no step.
        let r = Reach {
            p: 10,
            scale: 1.0,
            last: [f64::INFINITY, 1.0],
        };
        assert_eq!(plans[0].length(&r), 0.0);
        assert!(!plans[0].covers(&r, 1e-300));
    }
}
