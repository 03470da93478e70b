//! Proofs that a stretch of a step is clear of a wall. Samples of f along
//! a step, however many, can step over a dip of f below zero narrower than
//! their spacing (a point flying over a narrow bump of the floor). Here
//! the step's motion is enclosed in boxes instead: over θ ∈ [a, b] the
//! path's coordinates lie in intervals ([`polynomial_bounds`]), the wall's
//! f over that box in the model's `surface_bounds`. A box on which f > 0
//! is clear, and so is one on which f is proven monotone
//! (`normal_bounds` · dq/dθ of one sign) and positive at the end it
//! falls towards. Other boxes are split (a quarter at each end, the half
//! between), and a split point with f ≤ 0 is a crossing earlier than the
//! one the samples found.
//!
//! What is not proven is left to the samples, as before: a stretch
//! narrower than 2^−[`CLEAR_DEPTH`] of the step on which neither test
//! holds (the motion grazing the wall, touching it at the end where a
//! crossing is, or leaving it at the start), every box past
//! [`CLEAR_BOXES`] on one step, and a wall without bounds (a model whose
//! `surface_bounds` is `None`).

use super::Simulator;
use super::path::Path;
use super::thresholds::{CLEAR_BOXES, CLEAR_DEPTH};
use crate::interval::Interval;
use crate::{Surfaces, libm};

/// Bounds on the polynomial p(θ) = Σ cₖθᵏ and on its derivative over θ ∈
/// [a, b] ⊂ [0, 1], from the middle m (r = (b − a)/2): p(m + u) = p(m) +
/// p′(m)u + p″(ξ)u²/2 and p′(m + u) = p′(m) + p″(ξ′)u for some ξ, ξ′ in
/// [a, b], with p″ bounded there term by term (each θᵏ is increasing on
/// [0, 1], so each term lies between its values at the ends). Within O(r²)
/// of p's range and O(r) of p′'s, exact for a parabola; one pass over the
/// coefficients, in plain floating point widened by the rounding of the
/// sums (the proofs bound many stretches).
pub(super) fn polynomial_bounds(
    n: usize,
    c: impl Fn(usize) -> f64,
    a: f64,
    b: f64,
) -> (Interval, Interval) {
    let (m, r) = (0.5 * (a + b), 0.5 * (b - a));
    // p(m), p′(m) by Horner's scheme.
    let (mut p, mut dp) = (0.0, 0.0);
    for k in (0..n).rev() {
        dp = dp * m + p;
        p = p * m + c(k);
    }
    // p″ over [a, b], term by term; and the terms' sizes, for the slack.
    let (mut lo, mut hi) = (0.0, 0.0);
    let (mut size, mut rate_size) = (0.0, 0.0);
    // θᵏ⁻² at the ends, and b^k, b^(k−1).
    let (mut pa, mut pb, mut bk, mut bk1) = (1.0, 1.0, 1.0, 0.0);
    for k in 0..n {
        let x = c(k);
        size += libm::fabs(x) * bk;
        rate_size += k as f64 * libm::fabs(x) * bk1;
        (bk1, bk) = (bk, bk * b);
        if k >= 2 {
            let w = (k * (k - 1)) as f64 * x;
            let (u, v) = (w * pa, w * pb);
            lo += u.min(v);
            hi += u.max(v);
            (pa, pb) = (pa * a, pb * b);
        }
    }
    let curvature = libm::fabs(lo).max(libm::fabs(hi));
    // Each product and sum rounds once: a few ulps of the terms' sizes.
    let slack = 4.0 * (n + 2) as f64 * f64::EPSILON;
    let (spread, bend) = (libm::fabs(dp) * r, 0.5 * r * r);
    let (down, up) = (bend * lo.min(0.0), bend * hi.max(0.0));
    let value = Interval::new(
        p - spread + down - slack * size,
        p + spread + up + slack * size,
    );
    let rate = Interval::new(
        dp - curvature * r - slack * rate_size,
        dp + curvature * r + slack * rate_size,
    );
    (value, rate)
}

/// The first crossing of a wall on a stretch of a step, bracketed: f > 0
/// at θ = `a` (`fa`), f ≤ 0 at `b` (`fb`), and clear before `a`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Bracket {
    pub a: f64,
    pub fa: f64,
    pub b: f64,
    pub fb: f64,
}

/// A stretch [a, b] of the step still to be proven, with f at its ends.
#[derive(Clone, Copy)]
struct Stretch {
    a: f64,
    fa: f64,
    b: f64,
    fb: f64,
    depth: usize,
}

/// Where the search for wall `wall` along a step starts and ends.
pub(super) struct Ends {
    /// f at θ = 0.
    pub f0: f64,
    /// Whether the motion is leaving the wall at θ = 0 (just collided
    /// with, f ≈ 0 and rising): there f may be at or a rounding below 0.
    pub leaving: bool,
    /// The stretch ends at θ = `end`, where f is `f_end` (≤ 0 where the
    /// samples found a crossing there).
    pub end: f64,
    pub f_end: f64,
}

impl<M: Surfaces<N>, const N: usize> Simulator<'_, M, N> {
    /// A crossing of wall `k` before `ends.end` on the step whose motion
    /// is `path`, bracketed, if the stretch [0, end] is not proven clear
    /// up to where `ends` says f ≤ 0 (see the module's text for what is
    /// proven). `None` where it is, or where the model has no bounds.
    pub(super) fn earlier_crossing(
        &self,
        k: usize,
        path: &impl Path<N>,
        ends: &Ends,
    ) -> Option<Bracket> {
        let m = self.model;
        let wall = m.walls()[k];
        let f = |theta: f64| m.surface(wall, &path.position(theta));
        let (mut end, mut found) = (ends.end, None);
        let mut stack = [Stretch {
            a: 0.0,
            fa: ends.f0,
            b: ends.end,
            fb: ends.f_end,
            depth: 0,
        }; 2 * CLEAR_DEPTH + 3];
        let mut top = 1;
        let mut boxes = 0;
        // Only the coordinates f depends on are bounded: those whose entry
        // of df is not exactly zero over every q. f does not change with
        // the others, so any value of theirs (0) gives its range.
        let (mut q, mut dq) = ([Interval::point(0.0); N], [Interval::point(0.0); N]);
        let wanted = m
            .normal_bounds(wall, &[Interval::ENTIRE; N])
            .map_or([true; N], |g| g.map(|g| !(g.lo == 0.0 && g.hi == 0.0)));
        while top > 0 {
            top -= 1;
            let s = stack[top];
            boxes += 1;
            if boxes > CLEAR_BOXES {
                break;
            }
            path.bounds(s.a, s.b, &wanted, &mut q, &mut dq);
            let bound = m.surface_bounds(wall, &q)?;
            if bound.lo > 0.0 {
                continue;
            }
            if let Some(g) = m.normal_bounds(wall, &q) {
                let rate = (g.iter().zip(&dq).zip(&wanted))
                    .filter(|(_, w)| **w)
                    .fold(Interval::point(0.0), |r, ((g, d), _)| r + *g * *d);
                let rises_from_clear = s.fa > 0.0 || (s.a == 0.0 && ends.leaving);
                if rate.lo > 0.0 && rises_from_clear {
                    continue;
                }
                if rate.hi < 0.0 && s.fb > 0.0 {
                    continue;
                }
                if rate.hi < 0.0 && s.fa > 0.0 {
                    // f falls through zero once on the stretch: the first
                    // crossing is in it.
                    found = Some(Bracket {
                        a: s.a,
                        fa: s.fa,
                        b: s.b,
                        fb: s.fb,
                    });
                    continue;
                }
            }
            if s.depth >= CLEAR_DEPTH {
                continue;
            }
            // A stretch with both ends on the wall (a step from one
            // collision to the next) has its hump in the middle: split it
            // into a quarter at each end, monotone, and the half between,
            // clear by f > 0. Others are halved.
            let starts_on_wall = s.fa <= 0.0 || (s.a == 0.0 && ends.leaving);
            let width = s.b - s.a;
            let (points, depths): (&[f64], &[usize]) = if starts_on_wall && s.fb <= 0.0 {
                (&[0.25, 0.75], &[2, 1, 2])
            } else {
                (&[0.5], &[1, 1])
            };
            // The children, left to right; at most three.
            let mut children = [s; 3];
            let (mut count, mut crossed) = (0, false);
            let mut from = (s.a, s.fa);
            for (i, &p) in points.iter().enumerate() {
                let x = s.a + p * width;
                let fx = f(x);
                children[i] = Stretch {
                    a: from.0,
                    fa: from.1,
                    b: x,
                    fb: fx,
                    depth: s.depth + depths[i],
                };
                count = i + 1;
                if fx <= 0.0 && from.1 > 0.0 {
                    // A crossing before `end` in this child: what lies
                    // beyond it (the rest of the stack, the children to
                    // its right) no longer matters.
                    end = x;
                    found = Some(Bracket {
                        a: from.0,
                        fa: from.1,
                        b: x,
                        fb: fx,
                    });
                    (top, crossed) = (0, true);
                    break;
                }
                from = (x, fx);
            }
            if !crossed {
                // No crossing at a split point: the last child too.
                children[count] = Stretch {
                    a: from.0,
                    fa: from.1,
                    depth: s.depth + depths[count],
                    ..s
                };
                count += 1;
            }
            // The leftmost on top: the first crossing is searched first.
            for child in children[..count].iter().rev() {
                stack[top] = *child;
                top += 1;
            }
        }
        found.filter(|_| end < ends.end)
    }
}

#[cfg(test)]
mod tests {
    use super::polynomial_bounds;

    #[test]
    fn polynomial_bounds_enclose_values_and_rates() {
        // p(θ) = 1 − 3θ + 0.5θ² + 2θ³ − θ⁴ over stretches of [0, 1].
        let c = [1.0, -3.0, 0.5, 2.0, -1.0];
        let p = |t: f64| c.iter().rev().fold(0.0, |acc, x| acc * t + x);
        let dp = |t: f64| -3.0 + t + 6.0 * t * t - 4.0 * t * t * t;
        for (a, b) in [(0.0, 1.0), (0.2, 0.3), (0.5, 0.5 + 1e-9), (0.9, 1.0)] {
            let (value, rate) = polynomial_bounds(c.len(), |k| c[k], a, b);
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for k in 0..=100 {
                let t = a + (b - a) * k as f64 / 100.0;
                assert!(value.contains(p(t)), "p({t}) outside {value:?}");
                assert!(rate.contains(dp(t)), "p'({t}) outside {rate:?}");
                lo = lo.min(p(t));
                hi = hi.max(p(t));
            }
            // Tight on short stretches: within a few times r² of the
            // range, and the rate within a few times r of p′ at the middle.
            let (r, m) = (0.5 * (b - a), 0.5 * (a + b));
            assert!(
                value.width() <= (hi - lo) + 40.0 * r * r + 1e-12,
                "{value:?} vs [{lo}, {hi}]"
            );
            assert!(
                rate.lo >= dp(m) - 40.0 * r - 1e-12 && rate.hi <= dp(m) + 40.0 * r + 1e-12,
                "{rate:?}"
            );
        }
    }
}
