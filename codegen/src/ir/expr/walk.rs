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
            NodeKind::Call(f, x) => {
                let v = x.value(lookup)?;
                match f {
                    Function::Sin => v.sin(),
                    Function::Cos => v.cos(),
                    Function::Tan => v.tan(),
                    Function::Exp => v.exp(),
                    Function::Log => v.ln(),
                    Function::Sqrt => v.sqrt(),
                }
            }
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
            NodeKind::Call(Function::Exp, x) => {
                x.degree(degree).max(1).saturating_mul(x.largest_number())
            }
            NodeKind::Call(_, x) => x.degree(degree).max(1),
            NodeKind::Pow(x, n) => x
                .degree(degree)
                .saturating_mul(n.num.unsigned_abs().min(u64::MAX as u128) as u64),
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
