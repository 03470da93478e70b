//! Walking symbolica's expressions: what the passes that only look at an
//! expression (never rebuild it) share.

use symbolica::prelude::*;

/// The expressions `a` is made of, one level down: a function's
/// arguments, a sum's terms, a product's factors, a power's base and
/// exponent; none for a number or a symbol.
pub fn children(a: AtomView<'_>) -> Vec<AtomView<'_>> {
    match a {
        AtomView::Fun(f) => f.iter().collect(),
        AtomView::Add(s) => s.iter().collect(),
        AtomView::Mul(m) => m.iter().collect(),
        AtomView::Pow(p) => {
            let (b, e) = p.get_base_exp();
            vec![b, e]
        }
        AtomView::Var(_) | AtomView::Num(_) => Vec::new(),
    }
}

/// The one argument of an application.
pub fn argument(app: &Atom) -> Atom {
    match app.as_view() {
        AtomView::Fun(f) => f.iter().next().expect("one argument").to_owned(),
        _ => unreachable!("an application"),
    }
}

/// The number of expressions `a` is made of, itself included: the size of
/// its tree, each shared part counted where it occurs.
pub fn size(a: AtomView<'_>) -> usize {
    1 + children(a).into_iter().map(size).sum::<usize>()
}
