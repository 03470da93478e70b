//! Small fixed-size linear algebra, without heap allocation: one Cholesky
//! factorisation and one constrained solve ([`constrained_solve`]) that the
//! equations of motion, the projections onto the constraints and the
//! structured collision maps share.
//!
//! [`projector`] computes P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B numerically from G and the rows
//! of B. Generated models evaluate P from its symbolic form where they can;
//! this is the generic path (and an independent check of the generated one).

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
/// Every solve of the runtime uses it: the equations of motion (for models
/// without a closed-form q̈), projections onto the constraints and
/// structured collision maps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cholesky<const N: usize> {
    l: [[f64; N]; N],
    /// 1 / Lᵢᵢ: divisions are the slow part of a small factorisation.
    inv: [f64; N],
    n: usize,
}

/// A Cholesky pivot at most this many units of roundoff of its diagonal
/// entry counts as zero ([`Cholesky::new`]).
pub const PIVOT_ULPS: f64 = 16.0;

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
                    // A pivot within rounding of zero, relative to the
                    // entry it came from, has lost every digit to
                    // cancellation: the block is singular to working
                    // precision (a coin lying flat in z-x-z angles, whose
                    // φ and ψ turn it about one axis). NaN fails too.
                    let floor = PIVOT_ULPS * f64::EPSILON * libm::fabs(a[i][i]);
                    if sum.partial_cmp(&floor) != Some(core::cmp::Ordering::Greater) {
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
        self.solve_upper(&self.solve_lower(b))
    }

    /// y with L y = b (forward substitution).
    pub fn solve_lower(&self, b: &[f64; N]) -> [f64; N] {
        let (l, n) = (&self.l, self.n);
        let mut y = [0.0; N];
        for i in 0..n {
            y[i] = (b[i] - dot_prefix(&l[i], &y, i)) * self.inv[i];
        }
        y
    }

    /// x with Lᵀ x = y (back substitution).
    pub fn solve_upper(&self, y: &[f64; N]) -> [f64; N] {
        let (l, n) = (&self.l, self.n);
        let mut y = *y;
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
    /// The conditions on a velocity cannot all hold: rates given at a start
    /// that no admissible velocity has (they contradict the constraints or
    /// each other).
    Inconsistent,
}

impl core::fmt::Display for ProjectorError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            ProjectorError::MassMatrixNotPositiveDefinite => {
                "the mass matrix G(q) is not positive definite (a zero or negative mass or moment of inertia, or a coordinate singularity?)"
            }
            ProjectorError::NonFinite => "an entry of G(q) or of the rows is not finite",
            ProjectorError::DependentRows => {
                "the constraint rows are dependent here (B G⁻¹ Bᵀ is singular)"
            }
            ProjectorError::Inconsistent => {
                "the rates given at the start contradict the constraints or each other: no admissible velocity has them all"
            }
        })
    }
}

/// P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B from G and the rows of B, without allocation.
///
/// With G = L Lᵀ (Cholesky) and w = Lᵀ v the metric becomes Euclidean and
/// the rows of B become those of C = B L⁻ᵀ; P is L⁻ᵀ (orthogonal projector
/// onto the row space of C) Lᵀ. The row space is spanned by Gram–Schmidt,
/// so rows of B that depend on earlier ones (relative size below `1e-12`)
/// are ignored rather than making BG⁻¹Bᵀ singular.
#[allow(clippy::needless_range_loop)] // matrix code reads best with indices
pub fn projector<const N: usize>(
    g: &[[f64; N]; N],
    b_rows: &[[f64; N]],
) -> Result<[[f64; N]; N], ProjectorError> {
    let finite = |r: &[f64; N]| r.iter().all(|x| x.is_finite());
    if !g.iter().all(finite) || !b_rows.iter().all(finite) {
        return Err(ProjectorError::NonFinite);
    }
    let chol = Cholesky::new(g, N).ok_or(ProjectorError::MassMatrixNotPositiveDefinite)?;
    // Orthonormal basis of the row space of C = B L⁻ᵀ, i.e. of the columns
    // of L⁻¹ Bᵀ.
    let mut basis = [[0.0; N]; N];
    let mut rank = 0;
    for row in b_rows {
        let mut c = chol.solve_lower(row);
        let size = libm::sqrt(dot(&c, &c));
        off_span(&basis[..rank], &mut c);
        let rest = libm::sqrt(dot(&c, &c));
        if size > 0.0 && rest > 1e-12 * size && rank < N {
            basis[rank] = c.map(|x| x / rest);
            rank += 1;
        }
    }
    // P_w = Σ e eᵀ; column j of P is L⁻ᵀ (P_w Lᵀ)ⱼ, and (Lᵀ)ₖⱼ = Lⱼₖ.
    let mut p = [[0.0; N]; N];
    for j in 0..N {
        let lt_col: [f64; N] = core::array::from_fn(|k| chol.l[j][k]);
        let mut col = [0.0; N];
        for e in &basis[..rank] {
            let k = dot(e, &lt_col);
            for (ci, ei) in col.iter_mut().zip(e) {
                *ci += k * ei;
            }
        }
        let x = chol.solve_upper(&col);
        for (i, xi) in x.iter().enumerate() {
            p[i][j] = *xi;
        }
    }
    if p.iter().all(finite) {
        Ok(p)
    } else {
        Err(ProjectorError::MassMatrixNotPositiveDefinite)
    }
}

/// The v of least ½ vᵀHv with rₖ·v = dₖ for the `conditions` (rₖ, dₖ), for
/// H symmetric positive definite.
///
/// The rows are taken in order; one that depends on earlier ones (its part
/// off their span, in the metric of H, below `1e-12` of its size) adds no
/// condition, so the independent rows hold exactly and the caller checks
/// the others (they hold too when the conditions are consistent). With
/// H = L Lᵀ and w = Lᵀ v the conditions read (L⁻¹rₖ)·w = dₖ and the least
/// |w| lies in the span of the L⁻¹rₖ: Gram–Schmidt builds an orthonormal
/// basis of it and, row by row, w's component along each new vector.
pub fn least_solution<const N: usize>(
    h: &[[f64; N]; N],
    conditions: impl IntoIterator<Item = ([f64; N], f64)>,
) -> Result<[f64; N], ProjectorError> {
    let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
    if !h.iter().all(|row| finite(row)) {
        return Err(ProjectorError::NonFinite);
    }
    let chol = Cholesky::new(h, N).ok_or(ProjectorError::MassMatrixNotPositiveDefinite)?;
    let mut basis = [[0.0; N]; N];
    let mut along = [0.0; N];
    let mut rank = 0;
    for (row, dk) in conditions {
        if !finite(&row) || !dk.is_finite() {
            return Err(ProjectorError::NonFinite);
        }
        let mut c = chol.solve_lower(&row);
        let size = libm::sqrt(dot(&c, &c));
        let parts = off_span(&basis[..rank], &mut c);
        let known: f64 = parts.iter().zip(&along[..rank]).map(|(k, a)| k * a).sum();
        let rest = libm::sqrt(dot(&c, &c));
        if size > 0.0 && rest > 1e-12 * size && rank < N {
            basis[rank] = c.map(|x| x / rest);
            along[rank] = (dk - known) / rest;
            rank += 1;
        }
    }
    let mut w = [0.0; N];
    for (e, a) in basis[..rank].iter().zip(&along[..rank]) {
        for (wi, ei) in w.iter_mut().zip(e) {
            *wi += a * ei;
        }
    }
    let v = chol.solve_upper(&w);
    if finite(&v) {
        Ok(v)
    } else {
        Err(ProjectorError::DependentRows)
    }
}

/// Removes from `c` its components along the orthonormal `basis` (modified
/// Gram–Schmidt) and returns them, one per basis vector.
fn off_span<const N: usize>(basis: &[[f64; N]], c: &mut [f64; N]) -> [f64; N] {
    let mut parts = [0.0; N];
    for (e, part) in basis.iter().zip(parts.iter_mut()) {
        *part = dot(e, c);
        for (ci, ei) in c.iter_mut().zip(e) {
            *ci -= *part * ei;
        }
    }
    parts
}

/// The collision map v⁺ = (I − 2P) v.
pub fn reflect<const N: usize>(p: &[[f64; N]; N], v: &[f64; N]) -> [f64; N] {
    let pv = mat_vec(p, v);
    core::array::from_fn(|i| v[i] - 2.0 * pv[i])
}

/// The constrained solve: with G = L Lᵀ and the rows R (k of them),
/// Y = G⁻¹Rᵀ and the k×k system (R Y) μ = `rhs`, returns `base` + Y μ and
/// μ. R G⁻¹ Rᵀ is symmetric, and positive definite exactly when R's rows are
/// independent: `None` otherwise. The equations of motion (μ = λ, base =
/// −G⁻¹h) and [`correction`] (base = 0) are both this solve.
pub fn constrained_solve<const N: usize>(
    chol: &Cholesky<N>,
    rows: &[[f64; N]],
    rhs: &[f64],
    base: [f64; N],
) -> Option<([f64; N], [f64; N])> {
    let k = rows.len().min(rhs.len()).min(N);
    let mut y = [[0.0; N]; N];
    for (c, row) in rows[..k].iter().enumerate() {
        y[c] = chol.solve(row);
    }
    let mut s = [[0.0; N]; N];
    let mut b = [0.0; N];
    for a in 0..k {
        for c in 0..k {
            s[a][c] = dot(&rows[a], &y[c]);
        }
        b[a] = rhs[a];
    }
    let mu = Cholesky::new(&s, k)?.solve(&b);
    let mut out = base;
    for (c, yc) in y[..k].iter().enumerate() {
        for (o, yi) in out.iter_mut().zip(yc) {
            *o += mu[c] * yi;
        }
    }
    Some((out, mu))
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
    let chol = Cholesky::new(g, N).ok_or(ProjectorError::MassMatrixNotPositiveDefinite)?;
    let (delta, _) =
        constrained_solve(&chol, rows, r, [0.0; N]).ok_or(ProjectorError::DependentRows)?;
    if finite(&delta) {
        Ok(delta)
    } else {
        Err(ProjectorError::DependentRows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const H: [[f64; 3]; 3] = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];

    /// The least ½ vᵀHv with R v = d satisfies the rows, and H v is
    /// orthogonal to ker R (the optimality condition H v = Rᵀμ).
    #[test]
    fn least_solution_meets_the_rows_and_is_least() {
        let rows = [[1.0, 2.0, -1.0]];
        let v = least_solution(&H, [(rows[0], 3.0)]).unwrap();
        assert!((dot(&rows[0], &v) - 3.0).abs() < 1e-14);
        // Two directions spanning ker R.
        for z in [[2.0, -1.0, 0.0], [1.0, 0.0, 1.0]] {
            assert!(dot(&rows[0], &z).abs() < 1e-15);
            assert!(dot(&mat_vec(&H, &v), &z).abs() < 1e-14, "{v:?}");
        }
        // By hand: μ = d / (R H⁻¹ Rᵀ), v = μ H⁻¹ Rᵀ, the same solve.
        let chol = Cholesky::new(&H, 3).unwrap();
        let y = chol.solve(&rows[0]);
        let mu = 3.0 / dot(&rows[0], &y);
        for i in 0..3 {
            assert!((v[i] - mu * y[i]).abs() < 1e-14);
        }
    }

    /// A row that repeats a combination of earlier ones adds no condition:
    /// consistent, the answer is that of the independent rows; conflicting,
    /// the independent rows hold and the repeated one does not.
    #[test]
    fn dependent_rows_add_no_condition() {
        let rows = [[1.0, 0.0, 1.0], [0.0, 1.0, 0.0], [2.0, 1.0, 2.0]];
        let with = |d: [f64; 3], k: usize| least_solution(&H, rows.into_iter().zip(d).take(k));
        let alone = with([1.0, 2.0, 0.0], 2).unwrap();
        let consistent = with([1.0, 2.0, 4.0], 3).unwrap();
        assert_eq!(alone, consistent);
        let conflicting = with([1.0, 2.0, 5.0], 3).unwrap();
        assert!((dot(&rows[0], &conflicting) - 1.0).abs() < 1e-14);
        assert!((dot(&rows[2], &conflicting) - 4.0).abs() < 1e-14);
        assert_eq!(
            least_solution(&[[0.0; 3]; 3], rows.into_iter().zip([1.0, 2.0, 4.0])),
            Err(ProjectorError::MassMatrixNotPositiveDefinite)
        );
    }
}
