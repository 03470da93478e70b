//! "Certainly not zero" without expanding: an expression's value at one
//! point, computed at two precisions. The exact zero test (an expansion
//! and a rational function) costs as much as the expansion, which for a
//! sum of products of large sums is far more than the expression (a
//! potential √((1 + x + y + z)¹⁵)·(1 + x − y + z)¹⁰ has a force that
//! expands to hundreds of thousands of products); the value costs one walk
//! of the expression.
//!
//! An expression that is zero as a rational function of its symbols and
//! function applications is zero at every point where it is defined, so
//! a value that is clearly not zero settles the test. "Clearly" is decided
//! without knowing the expression's scale: rounding errors of a zero value
//! shrink with the precision (about 2⁻¹²⁸ and 2⁻²⁵⁶ of its terms), while a
//! value that is not zero stays put, so two values that agree to 2⁻⁶⁴ are
//! not rounding. Anything else (the two disagree, a value is not finite, a
//! function has no value at the point) answers nothing, and the exact
//! test decides. The point puts each symbol in [1/4, 3/4], from a hash of
//! its name (the same point every run), where square roots and logarithms
//! of the symbols themselves are real.

use std::collections::HashSet;

use symbolica::prelude::*;

use super::atoms::children;

/// The two precisions, in bits.
const LOW: u32 = 128;
const HIGH: u32 = 256;

/// Whether `a` is certainly not zero; `false` says nothing.
pub fn nonzero(a: &Atom) -> bool {
    let mut symbols = HashSet::new();
    collect(a.as_view(), &mut symbols);
    let value = |prec: u32| {
        let map: std::collections::HashMap<Atom, Float> = symbols
            .iter()
            .map(|s| (Atom::from(*s), Float::with_val(prec, coordinate(*s))))
            .collect();
        a.evaluate_with_prec(&map, prec).ok()
    };
    let (Some(low), Some(high)) = (value(LOW), value(HIGH)) else {
        return false;
    };
    let (low, high) = (low.to_f64(), high.to_f64());
    // Agreement to 2⁻⁶⁴ shows in f64 as agreement to its last bits.
    high.is_finite() && high != 0.0 && (low - high).abs() <= 4.0 * f64::EPSILON * high.abs()
}

/// The symbols `a` reads as variables (not the functions it applies).
fn collect(a: AtomView, out: &mut HashSet<Symbol>) {
    if let AtomView::Var(v) = a {
        out.insert(v.get_symbol());
    }
    children(a).into_iter().for_each(|x| collect(x, out));
}

/// The symbol's value at the point: in [1/4, 3/4], from an FNV-1a hash of
/// its name.
fn coordinate(s: Symbol) -> f64 {
    let hash = s
        .to_string()
        .bytes()
        .fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
    0.25 + 0.5 * (hash >> 11) as f64 / (1u64 << 53) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::derive::build::{Namespace, own_symbol};

    /// Values settle "not zero" for expressions that are not, whatever
    /// their scale, and never for expressions that are zero but not
    /// written as 0 (rounding at the two precisions differs there).
    #[test]
    fn only_values_that_are_not_rounding_settle() {
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("probe test");
        let [x, y, z] = ["x", "y", "z"].map(|n| Atom::from(own_symbol(n)));
        let one = Atom::num(1);
        let half = Atom::num(1) / Atom::num(2);
        let sum = &one + &x + &y + &z;
        let zeros = [
            // (1 + x)² − 1 − 2x − x², unexpanded.
            (&one + &x).pow(Atom::num(2)) - &one - Atom::num(2) * &x - x.pow(Atom::num(2)),
            // sin² + cos² − 1: zero as a function, though not as a rational
            // function of sin and cos (the exact test says no; the values
            // must not say anything).
            function!(Symbol::SIN, &x).pow(Atom::num(2))
                + function!(Symbol::COS, &x).pow(Atom::num(2))
                - &one,
            // √s·√s − s, with s large at the point.
            sum.pow(Atom::num(40)).pow(half.clone()).pow(Atom::num(2)) - sum.pow(Atom::num(40)),
            Atom::num(0),
        ];
        for a in &zeros {
            assert!(!nonzero(a), "{a}");
        }
        let tiny = Atom::num(1) / Atom::num(10).pow(Atom::num(30));
        let not_zeros = [
            &x - &y,
            // Small and large values alike.
            &tiny * (&x - &y),
            sum.pow(Atom::num(60)) * (&x - &z),
            sum.pow(half) * function!(Symbol::LOG, &y) - &z,
        ];
        for a in &not_zeros {
            assert!(nonzero(a), "{a}");
        }
        // Outside the functions' domains, or where a difference cancels
        // all but a part below the rounding of its terms, the values say
        // nothing (the exact test decides).
        let undefined = function!(Symbol::LOG, &x - &one) * &y;
        let cancelled = &zeros[0] + &tiny;
        for a in [undefined, cancelled] {
            assert!(!nonzero(&a), "{a}");
        }
    }
}
