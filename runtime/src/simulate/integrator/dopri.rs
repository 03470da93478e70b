//! Dormand–Prince 5(4): the tableau, Shampine's dense output (1986), the
//! error estimate and the standard step-size controller.

use super::super::phase::{Combine, Phase, scaled_norm};
use super::{Dense, Method, Trial};
use crate::libm;

/// Dormand–Prince 5(4) with error control on every component of (q, q̇):
/// a step is accepted when the RMS of eᵢ / (atol + rtol·|yᵢ|) is ≤ 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DormandPrince {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest step allowed.
    pub max_step: f64,
}

impl Default for DormandPrince {
    fn default() -> Self {
        Self {
            rtol: 1e-10,
            atol: 1e-12,
            max_step: f64::INFINITY,
        }
    }
}

// Nodes, stages, the fifth-order weights (= the last stage row, FSAL) and
// the error weights b − b̂.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
// Shampine's dense output (1986).
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

// The controller: safety 0.9, exponent 1/5, factor in [0.2, 5].
// 0.9·err^(−1/5) reaches 5 for err ≤ (0.9/5)⁵ and 0.2 for err ≥ 4.5⁵: the
// power (by exp and log, faster than pow) is needed only in between.
const GROW_MOST_BELOW: f64 = 1.889568e-4;
const SHRINK_MOST_ABOVE: f64 = 1845.28125;

impl DormandPrince {
    /// The seven stages of one step (the last is f(y₁), FSAL) and y₁.
    fn stages<Y: Combine, E>(
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, E>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
        k: &mut [Y; 7],
    ) -> Result<Y, E> {
        k[0] = *f0;
        for s in 1..7 {
            let terms: [(f64, &Y); 6] = core::array::from_fn(|j| (A[s][j], &k[j]));
            let ys = y0.plus(h, &terms[..s]);
            k[s] = rhs(t0 + C[s] * h, &ys)?;
        }
        // The last stage was evaluated at y₁ itself.
        let terms: [(f64, &Y); 6] = core::array::from_fn(|j| (A[6][j], &k[j]));
        Ok(y0.plus(h, &terms))
    }

    /// The stages of one step, y₁ and the scaled error estimate.
    fn stepped<Y: Combine, E>(
        &self,
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, E>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
        k: &mut [Y; 7],
    ) -> Result<(Y, f64), E> {
        let y1 = Self::stages(rhs, y0, f0, t0, h, k)?;
        let e_terms: [(f64, &Y); 7] = core::array::from_fn(|j| (E[j], &k[j]));
        let err = Y::ZERO.plus(h, &e_terms);
        Ok((y1, Y::error(&err, y0, &y1, self.rtol, self.atol)))
    }
}

impl Method for DormandPrince {
    fn valid(&self) -> bool {
        self.rtol > 0.0 && self.atol > 0.0 && self.max_step > 0.0
    }

    fn adaptive(&self) -> bool {
        true
    }

    fn initial_step<const N: usize>(&self, y: &Phase<N>, f0: &Phase<N>) -> f64 {
        // Hairer's first guess: 1% of the ratio of the scaled norms of y
        // and y', bounded by the fifth root of the tolerance.
        let d0 = scaled_norm(y, y, y, self.rtol, self.atol);
        let d1 = scaled_norm(f0, y, y, self.rtol, self.atol);
        let h = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        h.min(self.max_step).max(1e-10)
    }

    fn max_step(&self) -> f64 {
        self.max_step
    }

    fn factor(&self, err: f64) -> f64 {
        if err <= GROW_MOST_BELOW {
            5.0
        } else if err < SHRINK_MOST_ABOVE {
            (0.9 * libm::exp(-0.2 * libm::log(err))).clamp(0.2, 5.0)
        } else {
            0.2
        }
    }

    fn advance<Y: Combine, Er>(
        &self,
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, Er>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
    ) -> Result<(Y, Option<Y>), Er> {
        let mut k = [*f0; 7];
        let y1 = Self::stages(rhs, y0, f0, t0, h, &mut k)?;
        Ok((y1, Some(k[6])))
    }

    fn estimate<Y: Combine, Er>(
        &self,
        rhs: &mut impl FnMut(f64, &Y) -> Result<Y, Er>,
        y0: &Y,
        f0: &Y,
        t0: f64,
        h: f64,
    ) -> Result<(Y, f64), Er> {
        self.stepped(rhs, y0, f0, t0, h, &mut [*f0; 7])
    }

    fn trial<const N: usize, Er>(
        &self,
        rhs: &mut impl FnMut(f64, &Phase<N>) -> Result<Phase<N>, Er>,
        y0: &Phase<N>,
        f0: &Phase<N>,
        t0: f64,
        h: f64,
    ) -> Result<Trial<N>, Er> {
        let mut k = [Phase::ZERO; 7];
        let (y1, error) = self.stepped(rhs, y0, f0, t0, h, &mut k)?;
        let d_terms: [(f64, &Phase<N>); 7] = core::array::from_fn(|j| (D[j], &k[j]));
        let r1 = Phase::ZERO.plus(1.0, &[(1.0, &y1), (-1.0, y0)]);
        let r2 = Phase::ZERO
            .plus(h, &[(1.0, &k[0])])
            .plus(1.0, &[(-1.0, &r1)]);
        let r3 = r1.plus(h, &[(-1.0, &k[6])]).plus(1.0, &[(-1.0, &r2)]);
        let r4 = Phase::ZERO.plus(h, &d_terms);
        Ok(Trial {
            y1,
            f1: k[6],
            error,
            dense: Dense::Shampine {
                y0: *y0,
                r: [r1, r2, r3, r4],
            },
        })
    }
}
