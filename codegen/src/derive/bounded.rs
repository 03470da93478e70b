//! Exact matrix arithmetic over rational functions, each product and
//! inverse weighed before it is made: the closed forms of q̈ and P are
//! products of G⁻¹, A or B and the right side, and one step of them can
//! multiply out to millions of terms before common factors cancel (a
//! rolling shell whose centre moves along x·acosh(x + φ): λ = (AG⁻¹Aᵀ)⁻¹r
//! alone took 7 s, the whole q̈ 13 s, and it compiled to 15 000
//! operations where the solve at run time takes 500).
//!
//! The weight is the terms the numerators multiply out to before
//! cancellation, an entry's numerators summed over its products, the
//! denominators left aside (they share factors, det G above all, that a
//! count multiplying them out would overstate a hundredfold). Past
//! [`budget::MAX_PRODUCT_TERMS`] the step is not made ([`Over::Product`]).

use symbolica::prelude::*;

use super::budget::{self, Over};
use super::{Field, Rat};

/// a·b, or [`Over`] where an entry's numerators multiply out past the
/// limit.
pub fn mul(a: &Matrix<Field>, b: &Matrix<Field>) -> Result<Matrix<Field>, Over> {
    let mut most = 0.0_f64;
    for i in 0..a.nrows() as u32 {
        for j in 0..b.ncols() as u32 {
            let entry: f64 = (0..a.ncols() as u32)
                .map(|k| terms(&a[(i, k)]) * terms(&b[(k, j)]))
                .sum();
            most = most.max(entry);
        }
    }
    within(most)?;
    Ok(a * b)
}

/// a⁻¹ (`None` where a is singular), or [`Over`] where its determinant's
/// numerator may pass the limit (the permanent of the numerators' term
/// counts, [`budget::estimate`]).
pub fn inv(a: &Matrix<Field>) -> Result<Option<Matrix<Field>>, Over> {
    let counts: Vec<Vec<Option<u64>>> = (0..a.nrows() as u32)
        .map(|i| {
            (0..a.ncols() as u32)
                .map(|j| budget::numerator_count(&a[(i, j)]))
                .collect()
        })
        .collect();
    within(budget::estimate(&counts))?;
    Ok(a.inv().ok())
}

/// [`Over::Product`] past [`budget::MAX_PRODUCT_TERMS`].
fn within(bound: f64) -> Result<(), Over> {
    if bound > budget::MAX_PRODUCT_TERMS {
        return Err(Over::Product(bound));
    }
    Ok(())
}

/// An entry's numerator terms (0 for zero).
fn terms(x: &Rat) -> f64 {
    x.numerator.nterms() as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::derive::build::{Namespace, own_symbol};

    /// A product is weighed by its numerators before it is made: within
    /// the limit it is the plain product, past it refused; an inverse by
    /// the permanent of its numerators' counts.
    #[test]
    fn steps_are_weighed_before_they_are_made() {
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("bounded test");
        let [x, y] = ["x", "y"].map(|n| Atom::from(own_symbol(n)));
        let vars = std::sync::Arc::new(vec![
            PolyVariable::Symbol(own_symbol("x")),
            PolyVariable::Symbol(own_symbol("y")),
        ]);
        let rat = |a: &Atom| -> Rat { a.to_rational_polynomial(&Q, &Z, Some(vars.clone())) };
        let field = Field::from_poly(&rat(&x).numerator);
        let one = Atom::num(1);
        // A sum of 1 225 terms, and its square's entries 1 225² = 1 500 625.
        let mut big = Atom::num(0);
        for i in 0..35 {
            for j in 0..35 {
                big += x.pow(Atom::num(i)) * y.pow(Atom::num(j));
            }
        }
        let column = |e: &Atom| Matrix::from_linear(vec![rat(e)], 1, 1, field.clone()).unwrap();
        let small = column(&(&x + &one));
        let within = mul(&small, &column(&big)).unwrap();
        assert_eq!(within[(0, 0)], rat(&((&x + &one) * &big)));
        assert!(
            matches!(mul(&column(&big), &column(&big)), Err(Over::Product(t)) if t == 1_500_625.0)
        );
        let pair = |a: &Atom, b: &Atom, c: &Atom, d: &Atom| {
            Matrix::from_linear(vec![rat(a), rat(b), rat(c), rat(d)], 2, 2, field.clone()).unwrap()
        };
        let zero = Atom::num(0);
        let diagonal = pair(&x, &zero, &zero, &(&y + &one));
        let inverse = inv(&diagonal).unwrap().unwrap();
        assert_eq!(inverse[(0, 0)], rat(&(&one / &x)));
        assert!(inv(&pair(&x, &x, &x, &x)).unwrap().is_none());
        assert!(matches!(
            inv(&pair(&big, &big, &big, &(&big + &one))),
            Err(Over::Product(_))
        ));
    }
}
