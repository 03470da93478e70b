//! What the derivation's expansions would cost, estimated before they are
//! made ([`expansion_terms`], [`expand`]), and what an exact G⁻¹ would
//! cost, estimated before it is attempted: the
//! number of terms of det G, bounded by the permanent of the matrix of
//! its entries' term counts (each of det G's n! products has at most as
//! many terms as the product of its factors' counts). Blocks of G that no
//! non-zero entry couples are inverted apart, so the estimate is the
//! largest block's; a block of numbers alone costs nothing.

use std::ops::Range;

use symbolica::prelude::*;

use super::{Rat, is_zero};
use crate::diag::{Collector, ErrorKind, Reported};

/// Most terms one expansion in the derivation may produce, by the bound of
/// [`expansion_terms`]. The file's own expressions are bounded before
/// derivation (`ir::limits::MAX_TERMS`), but differentiating multiplies
/// them out: a wall 1 − √((1 + x + y + z)ⁿ), of 816 terms at n = 15, has a
/// Hessian form bounded by 4.2 million terms and grew to 21 GB in 120 s
/// (`dalembert derive`, 2026-12-05); at n = 9 (bound 246 105) it took
/// 18 s, and at n = 7, within the limit, it derives in 4.3–4.6 s.
pub const MAX_EXPANDED_TERMS: f64 = 100_000.0;

/// An upper bound on the terms `a` expands to, products distributed and
/// positive integer powers of sums multiplied out, or on those of any
/// base or argument expanded inside it, whichever is larger.
pub fn expansion_terms(a: &Atom) -> f64 {
    let (own, inner) = terms(a.as_view());
    own.max(inner)
}

/// `a` expanded, or an error at `span` naming `what` and the limit when
/// its expansion could exceed [`MAX_EXPANDED_TERMS`].
pub fn expand(
    a: &Atom,
    cx: &mut Collector,
    span: &Range<usize>,
    what: &str,
) -> Result<Atom, Reported> {
    within(expansion_terms(a), cx, span, what)?;
    Ok(a.expand())
}

/// An expansion or reduction not made, for a caller to report at its
/// declaration ([`Over::report`]).
#[derive(Debug, Clone, Copy)]
pub enum Over {
    /// Refused before it was made: the bound on its terms, past
    /// [`MAX_EXPANDED_TERMS`].
    Terms(f64),
    /// A step of an exact matrix computation refused before it was made:
    /// the bound of [`super::bounded`], past [`MAX_PRODUCT_TERMS`].
    Product(f64),
    /// A quotient whose denominator vanishes by sin² + cos² = 1 or
    /// cosh² − sinh² = 1: the exact algebra divided by it, taking rows
    /// dependent only through the identities for independent ones.
    VanishingDenominator,
}

impl Over {
    /// The error at `span` naming `what` and why (for too many terms, the
    /// bound and the limit).
    pub fn report(self, cx: &mut Collector, span: &Range<usize>, what: &str) -> Reported {
        let kind = match self {
            Self::Terms(bound) => ErrorKind::Limit(format!(
                "{what} may expand to {bound:.0} terms in the derivation; the limit is {MAX_EXPANDED_TERMS:.0}"
            )),
            Self::Product(bound) => ErrorKind::Limit(format!(
                "{what} is a product of exact matrices, one step of which multiplies out to {bound:.0} terms before common factors cancel; the limit is {MAX_PRODUCT_TERMS:.0}"
            )),
            Self::VanishingDenominator => ErrorKind::Symbolic(format!(
                "{what} divides by an expression that vanishes by sin² + cos² = 1 or cosh² − sinh² = 1: \
                 rows of A or B that are dependent only through these identities are not recognised as dependent"
            )),
        };
        cx.error(kind, Some(span.clone()))
    }
}

/// Most terms one step of an exact matrix product or inverse may multiply
/// out to before common factors cancel ([`super::bounded`]). The largest in
/// the models shipped is 150 060 (`chain_4_symbolic`'s P, which derives in
/// 1.3 s); a rolling shell whose centre moves along x·acosh(x + φ) reached
/// 6.8 million in one step of q̈, which took 7.2 s (`dalembert generate`,
/// 2026-12-08).
pub const MAX_PRODUCT_TERMS: f64 = 1_000_000.0;

/// Most terms (numerator and denominator, in lowest terms) an entry of q̈
/// in closed form may have; past it q̈ is solved at run time, in a few
/// hundred operations, instead of simplified, compiled and evaluated in
/// thousands. The largest in the models shipped are 3194 (`chain_4_symbolic`)
/// and 3165 (the Chaplygin ball as a quaternion, q̈ in 4284 operations);
/// the Chaplygin ball's quaternion with its centre at x·acosh(x + i₂) has
/// 44 087 and ran past 100 s simplifying them, a rolling shell's at
/// x·acosh(x + φ) 35 635, 15 032 operations (`dalembert generate`,
/// 2026-12-08).
pub const MAX_CLOSED_FORM_TERMS: f64 = 10_000.0;

/// The most nodes an entry of q̈ in closed form may have as the
/// expression compiled (exponentials expanded); past it q̈ is solved at
/// run time. The largest in the models shipped is 52 482 (the Chaplygin
/// ball as a quaternion, which derives in 3 s); with its centre at
/// x·exp(x + i₂), an entry of 2 072 terms had 8.9 million once its
/// exponentials were expanded, and compiling it took 30 s (4 609
/// operations; solved at run time, 30 s → 0.8 s, 709).
pub const MAX_CLOSED_FORM_SIZE: usize = 100_000;

/// [`Over`] when `bound` terms exceed [`MAX_EXPANDED_TERMS`].
pub fn check(bound: f64) -> Result<(), Over> {
    if bound > MAX_EXPANDED_TERMS {
        return Err(Over::Terms(bound));
    }
    Ok(())
}

/// An error at `span` naming `what` and the limit when `bound` terms
/// exceed [`MAX_EXPANDED_TERMS`] (a sum's bound, checked as its terms are
/// made, stops the work before the sum is whole).
pub fn within(
    bound: f64,
    cx: &mut Collector,
    span: &Range<usize>,
    what: &str,
) -> Result<(), Reported> {
    check(bound).map_err(|o| o.report(cx, span, what))
}

/// The bound of a sum whose terms are made one at a time (derivatives, as
/// a row or a form is built): each term's [`expansion_terms`] is added as
/// it is made, so that a sum past [`MAX_EXPANDED_TERMS`] stops at the term
/// that takes it there.
#[derive(Default)]
pub struct Running(f64);

impl Running {
    /// Adds `term`'s bound: an error at `span` naming `what` once the sum's
    /// is past the limit.
    pub fn add(
        &mut self,
        term: &Atom,
        cx: &mut Collector,
        span: &Range<usize>,
        what: &str,
    ) -> Result<(), Reported> {
        self.0 += expansion_terms(term);
        within(self.0, cx, span, what)
    }
}

/// An upper bound on the terms of `a` as a rational function in lowest
/// terms, numerator and denominator together, every symbol and function
/// application one variable (as [`super::lower::Lowering`] writes it):
/// over a common denominator, each base of a negative power counted once
/// at its highest power, and products and integer powers multiplied out.
///
/// A derivative is compact as the symbolic engine writes it and can be
/// exponential in this form: each level of a nested atan(u) divides by
/// 1 + u², and the common denominator multiplies them all out.
pub fn rational_terms(a: &Atom) -> f64 {
    let f = fraction(a.as_view());
    f.num + f.denominator()
}

/// A bound on a rational function's terms: its numerator's, and its
/// denominator as the bases of negative powers, each with its power and
/// its own bound.
struct Fraction<'a> {
    num: f64,
    den: Vec<(AtomView<'a>, u32, f64)>,
}

impl Fraction<'_> {
    fn one() -> Self {
        Self {
            num: 1.0,
            den: Vec::new(),
        }
    }

    /// The bound on the denominator's terms, multiplied out.
    fn denominator(&self) -> f64 {
        (self.den.iter())
            .map(|&(_, k, t)| monomials(t, k))
            .product()
    }
}

/// The monomials of degree `k` in `t` terms: C(t + k − 1, k), the terms of
/// a sum of `t` terms to the `k`th power.
fn monomials(t: f64, k: u32) -> f64 {
    (1..=k).fold(1.0, |c, i| c * (t + i as f64 - 1.0) / i as f64)
}

fn fraction(a: AtomView<'_>) -> Fraction<'_> {
    match a {
        AtomView::Add(s) => {
            let parts: Vec<Fraction> = s.iter().map(fraction).collect();
            // The common denominator: each base at its highest power.
            let mut den: Vec<(AtomView, u32, f64)> = Vec::new();
            for (b, k, t) in parts.iter().flat_map(|p| p.den.iter().copied()) {
                match den.iter_mut().find(|d| d.0 == b) {
                    Some(d) => d.1 = d.1.max(k),
                    None => den.push((b, k, t)),
                }
            }
            // Each numerator times the factors its own denominator lacks.
            let num = (parts.iter())
                .map(|p| {
                    let missing: f64 = (den.iter())
                        .map(|&(b, k, t)| {
                            let own = (p.den.iter().find(|d| d.0 == b)).map_or(0, |d| d.1);
                            monomials(t, k - own)
                        })
                        .product();
                    p.num * missing
                })
                .sum();
            Fraction { num, den }
        }
        AtomView::Mul(m) => m.iter().map(fraction).fold(Fraction::one(), |mut f, g| {
            f.num *= g.num;
            for (b, k, t) in g.den {
                match f.den.iter_mut().find(|d| d.0 == b) {
                    Some(d) => d.1 += k,
                    None => f.den.push((b, k, t)),
                }
            }
            f
        }),
        AtomView::Pow(p) => {
            let (b, e) = p.get_base_exp();
            let Ok(k) = e.to_string().parse::<i64>() else {
                // A fractional power is one variable.
                return Fraction::one();
            };
            let base = fraction(b);
            let n = k.unsigned_abs().min(u32::MAX as u64) as u32;
            if k >= 0 {
                Fraction {
                    num: monomials(base.num, n),
                    den: (base.den.into_iter())
                        .map(|(b, j, t)| (b, j.saturating_mul(n), t))
                        .collect(),
                }
            } else {
                // 1/(p/q)ⁿ = qⁿ/pⁿ: the base's numerator is the new
                // denominator, counted as the base itself.
                Fraction {
                    num: monomials(base.denominator(), n),
                    den: vec![(b, n, base.num)],
                }
            }
        }
        AtomView::Fun(_) | AtomView::Num(_) | AtomView::Var(_) => Fraction::one(),
    }
}

/// (terms of the view's own expansion, largest expansion inside a power
/// or function that stays unexpanded at this level).
fn terms(a: AtomView) -> (f64, f64) {
    match a {
        AtomView::Add(s) => s
            .iter()
            .map(terms)
            .fold((0.0, 0.0), |(t, i), (u, j)| (t + u, i.max(j))),
        AtomView::Mul(m) => m
            .iter()
            .map(terms)
            .fold((1.0, 0.0), |(t, i), (u, j)| (t * u, i.max(j))),
        AtomView::Pow(p) => {
            let (b, e) = p.get_base_exp();
            let (base, inner) = terms(b);
            match e.to_string().parse::<u32>() {
                // The monomials of degree k in `base` terms: C(base + k − 1, k).
                Ok(k) => (
                    (1..=k).fold(1.0, |c, i| c * (base + i as f64 - 1.0) / i as f64),
                    inner,
                ),
                // A negative or fractional power stays one factor.
                Err(_) => (1.0, base.max(inner)),
            }
        }
        AtomView::Fun(f) => (
            1.0,
            f.iter()
                .map(|x| {
                    let (t, i) = terms(x);
                    t.max(i)
                })
                .fold(0.0, f64::max),
        ),
        AtomView::Num(_) | AtomView::Var(_) => (1.0, 0.0),
    }
}

/// The largest estimate of det G's terms that a closed-form P is derived
/// for. chain_4_symbolic's G (4×4, entries of 2 to 6 terms) estimates
/// 1608 and derives in 20 s; chain_3's 74 in 0.6 s; chain_5's 53 992 ran
/// past 120 s and 4.9 GB (`dalembert derive`, 2026-12-05): the time grows
/// somewhat faster than the estimate.
pub const MAX_DETERMINANT_TERMS: f64 = 5000.0;

/// Blocks larger than this are bounded by the product of their rows' sums
/// (an upper bound on the permanent) instead of computed exactly (Ryser's
/// formula, 2ⁿ·n² operations).
const EXACT_UP_TO: usize = 16;

/// The estimate for G, entry by entry.
pub fn determinant_terms(g: &[Vec<Atom>]) -> f64 {
    let counts: Vec<Vec<Option<u64>>> = g
        .iter()
        .map(|row| row.iter().map(term_count).collect())
        .collect();
    estimate(&counts)
}

/// The estimate for the matrix [[G, Bᵀ], [B, 0]], whose determinant is
/// ±det G · det(BG⁻¹Bᵀ): the denominator that a closed-form P = G⁻¹Bᵀ
/// (BG⁻¹Bᵀ)⁻¹B divides by. B's entries count by their numerators' terms
/// (a row's entries share its denominator, which the determinant does not
/// multiply out).
pub fn bordered_terms(g: &[Vec<Atom>], b: &[Vec<Rat>]) -> f64 {
    let (n, k) = (g.len(), b.len());
    let mut counts = vec![vec![Some(0); n + k]; n + k];
    for (i, row) in g.iter().enumerate() {
        for (j, a) in row.iter().enumerate() {
            counts[i][j] = term_count(a);
        }
    }
    for (r, row) in b.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            let c = numerator_count(x);
            counts[n + r][j] = c;
            counts[j][n + r] = c;
        }
    }
    estimate(&counts)
}

/// An exact entry's count for [`estimate`]: its numerator's terms (0 for
/// zero), `None` for a plain number.
pub fn numerator_count(x: &Rat) -> Option<u64> {
    if x.numerator.is_zero() {
        Some(0)
    } else if x.numerator.is_constant() {
        None
    } else {
        Some(x.numerator.nterms() as u64)
    }
}

/// The largest block's bound, from the entries' term counts (`None` for a
/// plain number).
pub fn estimate(counts: &[Vec<Option<u64>>]) -> f64 {
    blocks(counts)
        .iter()
        .filter(|block| {
            !block
                .iter()
                .all(|&i| block.iter().all(|&j| counts[i][j].is_none_or(|c| c == 0)))
        })
        .map(|block| {
            let sub: Vec<Vec<f64>> = block
                .iter()
                .map(|&i| {
                    block
                        .iter()
                        .map(|&j| counts[i][j].unwrap_or(1) as f64)
                        .collect()
                })
                .collect();
            permanent_bound(&sub)
        })
        .fold(0.0, f64::max)
}

/// The number of terms of an entry as a sum (0 for zero); `None` for a
/// plain number, which adds no symbol to a product.
fn term_count(a: &Atom) -> Option<u64> {
    match a.as_view() {
        AtomView::Num(_) if is_zero(a) => Some(0),
        AtomView::Num(_) => None,
        AtomView::Add(s) => Some(s.iter().count() as u64),
        _ if is_zero(a) => Some(0),
        _ => Some(1),
    }
}

/// The sets of indices that non-zero entries connect, each sorted.
fn blocks(counts: &[Vec<Option<u64>>]) -> Vec<Vec<usize>> {
    let n = counts.len();
    let mut block: Vec<usize> = (0..n).collect();
    fn root(block: &mut [usize], mut i: usize) -> usize {
        while block[i] != i {
            block[i] = block[block[i]];
            i = block[i];
        }
        i
    }
    for (i, row) in counts.iter().enumerate() {
        for (j, &entry) in row.iter().enumerate().take(i) {
            if entry != Some(0) || counts[j][i] != Some(0) {
                let (a, b) = (root(&mut block, i), root(&mut block, j));
                block[a] = b;
            }
        }
    }
    let mut out: Vec<Vec<usize>> = Vec::new();
    let mut index = vec![usize::MAX; n];
    for i in 0..n {
        let r = root(&mut block, i);
        if index[r] == usize::MAX {
            index[r] = out.len();
            out.push(Vec::new());
        }
        out[index[r]].push(i);
    }
    out
}

/// The permanent of a square matrix of non-negative numbers, exactly up
/// to [`EXACT_UP_TO`] rows (Ryser), else the product of its row sums.
fn permanent_bound(a: &[Vec<f64>]) -> f64 {
    let n = a.len();
    if n > EXACT_UP_TO {
        return a.iter().map(|row| row.iter().sum::<f64>()).product();
    }
    let mut total = 0.0;
    for subset in 1u32..(1 << n) {
        let product: f64 = a
            .iter()
            .map(|row| {
                (0..n)
                    .filter(|j| subset >> j & 1 == 1)
                    .map(|j| row[j])
                    .sum::<f64>()
            })
            .product();
        let sign = if (n as u32 - subset.count_ones()).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        total += sign * product;
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::derive::build::{Differentiate, Namespace, own_symbol};

    /// The bound is exact for a power of a sum and for a product of sums,
    /// and never below the expanded count, through a square root too.
    #[test]
    fn expansion_bound_holds() {
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("budget test");
        let [x, y, z] = ["x", "y", "z"].map(|n| Atom::from(own_symbol(n)));
        let count = |a: &Atom| match a.expand().as_view() {
            AtomView::Add(s) => s.iter().count() as f64,
            _ => 1.0,
        };
        let one = Atom::num(1);
        let sum = &one + &x + &y + &z;
        let cube = sum.pow(Atom::num(3));
        assert_eq!(expansion_terms(&cube), 20.0);
        assert_eq!(count(&cube), 20.0);
        let product = (&x + &y) * (&x - &z + &one);
        assert_eq!(expansion_terms(&product), 6.0);
        assert!(count(&product) <= 6.0);
        let root = &one - cube.pow(Atom::num(1) / Atom::num(2));
        for a in [root.d(own_symbol("x")), product.d(own_symbol("x"))] {
            assert!(expansion_terms(&a) >= count(&a), "{a}");
        }
    }

    /// The bound on a rational function's terms is never below the count
    /// and close to it on the derivatives of nested atan (each level
    /// dividing by 1 + u²), with a shared denominator counted once.
    #[test]
    fn rational_bound_holds() {
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("budget test");
        let [x, y, z] = ["x", "y", "z"].map(|n| Atom::from(own_symbol(n)));
        let count = |a: &Atom| {
            let r: Rat = a.to_rational_polynomial(&Q, &Z, None);
            (r.numerator.nterms() + r.denominator.nterms()) as f64
        };
        let one = Atom::num(1);
        let shared = (&x + &y) / (&one + &x * &x) + &z / (&one + &x * &x);
        assert_eq!(rational_terms(&shared), 5.0);
        assert_eq!(count(&shared), 5.0);
        let apart = &one / (&one + &x) + &one / (&one + &y);
        assert!(rational_terms(&apart) >= count(&apart));
        // ∂/∂z of atan(a_{n−1} + z) with a_k = atan(a_{k−1} + z) and
        // a_0 = x·y, each atan a symbol of its own (as lowered).
        let (mut u, mut d) = (&x * &y + &z, Atom::num(0));
        let mut bounds = Vec::new();
        for level in 1..=5 {
            d = (d + &one) / (&one + &u * &u);
            let (bound, terms) = (rational_terms(&d), count(&d));
            assert!(
                terms <= bound && bound <= 2.0 * terms,
                "level {level}: {bound}, {terms}"
            );
            bounds.push(bound);
            u = Atom::from(own_symbol(&format!("a{level}"))) + &z;
        }
        assert!(bounds[4] > 100.0 * bounds[0], "{bounds:?}");
    }

    /// The permanent by its definition: the sum over permutations.
    fn by_permutations(a: &[Vec<f64>]) -> f64 {
        fn go(a: &[Vec<f64>], row: usize, used: &mut Vec<bool>) -> f64 {
            if row == a.len() {
                return 1.0;
            }
            let mut sum = 0.0;
            for j in 0..a.len() {
                if !used[j] {
                    used[j] = true;
                    sum += a[row][j] * go(a, row + 1, used);
                    used[j] = false;
                }
            }
            sum
        }
        go(a, 0, &mut vec![false; a.len()])
    }

    /// The term counts of the n-link chain's G: n − max(i, j) + 1 masses
    /// on the diagonal, twice that (a cosine of a difference, expanded)
    /// off it.
    fn chain(n: usize) -> Vec<Vec<f64>> {
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let masses = (n - i.max(j)) as f64;
                        if i == j { masses } else { 2.0 * masses }
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn ryser_is_the_permanent() {
        for n in 1..=7 {
            let a = chain(n);
            assert_eq!(permanent_bound(&a), by_permutations(&a), "n = {n}");
        }
        let a: Vec<Vec<f64>> = (0..6)
            .map(|i| (0..6).map(|j| ((3 * i + 5 * j) % 7) as f64).collect())
            .collect();
        assert_eq!(permanent_bound(&a), by_permutations(&a));
        assert_eq!(permanent_bound(&chain(4)), 1608.0);
        assert_eq!(permanent_bound(&chain(5)), 53992.0);
    }

    #[test]
    fn large_blocks_are_bounded_by_row_sums() {
        let a = vec![vec![1.0; EXACT_UP_TO + 1]; EXACT_UP_TO + 1];
        let n = (EXACT_UP_TO + 1) as f64;
        let bound = n.powi(EXACT_UP_TO as i32 + 1);
        assert!((permanent_bound(&a) / bound - 1.0).abs() < 1e-12);
    }

    #[test]
    fn uncoupled_blocks_are_apart() {
        let z = Some(0);
        let counts = vec![
            vec![Some(2), z, Some(3), z],
            vec![z, None, z, z],
            vec![Some(3), z, Some(1), z],
            vec![z, z, z, Some(4)],
        ];
        assert_eq!(blocks(&counts), vec![vec![0, 2], vec![1], vec![3]]);
    }
}
