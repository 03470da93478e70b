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

    /// An upper bound on the polynomial degree, each name of degree
    /// `degree(name)` (a function application counts as a new variable of
    /// the degree of its argument). Saturating.
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
            NodeKind::Call(_, x) => x.degree(degree).max(1),
            NodeKind::Pow(x, n) => x
                .degree(degree)
                .saturating_mul(n.num.unsigned_abs().min(u64::MAX as u128) as u64),
        }
    }
}
