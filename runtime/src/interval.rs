//! Intervals: a range that holds every value a quantity takes over a box of
//! its inputs. Generated models evaluate each wall's f and its gradient on
//! intervals (`surface_bounds`, `normal_bounds`), so that the simulator can
//! prove a stretch of a step free of walls, however narrow a dip of f
//! between its samples would be.
//!
//! Every operation returns an interval that contains the exact result for
//! every point of its operands' intervals: the four arithmetic operations
//! are widened by one ulp outwards (f64 rounds each to nearest), the libm
//! functions by a few ulps, and anything undefined somewhere on the
//! operands (a square root of a range reaching below zero, a quotient by a
//! range holding zero, a NaN) is [`Interval::ENTIRE`], which proves
//! nothing.

use core::ops::{Add, Div, Mul, Neg, Sub};

use crate::libm;

/// A closed range [lo, hi] of reals (possibly infinite at either end).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// The lower bound.
    pub lo: f64,
    /// The upper bound.
    pub hi: f64,
}

/// ulps by which the result of a libm function is widened: musl's
/// functions (which the `libm` crate ports) are within one ulp.
const LIBM_ULPS: f64 = 4.0;

impl Interval {
    /// Every real: what is known of a value undefined somewhere on the box.
    pub const ENTIRE: Self = Self {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// [lo, hi]; `ENTIRE` if either is NaN or lo > hi.
    #[inline]
    pub fn new(lo: f64, hi: f64) -> Self {
        if lo <= hi {
            Self { lo, hi }
        } else {
            Self::ENTIRE
        }
    }

    /// The single number x.
    #[inline]
    pub fn point(x: f64) -> Self {
        Self::new(x, x)
    }

    /// The smallest interval holding both a and b.
    pub fn hull(a: f64, b: f64) -> Self {
        Self::new(a.min(b), a.max(b))
    }

    /// Whether x lies in it.
    pub fn contains(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// hi − lo.
    pub fn width(&self) -> f64 {
        self.hi - self.lo
    }

    /// [lo, hi] one ulp wider at each end: a correctly rounded operation's
    /// bounds.
    #[inline]
    fn rounded(lo: f64, hi: f64) -> Self {
        Self::new(lo.next_down(), hi.next_up())
    }

    /// [lo, hi] widened by `ulps` of each bound's size (and by the smallest
    /// normal number, for bounds at or near zero).
    fn widened(lo: f64, hi: f64, ulps: f64) -> Self {
        let by = |x: f64| ulps * f64::EPSILON * libm::fabs(x) + f64::MIN_POSITIVE;
        Self::new(lo - by(lo), hi + by(hi))
    }

    /// A monotone libm function's values at the ends, widened; `increasing`
    /// says which end gives the lower bound.
    fn monotone(self, f: impl Fn(f64) -> f64, increasing: bool) -> Self {
        let (a, b) = (f(self.lo), f(self.hi));
        let (lo, hi) = if increasing { (a, b) } else { (b, a) };
        Self::widened(lo, hi, LIBM_ULPS)
    }

    /// Its intersection with [lo, hi], for functions whose range is known
    /// (a widened tanh stays within [−1, 1]).
    fn within(self, lo: f64, hi: f64) -> Self {
        Self::new(self.lo.max(lo), self.hi.min(hi))
    }

    /// 1 / x.
    pub fn recip(self) -> Self {
        Self::point(1.0) / self
    }

    /// x · x · … · x, `n` factors (n ≥ 1): as tight as the exact power, not
    /// the product of n independent ranges.
    pub fn powi(self, n: u32) -> Self {
        if n <= 1 {
            return self;
        }
        let power = |x: f64| {
            let mut acc = x;
            for _ in 1..n {
                acc *= x;
            }
            acc
        };
        // Each product rounds once: n − 1 half-ulps at most, doubled.
        self.whole_power(power, n % 2 == 1, n as f64)
    }

    /// xⁿ for a whole n ≥ 1 from `power` (within `ulps`) at the ends: an
    /// odd power increases, an even one is least at 0.
    fn whole_power(self, power: impl Fn(f64) -> f64, odd: bool, ulps: f64) -> Self {
        if odd || self.lo >= 0.0 {
            Self::widened(power(self.lo), power(self.hi), ulps)
        } else if self.hi <= 0.0 {
            Self::widened(power(self.hi), power(self.lo), ulps)
        } else {
            let top = libm::fabs(self.lo).max(self.hi);
            Self::widened(0.0, power(top), ulps).within(0.0, f64::INFINITY)
        }
    }

    /// libm's pow(x, e): for a whole e as [`Interval::powi`] does (any
    /// sign of x), otherwise on x ≥ 0 only.
    pub fn pow(self, e: f64) -> Self {
        if e.is_nan() {
            return Self::ENTIRE;
        }
        let whole = libm::trunc(e) == e && libm::fabs(e) < 9.0e15;
        if whole && e < 0.0 {
            return self.pow(-e).recip();
        }
        if whole {
            let odd = libm::fmod(e, 2.0) == 1.0;
            return self.whole_power(|x| libm::pow(x, e), odd, LIBM_ULPS);
        }
        if self.lo < 0.0 || self.lo.is_nan() {
            return Self::ENTIRE;
        }
        self.monotone(|x| libm::pow(x, e), e > 0.0)
            .within(0.0, f64::INFINITY)
    }

    /// √x (undefined below zero).
    pub fn sqrt(self) -> Self {
        if self.lo < 0.0 || self.lo.is_nan() {
            return Self::ENTIRE;
        }
        Self::rounded(libm::sqrt(self.lo), libm::sqrt(self.hi)).within(0.0, f64::INFINITY)
    }

    /// eˣ.
    pub fn exp(self) -> Self {
        self.monotone(libm::exp, true).within(0.0, f64::INFINITY)
    }

    /// The natural logarithm (undefined below zero; −∞ at zero).
    pub fn log(self) -> Self {
        if self.lo < 0.0 || self.lo.is_nan() {
            return Self::ENTIRE;
        }
        self.monotone(libm::log, true)
    }

    /// The arctangent.
    pub fn atan(self) -> Self {
        let half_pi = core::f64::consts::FRAC_PI_2.next_up();
        self.monotone(libm::atan, true).within(-half_pi, half_pi)
    }

    /// The arcsine (undefined outside [−1, 1]).
    pub fn asin(self) -> Self {
        if self.lo.is_nan() || self.hi.is_nan() || self.lo < -1.0 || self.hi > 1.0 {
            return Self::ENTIRE;
        }
        let half_pi = core::f64::consts::FRAC_PI_2.next_up();
        self.monotone(libm::asin, true).within(-half_pi, half_pi)
    }

    /// The arccosine (undefined outside [−1, 1]).
    pub fn acos(self) -> Self {
        if self.lo.is_nan() || self.hi.is_nan() || self.lo < -1.0 || self.hi > 1.0 {
            return Self::ENTIRE;
        }
        let pi = core::f64::consts::PI.next_up();
        self.monotone(libm::acos, false).within(0.0, pi)
    }

    /// The hyperbolic sine.
    pub fn sinh(self) -> Self {
        self.monotone(libm::sinh, true)
    }

    /// The hyperbolic cosine (least at zero).
    pub fn cosh(self) -> Self {
        let c = if self.lo >= 0.0 {
            self.monotone(libm::cosh, true)
        } else if self.hi <= 0.0 {
            self.monotone(libm::cosh, false)
        } else {
            let top = libm::cosh(self.lo).max(libm::cosh(self.hi));
            Self::widened(1.0, top, LIBM_ULPS)
        };
        c.within(1.0, f64::INFINITY)
    }

    /// The hyperbolic tangent.
    pub fn tanh(self) -> Self {
        self.monotone(libm::tanh, true).within(-1.0, 1.0)
    }

    /// The inverse hyperbolic sine.
    pub fn asinh(self) -> Self {
        self.monotone(libm::asinh, true)
    }

    /// The inverse hyperbolic cosine (undefined below 1).
    pub fn acosh(self) -> Self {
        if self.lo < 1.0 || self.lo.is_nan() {
            return Self::ENTIRE;
        }
        self.monotone(libm::acosh, true).within(0.0, f64::INFINITY)
    }

    /// The inverse hyperbolic tangent (undefined outside (−1, 1)).
    pub fn atanh(self) -> Self {
        if self.lo.is_nan() || self.hi.is_nan() || self.lo <= -1.0 || self.hi >= 1.0 {
            return Self::ENTIRE;
        }
        self.monotone(libm::atanh, true)
    }

    /// The sine.
    pub fn sin(self) -> Self {
        // Extremes at (m + ½)π: +1 for even m, −1 for odd.
        self.periodic(libm::sin, 0.5)
    }

    /// The cosine.
    pub fn cos(self) -> Self {
        // Extremes at mπ: +1 for even m, −1 for odd.
        self.periodic(libm::cos, 0.0)
    }

    /// The tangent, as sin/cos (everything where cos may be 0).
    pub fn tan(self) -> Self {
        let (s, c) = self.sincos();
        s / c
    }

    /// Sine and cosine.
    pub fn sincos(self) -> (Self, Self) {
        (self.sin(), self.cos())
    }

    /// sin or cos, whose extremes ±1 lie at (m + `offset`)π, +1 for even m.
    fn periodic(self, f: fn(f64) -> f64, offset: f64) -> Self {
        let Some((first, last)) = self.extremes(offset) else {
            return Self::new(-1.0, 1.0);
        };
        let (a, b) = (f(self.lo), f(self.hi));
        let mut out = Self::widened(a.min(b), a.max(b), LIBM_ULPS);
        let mut m = first;
        while m <= last {
            if libm::fmod(m, 2.0) == 0.0 {
                out.hi = 1.0;
            } else {
                out.lo = -1.0;
            }
            m += 1.0;
        }
        out.within(-1.0, 1.0)
    }

    /// The whole numbers m, first to last, for which (m + `offset`)π may
    /// lie in the interval (possibly one more at each end: the test is
    /// made on a slightly wider interval, as π and the quotients round);
    /// `None` when the interval is too wide or not finite for that to be
    /// worth it (it holds at least one of each parity then, or proves
    /// nothing).
    fn extremes(&self, offset: f64) -> Option<(f64, f64)> {
        let width = self.width();
        if width.is_nan() || width >= 2.0 * core::f64::consts::PI {
            return None;
        }
        let pi = core::f64::consts::PI;
        let (a, b) = (self.lo / pi - offset, self.hi / pi - offset);
        let slack = 1e-9 * (1.0 + libm::fabs(a).max(libm::fabs(b)));
        let (first, last) = (libm::ceil(a - slack), libm::floor(b + slack));
        Some((first, last))
    }
}

impl Add for Interval {
    type Output = Self;
    #[inline]
    fn add(self, b: Self) -> Self {
        Self::rounded(self.lo + b.lo, self.hi + b.hi)
    }
}

impl Sub for Interval {
    type Output = Self;
    #[inline]
    fn sub(self, b: Self) -> Self {
        Self::rounded(self.lo - b.hi, self.hi - b.lo)
    }
}

impl Neg for Interval {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self::new(-self.hi, -self.lo)
    }
}

impl Mul for Interval {
    type Output = Self;
    #[inline]
    fn mul(self, b: Self) -> Self {
        let p = [
            self.lo * b.lo,
            self.lo * b.hi,
            self.hi * b.lo,
            self.hi * b.hi,
        ];
        // 0 · ∞ is NaN: no bound then.
        if p.iter().any(|x| x.is_nan()) {
            return Self::ENTIRE;
        }
        let lo = p.iter().fold(f64::INFINITY, |m, &x| m.min(x));
        let hi = p.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x));
        Self::rounded(lo, hi)
    }
}

impl Div for Interval {
    type Output = Self;
    fn div(self, b: Self) -> Self {
        if !(b.lo > 0.0 || b.hi < 0.0) {
            return Self::ENTIRE;
        }
        let q = [
            self.lo / b.lo,
            self.lo / b.hi,
            self.hi / b.lo,
            self.hi / b.hi,
        ];
        if q.iter().any(|x| x.is_nan()) {
            return Self::ENTIRE;
        }
        let lo = q.iter().fold(f64::INFINITY, |m, &x| m.min(x));
        let hi = q.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x));
        Self::rounded(lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::Interval;
    use crate::libm;

    /// Points spread over [lo, hi], its ends included.
    fn points(x: Interval) -> impl Iterator<Item = f64> {
        (0..=200).map(move |k| x.lo + (x.hi - x.lo) * k as f64 / 200.0)
    }

    /// f's interval over `x` holds f at every sampled point of `x`, and is
    /// within `slack` of their range (not needlessly wide).
    fn encloses(name: &str, x: Interval, f: fn(f64) -> f64, fi: fn(Interval) -> Interval) {
        let y = fi(x);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for t in points(x) {
            let v = f(t);
            assert!(y.contains(v), "{name}({t}) = {v} outside {y:?} for {x:?}");
            lo = lo.min(v);
            hi = hi.max(v);
        }
        let slack = 1e-6 * (1.0 + hi.abs().max(lo.abs()));
        assert!(
            y.lo >= lo - slack - 0.02 * (hi - lo) && y.hi <= hi + slack + 0.02 * (hi - lo),
            "{name}: {y:?} much wider than [{lo}, {hi}] for {x:?}"
        );
    }

    #[test]
    fn functions_enclose_their_values_tightly() {
        let boxes = [
            Interval::new(-0.3, 0.2),
            Interval::new(0.1, 0.9),
            Interval::new(-3.5, -0.5),
            Interval::new(1.0, 5.0),
            Interval::new(-7.0, 7.0),
            Interval::new(100.0, 102.0),
            Interval::new(-1.0, 1.0),
        ];
        for x in boxes {
            encloses("sin", x, libm::sin, Interval::sin);
            encloses("cos", x, libm::cos, Interval::cos);
            encloses("exp", x, libm::exp, Interval::exp);
            encloses("atan", x, libm::atan, Interval::atan);
            encloses("sinh", x, libm::sinh, Interval::sinh);
            encloses("cosh", x, libm::cosh, Interval::cosh);
            encloses("tanh", x, libm::tanh, Interval::tanh);
            encloses("square", x, |t| t * t, |x| x.powi(2));
            encloses("cube", x, |t| t * t * t, |x| x.powi(3));
            encloses("fourth", x, |t| libm::pow(t, 4.0), |x| x.pow(4.0));
            encloses("inverse square", x, |t| 1.0 / (t * t), |x| x.pow(-2.0));
            if x.lo >= 0.0 {
                encloses("sqrt", x, libm::sqrt, Interval::sqrt);
                encloses("log", x, libm::log, Interval::log);
                encloses("pow 3/2", x, |t| libm::pow(t, 1.5), |x| x.pow(1.5));
            } else {
                // Undefined on part of the box: no bound.
                assert_eq!(x.sqrt(), Interval::ENTIRE);
                assert_eq!(x.log(), Interval::ENTIRE);
                assert_eq!(x.pow(1.5), Interval::ENTIRE);
            }
            if x.lo >= -1.0 && x.hi <= 1.0 {
                encloses("asin", x, libm::asin, Interval::asin);
                encloses("acos", x, libm::acos, Interval::acos);
            } else {
                assert_eq!(x.asin(), Interval::ENTIRE);
            }
        }
        // Wider than a period: all the sine can be.
        assert_eq!(Interval::new(0.0, 10.0).sin(), Interval::new(-1.0, 1.0));
    }

    #[test]
    fn arithmetic_encloses_every_combination() {
        let (a, b) = (Interval::new(-1.5, 2.0), Interval::new(0.25, 3.0));
        for x in points(a) {
            for y in points(b) {
                assert!((a + b).contains(x + y));
                assert!((a - b).contains(x - y));
                assert!((a * b).contains(x * y));
                assert!((a / b).contains(x / y));
                assert!((-a).contains(-x));
            }
        }
        // Rounding: 0.1 + 0.2 is not 0.3 in f64, but the interval holds
        // both the computed sum and the exact one's neighbours.
        let s = Interval::point(0.1) + Interval::point(0.2);
        assert!(s.lo < 0.1 + 0.2 && s.hi > 0.1 + 0.2);
        // A quotient by a range through zero, and 0 · ∞: no bound.
        assert_eq!(a / Interval::new(-1.0, 1.0), Interval::ENTIRE);
        assert_eq!(
            Interval::new(0.0, 1.0) * Interval::new(1.0, f64::INFINITY),
            Interval::ENTIRE
        );
        // Two factors are two independent values, even with equal ranges
        // (x · y over x, y ∈ [−1.5, 2]); a square is `powi`.
        assert!((a * a).lo < 0.0);
        assert_eq!(a.powi(2).lo, 0.0);
        // NaN anywhere proves nothing.
        assert_eq!(Interval::new(f64::NAN, 1.0), Interval::ENTIRE);
    }
}
