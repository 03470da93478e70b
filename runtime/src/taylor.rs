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

    /// The state at τ on the series (Horner's scheme, every component in
    /// step so that the 2N chains run side by side; each is [`eval`]'s).
    pub fn state(&self, tau: f64) -> ([f64; N], [f64; N]) {
        let (mut q, mut v) = ([0.0; N], [0.0; N]);
        for k in (0..=self.order.min(MAX_ORDER)).rev() {
            for i in 0..N {
                q[i] = q[i] * tau + self.q[i][k];
                v[i] = v[i] * tau + self.v[i][k];
            }
        }
        (q, v)
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

/// Σᵢ xᵢ·y₍ₙ₋₁₋ᵢ₎ over n = min(|x|, |y|), in four independent partial
/// sums: the convolutions below are short dot products whose cost is the
/// latency of one long chain of additions, and four chains run side by
/// side.
#[inline(always)]
fn reversed_dot(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len().min(y.len());
    let (x, y) = (&x[..n], &y[..n]);
    let mut s = [0.0; 4];
    let mut i = 0;
    while i + 4 <= n {
        s[0] += x[i] * y[n - 1 - i];
        s[1] += x[i + 1] * y[n - 2 - i];
        s[2] += x[i + 2] * y[n - 3 - i];
        s[3] += x[i + 3] * y[n - 4 - i];
        i += 4;
    }
    while i < n {
        s[0] += x[i] * y[n - 1 - i];
        i += 1;
    }
    (s[0] + s[1]) + (s[2] + s[3])
}

/// j·aⱼ for j = 1..=k, at index j − 1: the derivative's coefficients
/// (times k), which sin, cos and exp convolve with.
#[inline(always)]
fn scaled(a: &Coefficients, k: usize) -> Coefficients {
    let mut d = [0.0; CAPACITY];
    for (j, (dj, aj)) in d.iter_mut().zip(&a[1..=k]).enumerate() {
        *dj = (j + 1) as f64 * aj;
    }
    d
}

/// Coefficient k of a·b.
#[inline]
pub fn mul(a: &Coefficients, b: &Coefficients, k: usize) -> f64 {
    reversed_dot(&a[..=k], &b[..=k])
}

/// Coefficient k of a², from a's coefficients (half the products of
/// [`mul`]).
#[inline]
pub fn square(a: &Coefficients, k: usize) -> f64 {
    let half = k.div_ceil(2);
    let mut acc = 2.0 * reversed_dot(&a[..half], &a[k + 1 - half..=k]);
    if k.is_multiple_of(2) {
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
    -reversed_dot(&a[1..=k], &c[..k]) * c[0]
}

/// Coefficient k of c = √a, from a's coefficients and c's below k.
#[inline]
pub fn sqrt(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return libm::sqrt(a[0]);
    }
    let acc = if k > 1 {
        reversed_dot(&c[1..k], &c[1..k])
    } else {
        0.0
    };
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
    reversed_dot(&scaled(a, k)[..k], &c[..k]) / k as f64
}

/// Coefficient k of c = ln(a), from a's coefficients and c's below k.
#[inline]
pub fn log(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return libm::log(a[0]);
    }
    let acc = if k > 1 {
        reversed_dot(&scaled(c, k - 1)[..k - 1], &a[1..k])
    } else {
        0.0
    };
    (a[k] - acc / k as f64) / a[0]
}

/// Coefficient k of (sin a, cos a), from a's coefficients and those of both
/// below k.
#[inline]
pub fn sin_cos(s: &Coefficients, c: &Coefficients, a: &Coefficients, k: usize) -> (f64, f64) {
    if k == 0 {
        return libm::sincos(a[0]);
    }
    let kf = k as f64;
    let d = scaled(a, k);
    let ss = reversed_dot(&d[..k], &c[..k]);
    let cc = reversed_dot(&d[..k], &s[..k]);
    (ss / kf, -cc / kf)
}

/// The degree of the polynomial of `order` with coefficients `c`: the
/// highest k ≤ order with cₖ ≠ 0 (0 for the zero polynomial).
pub fn degree(c: &Coefficients, order: usize) -> usize {
    let order = order.min(MAX_ORDER);
    c[..=order].iter().rposition(|x| *x != 0.0).unwrap_or(0)
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
