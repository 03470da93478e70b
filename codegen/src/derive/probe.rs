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
//!
//! symbolica's evaluation does not know the functions of ours (atan, asin,
//! acos and the hyperbolic ones): each application of one is valued first,
//! innermost first, from its argument's value at the same precision
//! ([`own_value`]), and the expression is then evaluated with those values
//! given. Without them every expression with such a function went to the
//! exact test, whose expansion had no bound (a wall with atan, sinh, asin
//! and acos in it and a term x·y: its P's derivatives past 2 GB in a
//! second).

use std::collections::{HashMap, HashSet};

use symbolica::prelude::*;

use super::atoms::{argument, children};
use super::build::{Atoms, own_functions};
use crate::function::{Elementary, Function};

/// The two precisions, in bits.
const LOW: u32 = 128;
const HIGH: u32 = 256;

/// Whether `a` is certainly not zero; `false` says nothing.
pub fn nonzero(a: &Atom) -> bool {
    let mut symbols = HashSet::new();
    collect(a.as_view(), &mut symbols);
    let ours: Vec<Symbol> = own_functions().collect();
    let mut applied = Vec::new();
    applications(a.as_view(), &ours, &mut applied);
    let value = |prec: u32| {
        let mut map: HashMap<Atom, Float> = symbols
            .iter()
            .map(|s| (Atom::from(*s), Float::with_val(prec, coordinate(*s))))
            .collect();
        for (app, f) in &applied {
            let z = argument(app).evaluate_with_prec(&map, prec).ok()?;
            let y = own_value(*f, z, prec)?;
            map.insert(app.clone(), y);
        }
        a.evaluate_with_prec(&map, prec).ok()
    };
    let (Some(low), Some(high)) = (value(LOW), value(HIGH)) else {
        return false;
    };
    let (low, high) = (low.to_f64(), high.to_f64());
    // Agreement to 2⁻⁶⁴ shows in f64 as agreement to its last bits.
    high.is_finite() && high != 0.0 && (low - high).abs() <= 4.0 * f64::EPSILON * high.abs()
}

/// The applications of the functions `ours` in `a`, each once, every one
/// after those inside its argument.
fn applications(a: AtomView, ours: &[Symbol], out: &mut Vec<(Atom, Function)>) {
    for x in children(a) {
        applications(x, ours, out);
    }
    if let AtomView::Fun(f) = a
        && ours.contains(&f.get_symbol())
        && let Some(function) = Function::from_name(f.get_symbol().get_stripped_name())
        && !out.iter().any(|(b, _)| b.as_view() == a)
    {
        out.push((a.to_owned(), function));
    }
}

/// f(`z`) at precision `prec` for a function of ours, by its rule in the
/// elementary functions ([`Function::elementary`]), which symbolica
/// evaluates: a closed form (the hyperbolic functions and their inverses
/// by exponentials and logarithms), or Newton's method from libm's value
/// (atan, asin and acos on tan, sin and cos), used only where its last
/// step is below 2⁻⁽ᵖʳᵉᶜ⁻⁸⁾ of the result (else `None`: a value off in
/// the same bits at both precisions could make a zero look like none).
fn own_value(f: Function, z: Float, prec: u32) -> Option<Float> {
    let (x, y) = (
        Atom::from(symbol!("dalembert_probe::z")),
        Atom::from(symbol!("dalembert_probe::y")),
    );
    let at = |e: &Atom, y_value: Option<&Float>| {
        let mut map = HashMap::from([(x.clone(), z.clone())]);
        if let Some(v) = y_value {
            map.insert(y.clone(), v.clone());
        }
        e.evaluate_with_prec(&map, prec).ok()
    };
    match f.elementary(&mut Atoms, x.clone(), y.clone()) {
        Elementary::Itself => None,
        Elementary::Closed(e) => at(&e, None).filter(|v| v.to_f64().is_finite()),
        Elementary::Newton(step) => {
            let mut value = Float::with_val(prec, f.value(z.to_f64()));
            let next = &y - &step;
            for _ in 0..6 {
                value = at(&next, Some(&value))?;
            }
            let last = at(&step, Some(&value))?.to_f64();
            let size = value.to_f64();
            (last.abs() <= size.abs() * 2f64.powi(8 - prec as i32) && size.is_finite())
                .then_some(value)
        }
    }
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

    /// The functions of ours are valued at both precisions, so their
    /// identities are zero to rounding (never "not zero": each value is
    /// right to its precision) and other expressions in them are settled
    /// without the exact test.
    #[test]
    fn functions_of_ours_are_valued() {
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("probe test, ours");
        let [x, y, z] = ["x", "y", "z"].map(|n| Atom::from(own_symbol(n)));
        let ours = |f: Function, a: &Atom| function!(own_symbol(f.name()), a);
        let (sin, cos) = (
            |a: &Atom| function!(Symbol::SIN, a),
            |a: &Atom| function!(Symbol::COS, a),
        );
        let one = Atom::num(1);
        let half = Atom::num(1) / Atom::num(2);
        let identities = [
            // tan(atan x) = x, sin(asin y) = y, cos(acos z) = z.
            sin(&ours(Function::Atan, &x)) / cos(&ours(Function::Atan, &x)) - &x,
            sin(&ours(Function::Asin, &y)) - &y,
            cos(&ours(Function::Acos, &z)) - &z,
            // cosh² − sinh² = 1, and each inverse undoes its function.
            ours(Function::Cosh, &x).pow(Atom::num(2))
                - ours(Function::Sinh, &x).pow(Atom::num(2))
                - &one,
            ours(Function::Asinh, &ours(Function::Sinh, &y)) - &y,
            ours(Function::Acosh, &ours(Function::Cosh, &z)) - &z,
            ours(Function::Atanh, &ours(Function::Tanh, &x)) - &x,
            // atan inside asin: asin(x/√(1 + x²)) = atan x.
            ours(
                Function::Asin,
                &(&x / (&one + x.pow(Atom::num(2))).pow(half.clone())),
            ) - ours(Function::Atan, &x),
        ];
        for a in &identities {
            assert!(!nonzero(a), "{a}");
        }
        let not_zeros = [
            ours(Function::Atan, &x) - ours(Function::Asin, &y),
            ours(Function::Acos, &z) * &x - &y,
            ours(Function::Sinh, &ours(Function::Atan, &x)) - &z,
            ours(Function::Acosh, &(&one + &x)) + ours(Function::Atanh, &y) * &z,
            ours(Function::Tanh, &x) - ours(Function::Asinh, &y),
        ];
        for a in &not_zeros {
            assert!(nonzero(a), "{a}");
        }
    }
}
