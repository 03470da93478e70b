//! Taylor-mode arithmetic: the normalised Taylor coefficients of a function
//! of time, x(t₀ + τ) = Σₖ xₖ τᵏ, one order at a time.
//!
//! Generated models call these recurrences instruction by instruction over
//! their straight-line programs (the generator's Taylor transform): each
//! function computes coefficient `k` of its result from coefficients
//! `0..=k` of its operands (and `0..k` of its own result), so a whole
//! program advances one order in one pass. They are the standard
//! recurrences of automatic differentiation (Griewank & Walther,
//! *Evaluating Derivatives*, ch. 13; Jorba & Zou, *Exp. Math.* 14, 2005):
//!
//! | result | coefficient k |
//! |---|---|
//! | a·b | Σⱼ₌₀..ₖ aⱼ bₖ₋ⱼ |
//! | 1/a | −(Σⱼ₌₁..ₖ aⱼ cₖ₋ⱼ)/a₀ |
//! | √a | (aₖ − Σⱼ₌₁..ₖ₋₁ cⱼ cₖ₋ⱼ)/(2c₀) |
//! | a^α | Σⱼ₌₀..ₖ₋₁ (α(k−j) − j) aₖ₋ⱼ cⱼ /(k a₀) |
//! | eᵃ | Σⱼ₌₁..ₖ j aⱼ cₖ₋ⱼ / k |
//! | ln a | (aₖ − Σⱼ₌₁..ₖ₋₁ j cⱼ aₖ₋ⱼ / k)/a₀ |
//! | sin a, cos a | s: Σⱼ₌₁..ₖ j aⱼ cₖ₋ⱼ / k, c: −Σⱼ₌₁..ₖ j aⱼ sₖ₋ⱼ / k |
//!
//! At k = 0 each is the function's value. No heap: coefficients live in
//! fixed arrays of [`CAPACITY`].

/// Coefficients kept per series: orders 0 to [`MAX_ORDER`].
pub const CAPACITY: usize = 32;

/// The highest order a series holds.
pub const MAX_ORDER: usize = CAPACITY - 1;

/// The coefficients of one function of time.
pub type Coefficients = [f64; CAPACITY];

/// The Taylor series of a state (q(t₀ + τ), q̇(t₀ + τ)) in τ: `q[i][k]` is
/// the k-th normalised coefficient of coordinate i, `v[i][k]` that of
/// velocity i.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Series<const N: usize> {
    /// Coefficients of the coordinates.
    pub q: [Coefficients; N],
    /// Coefficients of the velocities.
    pub v: [Coefficients; N],
    /// The highest order filled in.
    pub order: usize,
}

impl<const N: usize> Series<N> {
    /// The series of order 0 at the state (q, v): only the values.
    pub fn at(q: &[f64; N], v: &[f64; N]) -> Self {
        let mut s = Self {
            q: [[0.0; CAPACITY]; N],
            v: [[0.0; CAPACITY]; N],
            order: 0,
        };
        for i in 0..N {
            s.q[i][0] = q[i];
            s.v[i][0] = v[i];
        }
        s
    }

    /// The state at τ on the series (Horner's scheme).
    pub fn state(&self, tau: f64) -> ([f64; N], [f64; N]) {
        (
            core::array::from_fn(|i| eval(&self.q[i], self.order, tau)),
            core::array::from_fn(|i| eval(&self.v[i], self.order, tau)),
        )
    }
}

/// Σₖ₌₀..order cₖ τᵏ (Horner's scheme).
pub fn eval(c: &Coefficients, order: usize, tau: f64) -> f64 {
    let mut acc = 0.0;
    for x in c[..=order.min(MAX_ORDER)].iter().rev() {
        acc = acc * tau + x;
    }
    acc
}

/// The value and the first derivative in τ of Σₖ₌₀..order cₖ τᵏ.
pub fn eval_with_derivative(c: &Coefficients, order: usize, tau: f64) -> (f64, f64) {
    let (mut p, mut dp) = (0.0, 0.0);
    for x in c[..=order.min(MAX_ORDER)].iter().rev() {
        dp = dp * tau + p;
        p = p * tau + x;
    }
    (p, dp)
}

/// Coefficient k of a·b.
#[inline]
pub fn mul(a: &Coefficients, b: &Coefficients, k: usize) -> f64 {
    let mut acc = 0.0;
    for (x, y) in a[..=k].iter().zip(b[..=k].iter().rev()) {
        acc += x * y;
    }
    acc
}

/// Coefficient k of a², from a's coefficients (half the products of
/// [`mul`]).
#[inline]
pub fn square(a: &Coefficients, k: usize) -> f64 {
    let mut acc = 0.0;
    for j in 0..k.div_ceil(2) {
        acc += a[j] * a[k - j];
    }
    acc *= 2.0;
    if k % 2 == 0 {
        acc += a[k / 2] * a[k / 2];
    }
    acc
}

/// Coefficient k of c = 1/a, from a's coefficients and c's below k.
#[inline]
pub fn recip(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return 1.0 / a[0];
    }
    let mut acc = 0.0;
    for (x, y) in a[1..=k].iter().zip(c[..k].iter().rev()) {
        acc += x * y;
    }
    -acc * c[0]
}

/// Coefficient k of c = √a, from a's coefficients and c's below k.
#[inline]
pub fn sqrt(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return libm::sqrt(a[0]);
    }
    let mut acc = 0.0;
    for j in 1..k {
        acc += c[j] * c[k - j];
    }
    (a[k] - acc) / (2.0 * c[0])
}

/// Coefficient k of c = a^α (α real), from a's coefficients and c's below
/// k. a₀ must not vanish beyond order 0.
#[inline]
pub fn power(c: &Coefficients, a: &Coefficients, alpha: f64, k: usize) -> f64 {
    if k == 0 {
        return libm::pow(a[0], alpha);
    }
    let mut acc = 0.0;
    for j in 0..k {
        acc += (alpha * (k - j) as f64 - j as f64) * a[k - j] * c[j];
    }
    acc / (k as f64 * a[0])
}

/// Coefficient k of c = exp(a), from a's coefficients and c's below k.
#[inline]
pub fn exp(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return libm::exp(a[0]);
    }
    let mut acc = 0.0;
    for j in 1..=k {
        acc += j as f64 * a[j] * c[k - j];
    }
    acc / k as f64
}

/// Coefficient k of c = ln(a), from a's coefficients and c's below k.
#[inline]
pub fn log(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return libm::log(a[0]);
    }
    let mut acc = 0.0;
    for j in 1..k {
        acc += j as f64 * c[j] * a[k - j];
    }
    (a[k] - acc / k as f64) / a[0]
}

/// Coefficient k of (sin a, cos a), from a's coefficients and those of both
/// below k.
#[inline]
pub fn sin_cos(s: &Coefficients, c: &Coefficients, a: &Coefficients, k: usize) -> (f64, f64) {
    if k == 0 {
        return libm::sincos(a[0]);
    }
    let (mut ss, mut cc) = (0.0, 0.0);
    for j in 1..=k {
        let ja = j as f64 * a[j];
        ss += ja * c[k - j];
        cc += ja * s[k - j];
    }
    let kf = k as f64;
    (ss / kf, -cc / kf)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series of t ↦ t₀ + t (a variable) at t₀.
    fn var(t0: f64) -> Coefficients {
        let mut a = [0.0; CAPACITY];
        a[0] = t0;
        a[1] = 1.0;
        a
    }

    /// Each recurrence against the closed-form series of its function
    /// around t₀ = 0.3 (sin, cos, exp, 1/(1+t), √(1+t), (1+t)^α, ln(1+t)).
    #[test]
    fn recurrences_match_known_series() {
        let p = 20;
        let x = var(0.3);
        let one_plus = var(1.0);
        let (mut s, mut c, mut e) = ([0.0; CAPACITY], [0.0; CAPACITY], [0.0; CAPACITY]);
        let (mut r, mut q, mut w, mut l) = (
            [0.0; CAPACITY],
            [0.0; CAPACITY],
            [0.0; CAPACITY],
            [0.0; CAPACITY],
        );
        for k in 0..=p {
            (s[k], c[k]) = sin_cos(&s, &c, &x, k);
            e[k] = exp(&e, &x, k);
            r[k] = recip(&r, &one_plus, k);
            q[k] = sqrt(&q, &one_plus, k);
            w[k] = power(&w, &one_plus, -1.5, k);
            l[k] = log(&l, &one_plus, k);
        }
        let mut fact = 1.0;
        let mut binom_half = 1.0;
        let mut binom_alpha = 1.0;
        for k in 0..=p {
            if k > 0 {
                fact *= k as f64;
                binom_half *= (0.5 - (k - 1) as f64) / k as f64;
                binom_alpha *= (-1.5 - (k - 1) as f64) / k as f64;
            }
            let (sn, cs) = libm::sincos(0.3);
            let d = match k % 4 {
                0 => (sn, cs),
                1 => (cs, -sn),
                2 => (-sn, -cs),
                _ => (-cs, sn),
            };
            let close = |a: f64, b: f64| libm::fabs(a - b) <= 1e-15 * (1.0 + libm::fabs(b));
            assert!(close(s[k], d.0 / fact), "sin {k}");
            assert!(close(c[k], d.1 / fact), "cos {k}");
            assert!(close(e[k], libm::exp(0.3) / fact), "exp {k}");
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            assert!(close(r[k], sign), "recip {k}");
            assert!(close(q[k], binom_half), "sqrt {k}");
            assert!(close(w[k], binom_alpha), "power {k}");
            let ln = if k == 0 { 0.0 } else { -sign / k as f64 };
            assert!(close(l[k], ln), "log {k}");
        }
    }

    /// Products and squares agree, and Horner evaluates what they built.
    #[test]
    fn products_and_evaluation() {
        let a = var(2.0);
        let mut sq = [0.0; CAPACITY];
        let mut cube = [0.0; CAPACITY];
        for k in 0..4 {
            sq[k] = square(&a, k);
            assert_eq!(sq[k], mul(&a, &a, k));
            cube[k] = mul(&sq, &a, k);
        }
        // (2 + τ)³ at τ = 0.5.
        assert_eq!(eval(&cube, 3, 0.5), 15.625);
        let (v, d) = eval_with_derivative(&cube, 3, 0.5);
        assert_eq!((v, d), (15.625, 18.75));
    }
}
