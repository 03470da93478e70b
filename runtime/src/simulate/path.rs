//! The motion over one step, as the event search sees it: a Runge–Kutta
//! step's dense output or the polynomial of a step of Taylor's method, at
//! any θ ∈ [0, 1] of the step, and bounds on it over a stretch of θ (for
//! the proofs of `enclosure.rs`).

use super::enclosure::polynomial_bounds;
use super::integrator::Trial;
use super::phase::Phase;
use crate::interval::Interval;
use crate::taylor::{CAPACITY, MAX_ORDER, Series, degree};

/// The motion over one step, at θ ∈ [0, 1] of it.
pub(super) trait Path<const N: usize> {
    /// (q, q̇) at θ.
    fn state(&self, theta: f64) -> Phase<N>;

    /// q at θ (a wall's f needs no more).
    fn position(&self, theta: f64) -> [f64; N] {
        self.state(theta).q
    }

    /// Bounds on q and on dq/dθ over θ ∈ [a, b], into `q` and `dq`, for
    /// the coordinates `wanted` says (the others are left as they are).
    fn bounds(
        &self,
        a: f64,
        b: f64,
        wanted: &[bool; N],
        q: &mut [Interval; N],
        dq: &mut [Interval; N],
    );
}

/// A Runge–Kutta step of length `h` from `y0`: its ends, and its dense
/// output between them.
pub(super) struct RkStep<'a, const N: usize> {
    pub y0: &'a Phase<N>,
    pub trial: &'a Trial<N>,
    pub h: f64,
}

impl<const N: usize> Path<N> for RkStep<'_, N> {
    fn state(&self, theta: f64) -> Phase<N> {
        if theta == 0.0 {
            *self.y0
        } else if theta == 1.0 {
            self.trial.y1
        } else {
            self.trial.dense.at(theta, self.h)
        }
    }

    fn position(&self, theta: f64) -> [f64; N] {
        if theta == 0.0 {
            self.y0.q
        } else if theta == 1.0 {
            self.trial.y1.q
        } else {
            self.trial.dense.position(theta, self.h)
        }
    }

    fn bounds(
        &self,
        a: f64,
        b: f64,
        wanted: &[bool; N],
        q: &mut [Interval; N],
        dq: &mut [Interval; N],
    ) {
        let c = self.trial.dense.position_polynomial(self.h);
        for i in (0..N).filter(|&i| wanted[i]) {
            (q[i], dq[i]) = polynomial_bounds(c[i].len(), |k| c[i][k], a, b);
            // The step's ends are its states, the dense output's ends
            // within rounding of them: the hull holds both.
            for (theta, y) in [(0.0, self.y0), (1.0, &self.trial.y1)] {
                if a == theta || b == theta {
                    q[i] = Interval::new(q[i].lo.min(y.q[i]), q[i].hi.max(y.q[i]));
                }
            }
        }
    }
}

/// A step of Taylor's method of length `tau` along `series`.
pub(super) struct SeriesStep<'a, const N: usize> {
    pub series: &'a Series<N>,
    pub tau: f64,
}

impl<const N: usize> Path<N> for SeriesStep<'_, N> {
    fn state(&self, theta: f64) -> Phase<N> {
        let (q, v) = self.series.state(theta * self.tau);
        Phase { q, v }
    }

    fn position(&self, theta: f64) -> [f64; N] {
        let tau = theta * self.tau;
        let order = self.series.order;
        core::array::from_fn(|i| crate::taylor::eval(&self.series.q[i], order, tau))
    }

    fn bounds(
        &self,
        a: f64,
        b: f64,
        wanted: &[bool; N],
        q: &mut [Interval; N],
        dq: &mut [Interval; N],
    ) {
        // The series in θ: coefficient k times τᵏ, up to the last that is
        // not zero (a free flight's height is a parabola).
        let order = self.series.order.min(MAX_ORDER);
        let mut scaled = [0.0; CAPACITY];
        for i in (0..N).filter(|&i| wanted[i]) {
            let c = &self.series.q[i];
            let n = degree(c, order) + 1;
            let mut power = 1.0;
            for (d, c) in scaled.iter_mut().zip(&c[..n]) {
                *d = c * power;
                power *= self.tau;
            }
            (q[i], dq[i]) = polynomial_bounds(n, |k| scaled[k], a, b);
        }
    }
}
