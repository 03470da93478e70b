//! The linear solve inside a series: where q̈ is given by G(q) q̈ = −h(q, q̇)
//! (a dense G with no closed-form inverse), its Taylor coefficients follow
//! order by order from G's and h's without expanding the inverse:
//! Σⱼ₌₀..ₖ Gⱼ xₖ₋ⱼ = hₖ gives
//!
//! xₖ = G₀⁻¹ (hₖ − Σⱼ₌₁..ₖ Gⱼ xₖ₋ⱼ),   q̈ₖ = −xₖ,
//!
//! so G₀ = L D Lᵀ is factored once per series ([`ldl_factor`]) and every
//! order costs one history per entry of G that varies and one pair of
//! triangular solves ([`ldl_solve`]). Both work in place on G's lower
//! triangle packed row by row ([`lower`]), on slices, so generated code
//! (fixed arrays) and the generator's interpreter (vectors) run the same
//! operations in the same order.

/// Where entry (i, j), j ≤ i, of a symmetric n×n matrix is in its lower
/// triangle packed row by row (G₀₀, G₁₀, G₁₁, G₂₀, …).
#[inline(always)]
pub const fn lower(i: usize, j: usize) -> usize {
    i * (i + 1) / 2 + j
}

/// G = L D Lᵀ in place (L unit lower triangular, D diagonal, no pivoting:
/// G symmetric positive definite, as a mass matrix is): `a` holds G's
/// lower triangle ([`lower`]) for an n×n G, and on return L's entries
/// below the diagonal and D on it. A G that is not positive definite
/// leaves a zero, negative or non-finite entry of D, which the solve
/// carries into its result.
#[inline]
pub fn ldl_factor(a: &mut [f64], n: usize) {
    for i in 0..n {
        for j in 0..i {
            let mut s = a[lower(i, j)];
            for m in 0..j {
                s -= a[lower(i, m)] * a[lower(m, m)] * a[lower(j, m)];
            }
            a[lower(i, j)] = s / a[lower(j, j)];
        }
        let mut d = a[lower(i, i)];
        for m in 0..i {
            let l = a[lower(i, m)];
            d -= l * a[lower(m, m)] * l;
        }
        a[lower(i, i)] = d;
    }
}

/// x with L D Lᵀ x = r, in place in `r` (n = its length), from
/// [`ldl_factor`]'s `a`: forward substitution, the diagonal, back
/// substitution.
#[inline]
pub fn ldl_solve(a: &[f64], r: &mut [f64]) {
    let n = r.len();
    for i in 0..n {
        let mut y = r[i];
        for m in 0..i {
            y -= a[lower(i, m)] * r[m];
        }
        r[i] = y;
    }
    for i in 0..n {
        r[i] /= a[lower(i, i)];
    }
    for i in (0..n).rev() {
        let mut x = r[i];
        for m in i + 1..n {
            x -= a[lower(m, i)] * r[m];
        }
        r[i] = x;
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // matrices by index, as written on paper
mod tests {
    use super::*;

    /// A 3×3 positive definite G: the solve returns x with G x = r to
    /// rounding, and the factors multiply back to G.
    #[test]
    fn solves_a_positive_definite_system() {
        let g = [[4.0, 1.0, 0.5], [1.0, 3.0, -0.25], [0.5, -0.25, 2.0]];
        let mut a = [0.0; 6];
        for i in 0..3 {
            for j in 0..=i {
                a[lower(i, j)] = g[i][j];
            }
        }
        ldl_factor(&mut a, 3);
        // L D Lᵀ = G.
        for i in 0..3 {
            for j in 0..=i {
                let l = |r: usize, c: usize| match r.cmp(&c) {
                    core::cmp::Ordering::Equal => 1.0,
                    core::cmp::Ordering::Greater => a[lower(r, c)],
                    core::cmp::Ordering::Less => 0.0,
                };
                let back: f64 = (0..3).map(|m| l(i, m) * a[lower(m, m)] * l(j, m)).sum();
                assert!((back - g[i][j]).abs() <= 1e-15 * 4.0, "({i}, {j}): {back}");
            }
        }
        let r = [1.0, -2.0, 3.0];
        let mut x = r;
        ldl_solve(&a, &mut x);
        for i in 0..3 {
            let gx: f64 = (0..3).map(|j| g[i][j] * x[j]).sum();
            assert!((gx - r[i]).abs() <= 1e-14, "row {i}: {gx} against {}", r[i]);
        }
    }

    /// A singular G leaves a non-finite solution rather than a wrong
    /// finite one.
    #[test]
    fn singular_gives_non_finite() {
        let mut a = [1.0, 1.0, 1.0];
        ldl_factor(&mut a, 2);
        let mut x = [1.0, 2.0];
        ldl_solve(&a, &mut x);
        assert!(x.iter().any(|v| !v.is_finite()), "{x:?}");
    }
}
