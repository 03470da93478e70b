//! The singular value decomposition by one-sided Jacobi rotations
//! (Hestenes, 1958; Demmel & Veselić, 1992), for the small dense matrices of
//! Newton's method.
//!
//! nalgebra's bidiagonal SVD is not used: it occasionally returns singular
//! values and vectors that do not reproduce the matrix (dimforge/nalgebra
//! #1172, open), and it did so here, on the section basis of the puck near
//! a grazing motion, where a state moved by 2e-11 turned a rank-5
//! projection's null direction into one of its "singular vectors". The
//! one-sided method rotates pairs of columns of A until all are orthogonal,
//! A V = W: the singular values are W's column norms, U its normalised
//! columns, V the product of the rotations. It is slower than a
//! bidiagonalisation but accurate to rounding in every singular value, and
//! the matrices here have at most 2N ≤ 2·64 columns.

use nalgebra::{DMatrix, DVector};

/// A = U diag(σ) Vᵀ with σ in descending order; U has A's rows and one
/// column per singular value (zero where σ = 0), V is square.
#[derive(Clone, Debug)]
pub(crate) struct Svd {
    pub u: DMatrix<f64>,
    pub singular_values: DVector<f64>,
    pub v: DMatrix<f64>,
}

/// Sweeps over all column pairs before the rotations are given up on.
const SWEEPS: usize = 60;

impl Svd {
    /// The decomposition of `a`; `None` when it has a non-finite entry or
    /// the rotations do not converge.
    pub fn new(a: &DMatrix<f64>) -> Option<Self> {
        if !a.iter().all(|x| x.is_finite()) {
            return None;
        }
        let n = a.ncols();
        let mut w = a.clone();
        let mut v = DMatrix::identity(n, n);
        // A column this small is rounding left over from the rotations:
        // nothing to make orthogonal.
        let negligible = (f64::EPSILON * a.norm()).powi(2);
        let mut converged = false;
        for _ in 0..SWEEPS {
            let mut rotated = false;
            for p in 0..n {
                for q in p + 1..n {
                    let alpha = w.column(p).norm_squared();
                    let beta = w.column(q).norm_squared();
                    let gamma = w.column(p).dot(&w.column(q));
                    if alpha <= negligible
                        || beta <= negligible
                        || gamma.abs() <= f64::EPSILON * (alpha * beta).sqrt()
                    {
                        continue;
                    }
                    rotated = true;
                    // The rotation that makes columns p and q orthogonal.
                    let zeta = (beta - alpha) / (2.0 * gamma);
                    let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                    let c = 1.0 / (1.0 + t * t).sqrt();
                    let s = c * t;
                    rotate(&mut w, p, q, c, s);
                    rotate(&mut v, p, q, c, s);
                }
            }
            if !rotated {
                converged = true;
                break;
            }
        }
        if !converged {
            return None;
        }
        let norms: Vec<f64> = (0..n).map(|j| w.column(j).norm()).collect();
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&i, &j| norms[j].total_cmp(&norms[i]));
        let u = DMatrix::from_fn(a.nrows(), n, |i, k| {
            let j = order[k];
            if norms[j] > 0.0 {
                w[(i, j)] / norms[j]
            } else {
                0.0
            }
        });
        Some(Self {
            u,
            singular_values: DVector::from_fn(n, |k, _| norms[order[k]]),
            v: DMatrix::from_fn(n, n, |i, k| v[(i, order[k])]),
        })
    }

    /// The least-squares solution of A x = b of smallest norm, singular
    /// values at or below `cutoff` taken as zero.
    pub fn solve(&self, b: &DVector<f64>, cutoff: f64) -> DVector<f64> {
        let mut x = DVector::zeros(self.v.nrows());
        for (k, &sigma) in self.singular_values.iter().enumerate() {
            if sigma > cutoff {
                x += self.v.column(k) * (self.u.column(k).dot(b) / sigma);
            }
        }
        x
    }
}

/// Columns p and q of m replaced by c·m_p − s·m_q and s·m_p + c·m_q.
fn rotate(m: &mut DMatrix<f64>, p: usize, q: usize, c: f64, s: f64) {
    for i in 0..m.nrows() {
        let (x, y) = (m[(i, p)], m[(i, q)]);
        m[(i, p)] = c * x - s * y;
        m[(i, q)] = s * x + c * y;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(a: &DMatrix<f64>) -> Svd {
        let d = Svd::new(a).unwrap();
        let n = a.ncols();
        let sigma = DMatrix::from_diagonal(&d.singular_values);
        let error = (&d.u * sigma * d.v.transpose() - a).norm();
        assert!(error <= 1e-13 * a.norm().max(1.0), "A ≠ UΣVᵀ by {error:e}");
        let vtv = d.v.transpose() * &d.v - DMatrix::<f64>::identity(n, n);
        assert!(vtv.norm() <= 1e-13, "V not orthogonal: {vtv}");
        // The columns of U for non-zero σ are orthonormal.
        let rank = d.singular_values.iter().filter(|&&s| s > 1e-12).count();
        let u = d.u.columns(0, rank);
        let utu = u.transpose() * u - DMatrix::<f64>::identity(rank, rank);
        assert!(utu.norm() <= 1e-13, "U not orthonormal: {utu}");
        assert!(
            d.singular_values
                .as_slice()
                .windows(2)
                .all(|w| w[0] >= w[1]),
            "{:?}",
            d.singular_values
        );
        // Σσ² = |A|²_F, the check nalgebra's fails (nalgebra #1172).
        let sum: f64 = d.singular_values.iter().map(|s| s * s).sum();
        assert!((sum - a.norm_squared()).abs() <= 1e-13 * a.norm_squared().max(1.0));
        d
    }

    /// All-ones matrices are 1 1ᵀ: one singular value, √(mn).
    #[test]
    fn all_ones() {
        for (m, n) in [(3, 5), (5, 3), (6, 21), (21, 6), (4, 4)] {
            let d = check(&DMatrix::from_element(m, n, 1.0));
            let exact = ((m * n) as f64).sqrt();
            assert!((d.singular_values[0] - exact).abs() <= 1e-14 * exact);
            assert!(d.singular_values.iter().skip(1).all(|&s| s <= 1e-14));
        }
    }

    /// Random matrices, rank-deficient ones and a known spectrum.
    #[test]
    fn random_and_known_spectra() {
        let mut seed = 11_u64;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for (m, n) in [(6, 6), (12, 11), (12, 4), (3, 7)] {
            check(&DMatrix::from_fn(m, n, |_, _| uniform()));
            // Rank 2.
            let b = DMatrix::from_fn(m, 2, |_, _| uniform());
            let c = DMatrix::from_fn(2, n, |_, _| uniform());
            let d = check(&(b * c));
            assert!(d.singular_values.iter().skip(2).all(|&s| s <= 1e-14));
        }
        // Q diag(3, 2, 1e-9, 0) Rᵀ with Q, R orthogonal (Householder).
        let reflector = |x: DVector<f64>| {
            let x = x.normalize();
            DMatrix::<f64>::identity(4, 4) - 2.0 * &x * x.transpose()
        };
        let q = reflector(DVector::from_fn(4, |_, _| uniform()));
        let r = reflector(DVector::from_fn(4, |_, _| uniform()));
        let spectrum = DVector::from_vec(vec![3.0, 2.0, 1e-9, 0.0]);
        let d = check(&(&q * DMatrix::from_diagonal(&spectrum) * r.transpose()));
        for k in 0..3 {
            let want: f64 = spectrum[k];
            assert!((d.singular_values[k] - want).abs() <= 1e-15 * 3.0, "{k}");
        }
    }

    /// The smallest-norm least-squares solution: a rank-one system.
    #[test]
    fn smallest_norm_solution() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        let x = Svd::new(&a)
            .unwrap()
            .solve(&DVector::from_vec(vec![2.0, 2.0]), 1e-12);
        assert!((x[0] - 1.0).abs() <= 1e-15 && (x[1] - 1.0).abs() <= 1e-15);
    }
}
