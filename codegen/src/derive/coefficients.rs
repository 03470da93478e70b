//! Pass 5a: parameter-only coefficients named before evaluation.
//!
//! The exact passes leave polynomials expanded: an entry of the chain's G is
//! `l1*m2*l2*sin(q1)*sin(q2) + l1*m2*l2*cos(q1)*cos(q2) + l1*l2*m3*sin(q1)*sin(q2) + …`.
//! Handed to the evaluator as it is, every parameter is one more variable
//! of its Horner scheme, and the per-call code multiplies masses and lengths
//! term by term. Here every sum is regrouped by the part of each term that
//! depends on the coordinates or velocities, and the parameter-only factor
//! of each group (`l1*l2*(m2 + m3)`) becomes one new symbol. Equal
//! coefficients, or opposite ones, share one symbol, and terms whose
//! coefficient is one symbol share it as a factor (the evaluator does not
//! always find that factor itself): the same entry reads
//! `k0*(sin(q1)*sin(q2) + cos(q1)*cos(q2))`, three multiplications and an
//! addition per call. chain_8's G took 173 multiplications and 85 additions
//! per call expanded, and takes 84 and 28 so. The named coefficients are a
//! program of their own over the parameters (done once per parameter set,
//! see [`crate::program::Split`]), which the per-call program reads as
//! inputs.

use symbolica::prelude::*;

/// The outputs rewritten over named coefficients, and what each name stands
/// for (an expression in the parameters alone).
pub struct Named {
    /// The outputs, each equal to the original one with every symbol
    /// replaced by its coefficient.
    pub outputs: Vec<Atom>,
    /// The symbols given to coefficients, in order.
    pub symbols: Vec<Symbol>,
    /// Their expressions.
    pub coefficients: Vec<Atom>,
}

/// Names the parameter-only coefficients of `outputs`, whose varying symbols
/// (coordinates and velocities) are `varying`; coefficient `k` is named
/// `symbol(k)`.
pub fn name(outputs: &[Atom], varying: &[Symbol], symbol: impl Fn(usize) -> Symbol) -> Named {
    let mut n = Namer {
        varying,
        symbol: &symbol,
        named: Named {
            outputs: Vec::new(),
            symbols: Vec::new(),
            coefficients: Vec::new(),
        },
    };
    let outputs = outputs.iter().map(|a| n.visit(a.as_view())).collect();
    n.named.outputs = outputs;
    n.named
}

struct Namer<'a> {
    varying: &'a [Symbol],
    symbol: &'a dyn Fn(usize) -> Symbol,
    named: Named,
}

impl Namer<'_> {
    /// Whether `a` depends on the parameters and constants alone.
    fn fixed(&self, a: AtomView) -> bool {
        match a {
            AtomView::Num(_) => true,
            AtomView::Var(v) => !self.varying.contains(&v.get_symbol()),
            AtomView::Fun(f) => f.iter().all(|x| self.fixed(x)),
            AtomView::Pow(p) => {
                let (b, e) = p.get_base_exp();
                self.fixed(b) && self.fixed(e)
            }
            AtomView::Mul(m) => m.iter().all(|x| self.fixed(x)),
            AtomView::Add(s) => s.iter().all(|x| self.fixed(x)),
        }
    }

    /// `a` with the coefficients of its sums and products named.
    fn visit(&mut self, a: AtomView) -> Atom {
        match a {
            AtomView::Add(s) => {
                // (varying part, sum of the fixed factors of its terms)
                let mut groups: Vec<(Atom, Atom)> = Vec::new();
                for t in s.iter() {
                    let (fixed, varying) = self.split(t);
                    match groups.iter_mut().find(|(v, _)| *v == varying) {
                        Some((_, c)) => *c = &*c + &fixed,
                        None => groups.push((varying, fixed)),
                    }
                }
                // Terms whose coefficients are one symbol, up to sign, share
                // it as a factor: k·x − k·y is k·(x − y).
                let mut factored: Vec<(Atom, Atom)> = Vec::new();
                let mut sum = Atom::num(0);
                for (varying, fixed) in groups {
                    let c = self.coefficient(fixed);
                    let (sign, base) = if matches!(c.as_view(), AtomView::Var(_)) {
                        (Atom::num(1), c)
                    } else if matches!((-&c).as_view(), AtomView::Var(_)) {
                        (Atom::num(-1), -c)
                    } else {
                        sum += c * varying;
                        continue;
                    };
                    match factored.iter_mut().find(|(k, _)| *k == base) {
                        Some((_, rest)) => *rest = &*rest + sign * varying,
                        None => factored.push((base, sign * varying)),
                    }
                }
                for (k, rest) in factored {
                    sum += k * rest;
                }
                sum
            }
            AtomView::Mul(_) => {
                let (fixed, varying) = self.split(a);
                self.coefficient(fixed) * varying
            }
            AtomView::Pow(p) => {
                let (b, e) = p.get_base_exp();
                self.visit(b).pow(e.to_owned())
            }
            AtomView::Fun(f) if f.get_nargs() == 1 => match f.iter().next() {
                Some(x) => function!(f.get_symbol(), self.visit(x)),
                None => a.to_owned(),
            },
            _ => a.to_owned(),
        }
    }

    /// A term as its parameter-only factor and the rest (visited).
    fn split(&mut self, t: AtomView) -> (Atom, Atom) {
        if self.fixed(t) {
            return (t.to_owned(), Atom::num(1));
        }
        let AtomView::Mul(m) = t else {
            return (Atom::num(1), self.visit(t));
        };
        let (mut fixed, mut varying) = (Atom::num(1), Atom::num(1));
        for x in m.iter() {
            if self.fixed(x) {
                fixed *= x.to_owned();
            } else {
                varying *= self.visit(x);
            }
        }
        (fixed, varying)
    }

    /// A symbol for the parameter-only `c`, or `c` itself where it is a
    /// number or a single symbol (nothing to compute).
    fn coefficient(&mut self, c: Atom) -> Atom {
        let c = c.expand();
        if matches!(c.as_view(), AtomView::Num(_) | AtomView::Var(_)) {
            return c;
        }
        let named = &mut self.named;
        if let Some(k) = named.coefficients.iter().position(|x| *x == c) {
            return Atom::from(named.symbols[k]);
        }
        let minus = (-&c).expand();
        if let Some(k) = named.coefficients.iter().position(|x| *x == minus) {
            return -Atom::from(named.symbols[k]);
        }
        let s = (self.symbol)(named.symbols.len());
        named.symbols.push(s);
        named.coefficients.push(c);
        Atom::from(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::derive::build::{Namespace, own_symbol};

    /// The chain's G entry: two groups with one coefficient, l1 l2 (m2 + m3),
    /// and the same value as before.
    #[test]
    fn groups_terms_by_their_varying_part() {
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("coefficients test");
        let s = |n: &str| own_symbol(n);
        let (l1, l2, m2, m3, q1, q2) = (s("l1"), s("l2"), s("m2"), s("m3"), s("q1"), s("q2"));
        let [l1, l2, m2, m3, x1, x2] = [l1, l2, m2, m3, q1, q2].map(Atom::from);
        let (s1, c1) = (
            function!(Symbol::SIN, x1.clone()),
            function!(Symbol::COS, x1),
        );
        let (s2, c2) = (
            function!(Symbol::SIN, x2.clone()),
            function!(Symbol::COS, x2),
        );
        let g = (&l1 * &m2 * &l2 * &s1 * &s2 + &l1 * &m2 * &l2 * &c1 * &c2
            + &l1 * &l2 * &m3 * &s1 * &s2
            + &l1 * &l2 * &m3 * &c1 * &c2)
            // and the opposite coefficient on another term
            - &l1 * &l2 * &m2 * &s2
            - &l1 * &l2 * &m3 * &s2;
        let named = name(std::slice::from_ref(&g), &[q1, q2], |k| {
            own_symbol(&format!("k__{k}"))
        });
        assert_eq!(named.symbols.len(), 1, "{:?}", named.outputs[0]);
        let k = Atom::from(named.symbols[0]);
        let want = (&l1 * &l2 * (&m2 + &m3)).expand();
        assert_eq!(named.coefficients[0], want);
        let back = named.outputs[0].replace(k).with(want).expand();
        assert_eq!(back, g.expand());
    }
}
