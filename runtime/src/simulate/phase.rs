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
            let hc = h * c;
            for (o, x) in out.q.iter_mut().zip(&d.q) {
                *o += hc * x;
            }
            for (o, x) in out.v.iter_mut().zip(&d.v) {
                *o += hc * x;
            }
        }
        out
    }

    pub fn finite(&self) -> bool {
        self.q.iter().chain(&self.v).all(|x| x.is_finite())
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
