//! Dense output: the motion on one step, for any time inside it.

use super::super::phase::Phase;

/// The motion on one step, for any time inside it.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Dense<const N: usize> {
    /// Cubic Hermite through (y₀, f₀) and (y₁, f₁) (RK4).
    Hermite {
        y0: Phase<N>,
        y1: Phase<N>,
        f0: Phase<N>,
        f1: Phase<N>,
    },
    /// Shampine's continuous extension of Dormand–Prince (Hairer–Nørsett–
    /// Wanner, *Solving ODEs I*, §II.6):
    /// y₀ + θ(r₁ + (1−θ)(r₂ + θ(r₃ + (1−θ)r₄))).
    Shampine { y0: Phase<N>, r: [Phase<N>; 4] },
}

impl<const N: usize> Dense<N> {
    /// One half of the interpolated state at θ ∈ [0, 1] of a step of length
    /// `h`: `part` picks q or v out of each stored (q, v) pair.
    fn interpolate(&self, theta: f64, h: f64, part: fn(&Phase<N>) -> &[f64; N]) -> [f64; N] {
        match self {
            Dense::Hermite { y0, y1, f0, f1 } => {
                // y₀ + θ(y₁−y₀) + θ(θ−1)[(1−2θ)(y₁−y₀) + (θ−1)h f₀ + θ h f₁]
                let c = theta * (theta - 1.0);
                let (a, b, fa, fb) = (part(y0), part(y1), part(f0), part(f1));
                core::array::from_fn(|i| {
                    let d = b[i] - a[i];
                    a[i] + theta * d
                        + c * ((1.0 - 2.0 * theta) * d
                            + (theta - 1.0) * h * fa[i]
                            + theta * h * fb[i])
                })
            }
            Dense::Shampine { y0, r } => {
                let s = 1.0 - theta;
                let (a, r) = (part(y0), r.each_ref().map(part));
                core::array::from_fn(|i| {
                    a[i] + theta * (r[0][i] + s * (r[1][i] + theta * (r[2][i] + s * r[3][i])))
                })
            }
        }
    }

    /// The interpolated coordinates as polynomials in θ of degree 4 at
    /// most: `c[i][k]` is the coefficient of θᵏ in coordinate i (the same
    /// polynomials [`Dense::position`] evaluates, up to rounding).
    pub fn position_polynomial(&self, h: f64) -> [[f64; 5]; N] {
        match self {
            Dense::Hermite { y0, y1, f0, f1 } => {
                // y₀ + θ(d − p₀) + θ²(p₀ − p₁) + θ³p₁ with d = y₁ − y₀,
                // p₀ = d − h f₀, p₁ = −2d + h f₀ + h f₁.
                core::array::from_fn(|i| {
                    let d = y1.q[i] - y0.q[i];
                    let (a, b) = (h * f0.q[i], h * f1.q[i]);
                    let (p0, p1) = (d - a, -2.0 * d + a + b);
                    [y0.q[i], a, p0 - p1, p1, 0.0]
                })
            }
            Dense::Shampine { y0, r } => {
                // y₀ + θ(r₁ + (1−θ)(r₂ + θ(r₃ + (1−θ)r₄))) expanded.
                core::array::from_fn(|i| {
                    let [r1, r2, r3, r4] = r.each_ref().map(|r| r.q[i]);
                    [y0.q[i], r1 + r2, r3 + r4 - r2, -(r3 + 2.0 * r4), r4]
                })
            }
        }
    }

    /// The state the step started from.
    pub fn start(&self) -> &Phase<N> {
        match self {
            Dense::Hermite { y0, .. } | Dense::Shampine { y0, .. } => y0,
        }
    }

    /// The interpolated coordinates alone (half the work of [`Dense::at`];
    /// a wall's f needs no more).
    pub fn position(&self, theta: f64, h: f64) -> [f64; N] {
        self.interpolate(theta, h, |y| &y.q)
    }

    /// The interpolated state at θ ∈ [0, 1] of a step of length `h`.
    pub fn at(&self, theta: f64, h: f64) -> Phase<N> {
        Phase {
            q: self.interpolate(theta, h, |y| &y.q),
            v: self.interpolate(theta, h, |y| &y.v),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Dense, Phase};

    fn phase(seed: f64) -> Phase<2> {
        Phase {
            q: [seed.sin(), (2.0 * seed).cos()],
            v: [seed.cos(), seed * 0.3],
        }
    }

    /// The expanded polynomials are the interpolants `position` evaluates.
    #[test]
    fn position_polynomials_are_the_interpolants() {
        let h = 0.37;
        let dense = [
            Dense::Hermite {
                y0: phase(0.1),
                y1: phase(0.2),
                f0: phase(0.3),
                f1: phase(0.4),
            },
            Dense::Shampine {
                y0: phase(0.5),
                r: [phase(0.6), phase(0.7), phase(0.8), phase(0.9)],
            },
        ];
        for d in dense {
            let c = d.position_polynomial(h);
            for k in 0..=10 {
                let theta = k as f64 / 10.0;
                let q = d.position(theta, h);
                for i in 0..2 {
                    let p = c[i].iter().rev().fold(0.0, |acc, x| acc * theta + x);
                    assert!((p - q[i]).abs() <= 1e-14, "{p} vs {}", q[i]);
                }
            }
        }
    }
}
