//! Small fixed-size linear algebra, without heap allocation.
//!
//! [`projector`] computes P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B numerically from G and the rows
//! of B. Generated models evaluate P from its symbolic form instead; this is
//! the generic path (and an independent check of the generated one).

use nalgebra::SMatrix;

/// Euclidean dot product.
pub fn dot<const N: usize>(a: &[f64; N], b: &[f64; N]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Matrix–vector product M v.
pub fn mat_vec<const N: usize>(m: &[[f64; N]; N], v: &[f64; N]) -> [f64; N] {
    let mut out = [0.0; N];
    for (o, row) in out.iter_mut().zip(m) {
        *o = dot(row, v);
    }
    out
}

/// Matrix product A B.
pub fn mat_mul<const N: usize>(a: &[[f64; N]; N], b: &[[f64; N]; N]) -> [[f64; N]; N] {
    let mut out = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            out[i][j] = (0..N).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

/// The quadratic form ½ vᵀ G v.
pub fn kinetic_energy<const N: usize>(g: &[[f64; N]; N], v: &[f64; N]) -> f64 {
    0.5 * dot(v, &mat_vec(g, v))
}

/// The Cholesky factor L (G = L Lᵀ) of the leading `n`×`n` block of a
/// symmetric positive definite matrix, on fixed-size arrays.
///
/// The numeric solve of the equations of motion (for models without a
/// closed-form q̈) and structured collision maps use it; on the 6×6 mass
/// matrix of the ball in flight it was several times faster than nalgebra's
/// general-purpose static Cholesky (measured with `cargo bench --bench
/// simulate`, see docs/performance.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cholesky<const N: usize> {
    l: [[f64; N]; N],
    /// 1 / Lᵢᵢ: divisions are the slow part of a small factorisation.
    inv: [f64; N],
    n: usize,
}

impl<const N: usize> Cholesky<N> {
    /// Factors the leading `n`×`n` block of `a` (the rest is ignored);
    /// `None` unless that block is (numerically) positive definite.
    pub fn new(a: &[[f64; N]; N], n: usize) -> Option<Self> {
        let n = n.min(N);
        let mut l = [[0.0; N]; N];
        let mut inv = [0.0; N];
        for i in 0..n {
            for j in 0..=i {
                let sum = a[i][j] - dot_prefix(&l[i], &l[j], j);
                if i == j {
                    // NaN fails the comparison too.
                    if sum.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
                        return None;
                    }
                    l[i][i] = libm::sqrt(sum);
                    inv[i] = 1.0 / l[i][i];
                } else {
                    l[i][j] = sum * inv[j];
                }
            }
        }
        Some(Self { l, inv, n })
    }

    /// x with A x = b on the leading block (entries past it are zero).
    pub fn solve(&self, b: &[f64; N]) -> [f64; N] {
        let (l, n) = (&self.l, self.n);
        let mut y = [0.0; N];
        for i in 0..n {
            y[i] = (b[i] - dot_prefix(&l[i], &y, i)) * self.inv[i];
        }
        for i in (0..n).rev() {
            let mut sum = y[i];
            for k in i + 1..n {
                sum -= l[k][i] * y[k];
            }
            y[i] = sum * self.inv[i];
        }
        y
    }
}

/// Σₖ₍ₖ<ₙ₎ aₖ bₖ.
fn dot_prefix<const N: usize>(a: &[f64; N], b: &[f64; N], n: usize) -> f64 {
    a[..n].iter().zip(&b[..n]).map(|(x, y)| x * y).sum()
}

/// Why [`projector`] could not compute P.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProjectorError {
    /// G is not (numerically) symmetric positive definite.
    MassMatrixNotPositiveDefinite,
    /// An input entry is NaN or infinite.
    NonFinite,
    /// The rows are (numerically) dependent: R G⁻¹ Rᵀ is singular.
    DependentRows,
}

/// P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B from G and the rows of B, without allocation.
///
/// With G = L Lᵀ (Cholesky) and w = Lᵀ v the metric becomes Euclidean and
/// the rows of B become those of C = B L⁻ᵀ; P is L⁻ᵀ (orthogonal projector
/// onto the row space of C) Lᵀ. The row space is spanned by Gram–Schmidt,
/// so rows of B that depend on earlier ones (relative size below `1e-12`)
/// are ignored rather than making BG⁻¹Bᵀ singular.
pub fn projector<const N: usize>(
    g: &[[f64; N]; N],
    b_rows: &[[f64; N]],
) -> Result<[[f64; N]; N], ProjectorError> {
    let finite = |r: &[f64; N]| r.iter().all(|x| x.is_finite());
    if !g.iter().all(finite) || !b_rows.iter().all(finite) {
        return Err(ProjectorError::NonFinite);
    }
    let gm = SMatrix::<f64, N, N>::from_fn(|i, j| g[i][j]);
    let chol = gm
        .cholesky()
        .ok_or(ProjectorError::MassMatrixNotPositiveDefinite)?;
    let l = chol.l();
    // Orthonormal basis of the row space of C = B L⁻ᵀ, i.e. of the columns
    // of L⁻¹ Bᵀ.
    let mut basis = [[0.0; N]; N];
    let mut rank = 0;
    for row in b_rows {
        let bt = nalgebra::SVector::<f64, N>::from_fn(|i, _| row[i]);
        let Some(c) = l.solve_lower_triangular(&bt) else {
            return Err(ProjectorError::MassMatrixNotPositiveDefinite);
        };
        let mut c: [f64; N] = core::array::from_fn(|i| c[i]);
        let size = libm::sqrt(dot(&c, &c));
        for e in &basis[..rank] {
            let k = dot(e, &c);
            for (ci, ei) in c.iter_mut().zip(e) {
                *ci -= k * ei;
            }
        }
        let rest = libm::sqrt(dot(&c, &c));
        if size > 0.0 && rest > 1e-12 * size && rank < N {
            basis[rank] = c.map(|x| x / rest);
            rank += 1;
        }
    }
    // P_w = Σ e eᵀ; P = L⁻ᵀ P_w Lᵀ.
    let mut pw = SMatrix::<f64, N, N>::zeros();
    for e in &basis[..rank] {
        let ev = nalgebra::SVector::<f64, N>::from_fn(|i, _| e[i]);
        pw += ev * ev.transpose();
    }
    let lt = l.transpose();
    let p_lt = pw * lt;
    let Some(p) = lt.solve_upper_triangular(&p_lt) else {
        return Err(ProjectorError::MassMatrixNotPositiveDefinite);
    };
    Ok(core::array::from_fn(|i| {
        core::array::from_fn(|j| p[(i, j)])
    }))
}

/// The collision map v⁺ = (I − 2P) v.
pub fn reflect<const N: usize>(p: &[[f64; N]; N], v: &[f64; N]) -> [f64; N] {
    let pv = mat_vec(p, v);
    core::array::from_fn(|i| v[i] - 2.0 * pv[i])
}

/// The smallest correction in the metric of G that removes the residuals
/// `r` of the rows `rows`: δ = G⁻¹Rᵀ(RG⁻¹Rᵀ)⁻¹r, so that R δ = r and δ is
/// G-orthogonal to ker R. Subtracting it from a velocity v with r = R v
/// projects v onto ker R; subtracting it from q with r = h(q) is one
/// Gauss–Newton step towards h = 0.
pub fn correction<const N: usize>(
    g: &[[f64; N]; N],
    rows: &[[f64; N]],
    r: &[f64],
) -> Result<[f64; N], ProjectorError> {
    let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
    if !g.iter().all(|row| finite(row)) || !rows.iter().all(|row| finite(row)) || !finite(r) {
        return Err(ProjectorError::NonFinite);
    }
    let k = rows.len().min(r.len()).min(N);
    let chol = Cholesky::new(g, N).ok_or(ProjectorError::MassMatrixNotPositiveDefinite)?;
    // Y's columns G⁻¹Rᵀ, then the k×k system (R Y) μ = r.
    let mut y = [[0.0; N]; N];
    for (c, row) in rows[..k].iter().enumerate() {
        y[c] = chol.solve(row);
    }
    let mut s = [[0.0; N]; N];
    let mut rhs = [0.0; N];
    for a in 0..k {
        for b in 0..k {
            s[a][b] = dot(&rows[a], &y[b]);
        }
        rhs[a] = r[a];
    }
    let mu = Cholesky::new(&s, k)
        .ok_or(ProjectorError::DependentRows)?
        .solve(&rhs);
    let mut delta = [0.0; N];
    for (c, yc) in y[..k].iter().enumerate() {
        for (d, yi) in delta.iter_mut().zip(yc) {
            *d += mu[c] * yi;
        }
    }
    if finite(&delta) {
        Ok(delta)
    } else {
        Err(ProjectorError::DependentRows)
    }
}
