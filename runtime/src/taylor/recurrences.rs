//! The recurrences of Taylor-mode arithmetic: the normalised Taylor
//! coefficients of a function of time, x(t₀ + τ) = Σₖ xₖ τᵏ, one order at
//! a time.
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

use super::{CAPACITY, Coefficients};

/// 1/k for k = 1 to [`CAPACITY`] (entry 0 is 0): the recurrences' divisions
/// by the order as multiplications, which take a few cycles where a
/// division takes tens, on the chain from one order to the next.
pub const RECIPROCALS: [f64; CAPACITY + 1] = {
    let mut r = [0.0; CAPACITY + 1];
    let mut k = 1;
    while k <= CAPACITY {
        r[k] = 1.0 / k as f64;
        k += 1;
    }
    r
};

/// An intermediate series of which generated code only ever reads the
/// coefficient of the order it is computing (a sum's or a product's result
/// that no recurrence reads back): it keeps that coefficient alone, and
/// indexing it at any order gives it. 8 bytes of stack instead of a
/// [`Coefficients`] array's 256.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Current(pub f64);

impl core::ops::Index<usize> for Current {
    type Output = f64;
    #[inline(always)]
    fn index(&self, _order: usize) -> &f64 {
        &self.0
    }
}

impl core::ops::IndexMut<usize> for Current {
    #[inline(always)]
    fn index_mut(&mut self, _order: usize) -> &mut f64 {
        &mut self.0
    }
}

// Every recurrence at order k ≥ 1 is split in two: a *history*, a sum over
// j = 1..k−1 of products of coefficients below k, and a *finish* that adds
// the terms with coefficient k of an operand and applies the recurrence's
// factor. Generated code computes the histories of all of a program's
// operations in one loop over j (independent sums side by side, which is
// where the time goes) and then finishes each operation in program order;
// the whole-coefficient functions below ([`mul`], [`sin_cos`], …) compute
// the same history one term at a time, in the same order, then the same
// finish, so both give the same bits. The weighted recurrences (eᵃ, ln,
// sin/cos) multiply by j·aⱼ, which generated code keeps as a series of its
// own (`j as f64 * a[j]`, the same product).

/// Σⱼ₌₁..ₖ₋₁ aⱼ bₖ₋ⱼ, summed from j = 1 up: the history of a product.
#[inline(always)]
pub fn history(a: &Coefficients, b: &Coefficients, k: usize) -> f64 {
    let mut h = 0.0;
    for j in 1..k {
        h += a[j] * b[k - j];
    }
    h
}

/// Σⱼ₌₁..ₖ₋₁ (j·aⱼ) bₖ₋ⱼ, summed from j = 1 up: the history of eᵃ, ln and
/// sin/cos, with the weight on `a`.
#[inline(always)]
pub fn weighted_history(a: &Coefficients, b: &Coefficients, k: usize) -> f64 {
    let mut h = 0.0;
    for j in 1..k {
        h += (j as f64 * a[j]) * b[k - j];
    }
    h
}

/// Σⱼ₌₁..ₖ₋₁ (α(k−j) − j) aₖ₋ⱼ cⱼ, summed from j = 1 up: the history of
/// c = a^α.
#[inline(always)]
pub fn power_history(c: &Coefficients, a: &Coefficients, alpha: f64, k: usize) -> f64 {
    let mut h = 0.0;
    for j in 1..k {
        h += power_weight(alpha, k - j, j) * a[k - j] * c[j];
    }
    h
}

/// The weight α·r − j of aᵣ cⱼ in the recurrence of a^α (r + j = k).
#[inline(always)]
pub fn power_weight(alpha: f64, r: usize, j: usize) -> f64 {
    alpha * r as f64 - j as f64
}

/// Coefficient k ≥ 1 of a·b from its [`history`] h.
#[inline(always)]
pub fn mul_finish(a: &Coefficients, b: &Coefficients, h: f64, k: usize) -> f64 {
    a[0] * b[k] + a[k] * b[0] + h
}

/// Coefficient k ≥ 1 of a² from its [`history`] h (of a with itself).
#[inline(always)]
pub fn square_finish(a: &Coefficients, h: f64, k: usize) -> f64 {
    2.0 * a[0] * a[k] + h
}

/// Coefficient k ≥ 1 of c = 1/a from the [`history`] h of a with c.
#[inline(always)]
pub fn recip_finish(c: &Coefficients, a: &Coefficients, h: f64, k: usize) -> f64 {
    -(a[k] * c[0] + h) * c[0]
}

/// Coefficient k ≥ 1 of c = a/b from the [`history`] h of b with c:
/// cₖ = (aₖ − bₖc₀ − h)/b₀, one convolution where 1/b then a·(1/b) take
/// two. The division is by b₀, known from order 0 on: as a product with
/// 1/b₀ it is off the chain from one order's coefficients to the next
/// (a division's latency is several multiplications'), whatever the
/// compiler keeps of 1/b₀ from one order to the next.
#[inline(always)]
pub fn div_finish(c: &Coefficients, a: &Coefficients, b: &Coefficients, h: f64, k: usize) -> f64 {
    div_finish_by(c, a, b, h, k, 1.0 / b[0])
}

/// [`div_finish`] with its factor 1/b₀ given: generated code works it out
/// once per series, at order 0, so no order repeats the division.
#[inline(always)]
pub fn div_finish_by(
    c: &Coefficients,
    a: &Coefficients,
    b: &Coefficients,
    h: f64,
    k: usize,
    inv_b0: f64,
) -> f64 {
    (a[k] - b[k] * c[0] - h) * inv_b0
}

/// Coefficient k ≥ 1 of c = √a from the [`history`] h of c with itself.
#[inline(always)]
pub fn sqrt_finish(c: &Coefficients, a: &Coefficients, h: f64, k: usize) -> f64 {
    sqrt_finish_by(a, h, k, 0.5 / c[0])
}

/// [`sqrt_finish`] with its factor 1/(2c₀) given (see [`div_finish_by`]).
#[inline(always)]
pub fn sqrt_finish_by(a: &Coefficients, h: f64, k: usize, half_inv_c0: f64) -> f64 {
    (a[k] - h) * half_inv_c0
}

/// Coefficient k ≥ 1 of c = a^α from its [`power_history`] h.
#[inline(always)]
pub fn power_finish(c: &Coefficients, a: &Coefficients, alpha: f64, h: f64, k: usize) -> f64 {
    (power_weight(alpha, k, 0) * a[k] * c[0] + h) * (RECIPROCALS[k] / a[0])
}

/// Coefficient k ≥ 1 of c = eᵃ from the [`weighted_history`] h of a with c.
#[inline(always)]
pub fn exp_finish(c: &Coefficients, a: &Coefficients, h: f64, k: usize) -> f64 {
    ((k as f64 * a[k]) * c[0] + h) * RECIPROCALS[k]
}

/// Coefficient k ≥ 1 of ln a from the [`weighted_history`] h of ln a with
/// a.
#[inline(always)]
pub fn log_finish(a: &Coefficients, h: f64, k: usize) -> f64 {
    log_finish_by(a, h, k, 1.0 / a[0])
}

/// [`log_finish`] with its factor 1/a₀ given (see [`div_finish_by`]).
#[inline(always)]
pub fn log_finish_by(a: &Coefficients, h: f64, k: usize, inv_a0: f64) -> f64 {
    (a[k] - h * RECIPROCALS[k]) * inv_a0
}

/// Coefficient k ≥ 1 of (sin a, cos a) from the [`weighted_history`] of a
/// with cos (`hs`) and with sin (`hc`).
#[inline(always)]
pub fn sin_cos_finish(
    s: &Coefficients,
    c: &Coefficients,
    a: &Coefficients,
    hs: f64,
    hc: f64,
    k: usize,
) -> (f64, f64) {
    let dk = k as f64 * a[k];
    let ik = RECIPROCALS[k];
    ((dk * c[0] + hs) * ik, -(dk * s[0] + hc) * ik)
}

/// Coefficient k of a·b.
#[inline]
pub fn mul(a: &Coefficients, b: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return a[0] * b[0];
    }
    mul_finish(a, b, history(a, b, k), k)
}

/// Coefficient k of a².
#[inline]
pub fn square(a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return a[0] * a[0];
    }
    square_finish(a, history(a, a, k), k)
}

/// Coefficient k of c = 1/a, from a's coefficients and c's below k.
#[inline]
pub fn recip(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return 1.0 / a[0];
    }
    recip_finish(c, a, history(a, c, k), k)
}

/// Coefficient k of c = a/b, from a's and b's coefficients and c's below
/// k.
#[inline]
pub fn div(c: &Coefficients, a: &Coefficients, b: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return a[0] / b[0];
    }
    div_finish(c, a, b, history(b, c, k), k)
}

/// Coefficient k of c = √a, from a's coefficients and c's below k.
#[inline]
pub fn sqrt(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return libm::sqrt(a[0]);
    }
    sqrt_finish(c, a, history(c, c, k), k)
}

/// Coefficient k of c = a^α (α real), from a's coefficients and c's below
/// k. a₀ must not vanish beyond order 0.
#[inline]
pub fn power(c: &Coefficients, a: &Coefficients, alpha: f64, k: usize) -> f64 {
    if k == 0 {
        return libm::pow(a[0], alpha);
    }
    power_finish(c, a, alpha, power_history(c, a, alpha, k), k)
}

/// Coefficient k of c = exp(a), from a's coefficients and c's below k.
#[inline]
pub fn exp(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return libm::exp(a[0]);
    }
    exp_finish(c, a, weighted_history(a, c, k), k)
}

/// Coefficient k of c = ln(a), from a's coefficients and c's below k.
#[inline]
pub fn log(c: &Coefficients, a: &Coefficients, k: usize) -> f64 {
    if k == 0 {
        return libm::log(a[0]);
    }
    log_finish(a, weighted_history(c, a, k), k)
}

/// Coefficient k of (sin a, cos a), from a's coefficients and those of both
/// below k.
#[inline]
pub fn sin_cos(s: &Coefficients, c: &Coefficients, a: &Coefficients, k: usize) -> (f64, f64) {
    if k == 0 {
        return libm::sincos(a[0]);
    }
    sin_cos_finish(
        s,
        c,
        a,
        weighted_history(a, c, k),
        weighted_history(a, s, k),
        k,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::taylor::{eval, eval_with_derivative};

    /// The series of t ↦ t₀ + t (a variable) at t₀.
    fn var(t0: f64) -> Coefficients {
        let mut a = [0.0; CAPACITY];
        a[0] = t0;
        a[1] = 1.0;
        a
    }

    /// Each recurrence against the closed-form series of its function
    /// around t₀ = 0.3 (sin, cos, exp, 1/(1+t), √(1+t), (1+t)^α, ln(1+t),
    /// and (0.3 + t)/(1 + t) = 1 − 0.7/(1 + t)).
    #[test]
    fn recurrences_match_known_series() {
        let p = 20;
        let x = var(0.3);
        let one_plus = var(1.0);
        let (mut s, mut c, mut e) = ([0.0; CAPACITY], [0.0; CAPACITY], [0.0; CAPACITY]);
        let (mut r, mut q, mut w, mut l, mut quotient) = (
            [0.0; CAPACITY],
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
            quotient[k] = div(&quotient, &x, &one_plus, k);
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
            let ratio = if k == 0 { 0.3 } else { -0.7 * sign };
            assert!(close(quotient[k], ratio), "div {k}");
        }
    }

    /// The table holds exactly the rounded 1/k.
    #[test]
    fn reciprocals() {
        assert_eq!(RECIPROCALS[0], 0.0);
        for (k, r) in RECIPROCALS.iter().enumerate().skip(1) {
            assert_eq!(*r, 1.0 / k as f64, "{k}");
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
