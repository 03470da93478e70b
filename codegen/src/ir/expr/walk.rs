//! Walks over an expression tree: its names, value, size and degree.

use std::ops::Range;

use super::{Function, Node, NodeKind};

impl Node {
    /// Calls `f` on every name in the tree, with its span.
    pub fn visit_names(&self, f: &mut dyn FnMut(&str, &Range<usize>)) {
        match &self.kind {
            NodeKind::Name(n) => f(n, &self.span),
            NodeKind::Number(_) | NodeKind::Constant(_) => {}
            NodeKind::Sum(items) | NodeKind::Product(items) => {
                for (_, x) in items {
                    x.visit_names(f);
                }
            }
            NodeKind::Neg(x) | NodeKind::Pow(x, _) | NodeKind::Call(_, x) => x.visit_names(f),
        }
    }

    /// Its value in f64, each name's from `lookup` (`None` when a name has
    /// none).
    pub fn value(&self, lookup: &dyn Fn(&str) -> Option<f64>) -> Option<f64> {
        Some(match &self.kind {
            NodeKind::Number(r) => r.to_f64(),
            NodeKind::Name(n) => lookup(n)?,
            NodeKind::Constant(c) => c.value(),
            NodeKind::Neg(x) => -x.value(lookup)?,
            NodeKind::Sum(items) => items.iter().try_fold(0.0, |acc, (minus, x)| {
                let v = x.value(lookup)?;
                Some(if *minus { acc - v } else { acc + v })
            })?,
            NodeKind::Product(items) => items.iter().try_fold(1.0, |acc, (divide, x)| {
                let v = x.value(lookup)?;
                Some(if *divide { acc / v } else { acc * v })
            })?,
            NodeKind::Pow(x, n) => x.value(lookup)?.powf(n.to_f64()),
            NodeKind::Call(f, x) => f.value(x.value(lookup)?),
        })
    }

    /// Number of nodes, each name counting as `size(name)` (so that a
    /// definition counts as large as what it stands for). Saturating.
    pub fn size(&self, size: &dyn Fn(&str) -> u64) -> u64 {
        match &self.kind {
            NodeKind::Name(n) => size(n),
            NodeKind::Number(_) | NodeKind::Constant(_) => 1,
            NodeKind::Sum(items) | NodeKind::Product(items) => items
                .iter()
                .fold(1u64, |acc, (_, x)| acc.saturating_add(x.size(size))),
            NodeKind::Neg(x) | NodeKind::Pow(x, _) | NodeKind::Call(_, x) => {
                x.size(size).saturating_add(1)
            }
        }
    }

    /// Nesting depth, each name counting as `depth(name)` (so that a
    /// definition counts as deep as what it stands for). Saturating.
    pub fn depth(&self, depth: &dyn Fn(&str) -> u64) -> u64 {
        match &self.kind {
            NodeKind::Name(n) => depth(n),
            NodeKind::Number(_) | NodeKind::Constant(_) => 1,
            NodeKind::Sum(items) | NodeKind::Product(items) => items
                .iter()
                .map(|(_, x)| x.depth(depth))
                .max()
                .unwrap_or(0)
                .saturating_add(1),
            NodeKind::Neg(x) | NodeKind::Pow(x, _) | NodeKind::Call(_, x) => {
                x.depth(depth).saturating_add(1)
            }
        }
    }

    /// An upper bound on the number of terms of the tree expanded as a
    /// polynomial, each name counting as `terms(name)`: a sum adds, a
    /// product multiplies, a whole power n of t terms has at most
    /// C(n + t − 1, t − 1) (the multinomial's), and a function application
    /// or a fractional power is one term. `worst` is raised to the largest
    /// such bound met anywhere in the tree (a function's argument is
    /// expanded too). Saturating.
    pub fn terms(&self, terms: &dyn Fn(&str) -> u64, worst: &mut u64) -> u64 {
        let own = match &self.kind {
            NodeKind::Name(n) => terms(n),
            NodeKind::Number(_) | NodeKind::Constant(_) => 1,
            NodeKind::Sum(items) => items.iter().fold(0u64, |acc, (_, x)| {
                acc.saturating_add(x.terms(terms, worst))
            }),
            NodeKind::Product(items) => items.iter().fold(1u64, |acc, (_, x)| {
                acc.saturating_mul(x.terms(terms, worst))
            }),
            NodeKind::Neg(x) => x.terms(terms, worst),
            NodeKind::Pow(x, n) if n.den == 1 => {
                multinomial(x.terms(terms, worst), n.num.unsigned_abs())
            }
            NodeKind::Pow(x, _) | NodeKind::Call(_, x) => {
                x.terms(terms, worst);
                1
            }
        };
        *worst = (*worst).max(own);
        own
    }

    /// The most divisions nested inside one another along a path of the
    /// tree (a divisor or a negative power counts one), each name counting
    /// as `nested(name)`. Saturating.
    pub fn nested_divisions(&self, nested: &dyn Fn(&str) -> u64) -> u64 {
        match &self.kind {
            NodeKind::Name(n) => nested(n),
            NodeKind::Number(_) | NodeKind::Constant(_) => 0,
            NodeKind::Sum(items) | NodeKind::Product(items) => items
                .iter()
                .map(|(divide, x)| {
                    x.nested_divisions(nested)
                        .saturating_add(u64::from(*divide))
                })
                .max()
                .unwrap_or(0),
            NodeKind::Pow(x, n) if n.num < 0 => x.nested_divisions(nested).saturating_add(1),
            NodeKind::Neg(x) | NodeKind::Pow(x, _) | NodeKind::Call(_, x) => {
                x.nested_divisions(nested)
            }
        }
    }

    /// Function applications and fractional powers in the tree, each name
    /// counting as `count(name)`: the atoms of its expansion besides the
    /// names. Saturating.
    pub fn applications(&self, count: &dyn Fn(&str) -> u64) -> u64 {
        match &self.kind {
            NodeKind::Name(n) => count(n),
            NodeKind::Number(_) | NodeKind::Constant(_) => 0,
            NodeKind::Sum(items) | NodeKind::Product(items) => {
                items.iter().fold(0u64, |acc, (_, x)| {
                    acc.saturating_add(x.applications(count))
                })
            }
            NodeKind::Neg(x) => x.applications(count),
            NodeKind::Pow(x, n) if n.den == 1 => x.applications(count),
            NodeKind::Pow(x, _) | NodeKind::Call(_, x) => x.applications(count).saturating_add(1),
        }
    }

    /// The largest |numerator| or denominator of a number in the tree (at
    /// least 1; a denominator counts too, so that exp(x/0.00001) is bounded
    /// as exp(100000·x) is).
    fn largest_number(&self) -> u64 {
        match &self.kind {
            NodeKind::Number(r) => {
                let size = r.num.unsigned_abs().max(r.den.unsigned_abs());
                size.clamp(1, u64::MAX as u128) as u64
            }
            NodeKind::Name(_) | NodeKind::Constant(_) => 1,
            NodeKind::Sum(items) | NodeKind::Product(items) => items
                .iter()
                .map(|(_, x)| x.largest_number())
                .max()
                .unwrap_or(1),
            NodeKind::Neg(x) | NodeKind::Pow(x, _) | NodeKind::Call(_, x) => x.largest_number(),
        }
    }

    /// An upper bound on the polynomial degree, each name of degree
    /// `degree(name)` (a function application counts as a new variable of
    /// the degree of its argument; exp(k·x) as the k-th power of one, as
    /// the symbolic engine's exact arithmetic takes it). Saturating.
    pub fn degree(&self, degree: &dyn Fn(&str) -> u64) -> u64 {
        match &self.kind {
            NodeKind::Name(n) => degree(n),
            NodeKind::Number(_) | NodeKind::Constant(_) => 0,
            NodeKind::Sum(items) => items
                .iter()
                .map(|(_, x)| x.degree(degree))
                .max()
                .unwrap_or(0),
            NodeKind::Product(items) => items
                .iter()
                .fold(0u64, |acc, (_, x)| acc.saturating_add(x.degree(degree))),
            NodeKind::Neg(x) => x.degree(degree),
            // Exact arithmetic takes exp(k·x) for exp(x)^k: k multiplies.
            // (exp of a constant is a constant, as any function's is.)
            NodeKind::Call(Function::Exp, x) => match x.degree(degree) {
                0 => 1,
                d => d.saturating_mul(x.largest_number()),
            },
            NodeKind::Call(_, x) => x.degree(degree).max(1),
            NodeKind::Pow(x, n) => x
                .degree(degree)
                .saturating_mul(n.num.unsigned_abs().min(u64::MAX as u128) as u64),
        }
    }

    /// The degree as written in the names with a positive `degree(name)`,
    /// the others taken as constants, for a tree that is a polynomial in
    /// those names ([`Node::non_polynomial`] finds nothing): a divisor, a
    /// function's argument or the base of a fractional or negative power is
    /// then free of them and counts 0. An upper bound (terms that cancel
    /// count). Saturating.
    pub fn degree_in(&self, degree: &dyn Fn(&str) -> u64) -> u64 {
        match &self.kind {
            NodeKind::Name(n) => degree(n),
            NodeKind::Number(_) | NodeKind::Constant(_) | NodeKind::Call(..) => 0,
            NodeKind::Sum(items) => items
                .iter()
                .map(|(_, x)| x.degree_in(degree))
                .max()
                .unwrap_or(0),
            NodeKind::Product(items) => items
                .iter()
                .filter(|(divide, _)| !divide)
                .fold(0u64, |acc, (_, x)| acc.saturating_add(x.degree_in(degree))),
            NodeKind::Neg(x) => x.degree_in(degree),
            NodeKind::Pow(x, n) if n.den == 1 && n.num >= 0 => x
                .degree_in(degree)
                .saturating_mul(n.num.unsigned_abs().min(u64::MAX as u128) as u64),
            NodeKind::Pow(..) => 0,
        }
    }

    /// Whether a name for which `varies` holds occurs in the tree.
    pub fn depends(&self, varies: &dyn Fn(&str) -> bool) -> bool {
        self.first_name(varies).is_some()
    }

    /// The first name in the tree for which `varies` holds.
    fn first_name(&self, varies: &dyn Fn(&str) -> bool) -> Option<String> {
        let mut name = None;
        self.visit_names(&mut |n, _| {
            if name.is_none() && varies(n) {
                name = Some(n.to_string());
            }
        });
        name
    }

    /// The first place where a name for which `varies` holds occurs other
    /// than in sums, products and powers with whole non-negative exponents:
    /// inside a function, in a divisor, or in the base of a fractional or
    /// negative power. Returns that node's span, the name and the place in
    /// words; `None` where the tree is a polynomial in those names.
    pub fn non_polynomial(
        &self,
        varies: &dyn Fn(&str) -> bool,
    ) -> Option<(Range<usize>, String, String)> {
        let first = |x: &Node| x.first_name(varies);
        match &self.kind {
            NodeKind::Name(_) | NodeKind::Number(_) | NodeKind::Constant(_) => None,
            NodeKind::Sum(items) => items.iter().find_map(|(_, x)| x.non_polynomial(varies)),
            NodeKind::Product(items) => items.iter().find_map(|(divide, x)| match first(x) {
                Some(name) if *divide => Some((x.span.clone(), name, "in a divisor".into())),
                _ => x.non_polynomial(varies),
            }),
            NodeKind::Neg(x) => x.non_polynomial(varies),
            NodeKind::Pow(x, n) => match first(x) {
                Some(name) if n.den != 1 || n.num < 0 => {
                    Some((self.span.clone(), name, format!("raised to the power {n}")))
                }
                _ => x.non_polynomial(varies),
            },
            NodeKind::Call(f, x) => {
                first(x).map(|name| (self.span.clone(), name, format!("inside {}(…)", f.name())))
            }
        }
    }
}

/// C(n + t − 1, t − 1): the number of monomials of degree n in t variables
/// (the terms of a sum of t terms raised to the power n), saturating at
/// u64::MAX.
pub(crate) fn multinomial(t: u64, n: u128) -> u64 {
    if t <= 1 || n == 0 {
        return 1;
    }
    // C(n + k, k) with k = min(t − 1, n), built as a product of fractions
    // each of which leaves an integer.
    let n = n.min(u64::MAX as u128) as u64;
    let k = (t - 1).min(n);
    let m = (t - 1).max(n);
    let mut c: u128 = 1;
    for i in 1..=k as u128 {
        c = match c.checked_mul(m as u128 + i) {
            Some(x) if x / i <= u64::MAX as u128 => x / i,
            _ => return u64::MAX,
        };
    }
    c as u64
}

#[cfg(test)]
mod tests {
    use super::super::parse;
    use super::multinomial;

    #[test]
    fn monomials_of_a_power_of_a_sum() {
        assert_eq!(multinomial(1, 100), 1);
        assert_eq!(multinomial(5, 0), 1);
        assert_eq!(multinomial(2, 3), 4);
        // (x+y+z+u+w)^100: C(104, 4).
        assert_eq!(multinomial(5, 100), 4_598_126);
        assert_eq!(multinomial(100, 5), multinomial(6, 99));
        assert_eq!(multinomial(1000, 1000), u64::MAX);
        assert_eq!(multinomial(u64::MAX, u128::MAX), u64::MAX);
    }

    #[test]
    fn terms_and_depth_count_through_names() {
        let terms = |text: &str| {
            let mut worst = 0;
            let own = parse(text)
                .unwrap()
                .terms(&|n| if n == "d" { 10 } else { 1 }, &mut worst);
            (own, worst)
        };
        assert_eq!(terms("(x + y + z + u + w)^100"), (4_598_126, 4_598_126));
        assert_eq!(terms("(x + y)*(x - y)"), (4, 4));
        assert_eq!(terms("d^2"), (55, 55));
        // A function's argument is expanded on its own.
        assert_eq!(terms("sin((x + y)^3) + 1"), (2, 4));
        assert_eq!(terms("sqrt(x^2 + y^2)"), (1, 2));
        let nested = |text: &str| {
            parse(text)
                .unwrap()
                .nested_divisions(&|n| if n == "d" { 3 } else { 0 })
        };
        assert_eq!(nested("1/(1 + d)"), 4);
        assert_eq!(nested("x/y + 1/z"), 1);
        assert_eq!(nested("(1 + 1/x)^(-2)"), 2);
        assert_eq!(nested("sin(1/x)*d"), 3);
        let depth = parse("1/(1 + d)")
            .unwrap()
            .depth(&|n| if n == "d" { 7 } else { 1 });
        // Product → Sum → d (7 levels deep).
        assert_eq!(depth, 9);
    }
}
