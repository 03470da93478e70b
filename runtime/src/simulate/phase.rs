//! A point of phase space (q, q̇), or its time derivative (q̇, q̈), and the
//! norms the integrators measure it with.

use crate::libm;

/// (q, q̇) or its time derivative (q̇, q̈).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Phase<const N: usize> {
    pub q: [f64; N],
    pub v: [f64; N],
}

impl<const N: usize> Phase<N> {
    pub const ZERO: Self = Self {
        q: [0.0; N],
        v: [0.0; N],
    };

    /// self + h Σ cₖ dₖ.
    pub fn plus(&self, h: f64, terms: &[(f64, &Phase<N>)]) -> Self {
        let mut out = *self;
        for &(c, d) in terms {
            out.add_scaled(h * c, d);
        }
        out
    }

    /// self += a d.
    fn add_scaled(&mut self, a: f64, d: &Phase<N>) {
        for (o, x) in self.q.iter_mut().zip(&d.q) {
            *o += a * x;
        }
        for (o, x) in self.v.iter_mut().zip(&d.v) {
            *o += a * x;
        }
    }

    pub fn finite(&self) -> bool {
        self.q.iter().chain(&self.v).all(|x| x.is_finite())
    }
}

/// What a Runge–Kutta step combines: a phase point, or a phase point with
/// a tangent to it, so that one step's code also differentiates itself.
pub(crate) trait Combine: Copy {
    const ZERO: Self;

    /// self + h Σ cₖ dₖ.
    fn plus(&self, h: f64, terms: &[(f64, &Self)]) -> Self;

    /// The size of an error estimate `e` of a step from `a` to `b` that
    /// error control holds to 1 ([`scaled_norm`]).
    fn error(e: &Self, a: &Self, b: &Self, rtol: f64, atol: f64) -> f64;

    fn finite(&self) -> bool;
}

impl<const N: usize> Combine for Phase<N> {
    const ZERO: Self = Phase::ZERO;

    fn plus(&self, h: f64, terms: &[(f64, &Self)]) -> Self {
        Phase::plus(self, h, terms)
    }

    fn error(e: &Self, a: &Self, b: &Self, rtol: f64, atol: f64) -> f64 {
        scaled_norm(e, a, b, rtol, atol)
    }

    fn finite(&self) -> bool {
        Phase::finite(self)
    }
}

/// A phase point x and a tangent dx at it (or their time derivatives,
/// (ẋ, J(x) dx)): a Runge–Kutta step over `Dual`s is the step and its
/// derivative along dx, the same stages and weights applied to both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Dual<const N: usize> {
    pub x: Phase<N>,
    pub dx: Phase<N>,
}

impl<const N: usize> Combine for Dual<N> {
    const ZERO: Self = Dual {
        x: Phase::ZERO,
        dx: Phase::ZERO,
    };

    /// The tangent's error alone: the point's was the simulator's to
    /// control, at its own tolerance.
    fn error(e: &Self, a: &Self, b: &Self, rtol: f64, atol: f64) -> f64 {
        scaled_norm(&e.dx, &a.dx, &b.dx, rtol, atol)
    }

    fn finite(&self) -> bool {
        self.x.finite() && self.dx.finite()
    }

    fn plus(&self, h: f64, terms: &[(f64, &Self)]) -> Self {
        let mut out = *self;
        for &(c, d) in terms {
            out.x.add_scaled(h * c, &d.x);
            out.dx.add_scaled(h * c, &d.dx);
        }
        out
    }
}

/// Euclidean norm.
pub(crate) fn norm(x: &[f64]) -> f64 {
    libm::sqrt(x.iter().map(|v| v * v).sum())
}

/// RMS of eᵢ / (atol + rtol·max(|aᵢ|, |bᵢ|)) over all components.
pub(crate) fn scaled_norm<const N: usize>(
    e: &Phase<N>,
    a: &Phase<N>,
    b: &Phase<N>,
    rtol: f64,
    atol: f64,
) -> f64 {
    let mut sum = 0.0;
    let parts = [(&e.q, &a.q, &b.q), (&e.v, &a.v, &b.v)];
    for (e, a, b) in parts {
        for i in 0..N {
            let sc = atol + rtol * a[i].abs().max(b[i].abs());
            sum += (e[i] / sc) * (e[i] / sc);
        }
    }
    if N == 0 {
        0.0
    } else {
        libm::sqrt(sum / (2 * N) as f64)
    }
}
