//! Which histories a series function sums two at a time.
//!
//! At order k every convolution sums its history, Σⱼ₌₁..ₖ₋₁ aⱼ bₖ₋ⱼ, in
//! one loop over j. Two products aⱼ·bᵣ and cⱼ·dᵣ are summed as one
//! `taylor::Pair` when their operands are kept side by side, aⱼ beside cⱼ
//! and bᵣ beside dᵣ: arrays of pairs (`l{id}`, *lanes*) in the caller's
//! `SeriesScratch`, each written once per order after the operations that
//! give its coefficients. Per j a pair then costs two loads, a vector
//! product and a vector sum, where two scalar histories cost up to four
//! loads, two products and two sums (and the compiler's own pairing of
//! scalar sums, shuffles to gather the operands).
//!
//! The plan is a function of the transform alone, so `SeriesScratch`'s
//! size and the function's statements agree. Products are paired first
//! among those with the same right operand (so that two pairs with the
//! same operands share their lanes), then in program order; a power's
//! history (a weighted product) and an odd one out stay single. Pairing
//! changes no bits: each lane is its history's own sum, in the same order.

use std::ops::Range;

use crate::program::{Op, Series, Solve, Transform};

/// An operand of a history: a series, or the weighted series j·aⱼ that
/// op `index` keeps (`w{index}`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Operand {
    Series(Series),
    Weight(usize),
}

/// One history's term at j (with r = k − j).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum History {
    /// `left[j] * right[r]`.
    Product { left: Operand, right: Operand },
    /// `power_weight(alpha, r, j) * a[r] * dst[j]`.
    Power { alpha: f64, a: Series, dst: Series },
}

/// The histories of op `index` (of `t.ops`), in the order its finish
/// reads them.
fn of_op(op: &Op, index: usize) -> Vec<History> {
    use Operand::{Series as S, Weight as W};
    let product = |left, right| History::Product { left, right };
    match *op {
        Op::Mul { a, b, .. } => vec![product(S(a), S(b))],
        Op::Square { a, .. } => vec![product(S(a), S(a))],
        Op::Recip { dst, a } => vec![product(S(a), S(dst))],
        Op::Div { dst, b, .. } => vec![product(S(b), S(dst))],
        Op::Sqrt { dst, .. } => vec![product(S(dst), S(dst))],
        Op::Power { dst, a, alpha } => vec![History::Power { alpha, a, dst }],
        Op::Exp { dst, .. } => vec![product(W(index), S(dst))],
        Op::Log { a, .. } => vec![product(W(index), S(a))],
        Op::Arc { w, .. } => vec![product(W(index), S(w))],
        Op::SinCos { sin, cos, .. } => {
            vec![product(W(index), S(cos)), product(W(index), S(sin))]
        }
        Op::Add { .. } | Op::Scale { .. } => Vec::new(),
    }
}

/// The solve's histories, Σ Gⱼ xₖ₋ⱼ for every entry of G that varies, in
/// row order.
fn of_solve(solve: &Solve) -> Vec<History> {
    solve
        .varying()
        .map(|(_, m, g, _)| History::Product {
            left: Operand::Series(g),
            right: Operand::Series(solve.x[m]),
        })
        .collect()
}

/// A group's histories: its ops' in program order, then its solve's.
fn of_group(t: &Transform, group: &Group) -> Vec<History> {
    let ops = t.ops[group.ops.clone()]
        .iter()
        .enumerate()
        .flat_map(|(i, op)| of_op(op, group.ops.start + i));
    ops.chain(group.solve(t).into_iter().flat_map(of_solve))
        .collect()
}

/// The ops a function runs at each order in one stretch (its history loops,
/// then their finishes), and whether the transform's solve follows them.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Group {
    pub ops: Range<usize>,
    pub solve: bool,
}

impl Group {
    /// The transform's solve, if this group runs it.
    pub fn solve<'a>(&self, t: &'a Transform) -> Option<&'a Solve> {
        t.solve.as_ref().filter(|_| self.solve)
    }
}

/// A transform's groups, in the order its function runs them: with the
/// momentum's solve, the ops that read coordinates and the solve, then the
/// rest; for the variational system, the ops shared by every column, then
/// the rest; otherwise all ops (and the solve of G q̈ = −h, if any).
fn groups(t: &Transform) -> Vec<Group> {
    if let Some(shared) = t.shared {
        let group = |ops| Group { ops, solve: false };
        return vec![group(0..shared), group(shared..t.ops.len())];
    }
    match &t.solve {
        Some(solve) if solve.momentum => vec![
            Group {
                ops: 0..solve.split,
                solve: true,
            },
            Group {
                ops: solve.split..t.ops.len(),
                solve: false,
            },
        ],
        solve => vec![Group {
            ops: 0..t.ops.len(),
            solve: solve.is_some(),
        }],
    }
}

/// Two histories (indices into the group's list) summed as one pair, from
/// lanes `left` (their left operands) and `right`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Paired {
    pub first: usize,
    pub second: usize,
    pub left: usize,
    pub right: usize,
}

/// One group's part of the plan.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct GroupPlan {
    /// The group's ops and whether it runs the solve.
    pub group: Group,
    /// Its histories ([`of_group`]), in the order the finishes read them.
    pub histories: Vec<History>,
    /// The pairs, in the order their accumulators are declared.
    pub pairs: Vec<Paired>,
    /// The histories summed alone.
    pub single: Vec<usize>,
    /// The lanes this group writes (their first use): id and operands.
    pub stores: Vec<(usize, (Operand, Operand))>,
}

/// A transform's plan: each group's, in the order its function runs them
/// ([`groups`]), and how many lanes it uses.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Plan {
    pub groups: Vec<GroupPlan>,
    pub lanes: usize,
}

/// The plan of `t`'s function, its groups as [`groups`] gives them.
pub(super) fn plan(t: &Transform) -> Plan {
    let mut lanes = Vec::new();
    let groups = groups(t)
        .into_iter()
        .map(|group| {
            let histories = of_group(t, &group);
            let mut plan = assign(&histories, &mut lanes);
            plan.group = group;
            plan.histories = histories;
            plan
        })
        .collect();
    Plan {
        groups,
        lanes: lanes.len(),
    }
}

/// One group's pairs and single histories, its pairs' lanes taken from
/// `lanes` (the lanes of the function's earlier groups) or added to it.
fn assign(histories: &[History], lanes: &mut Vec<(Operand, Operand)>) -> GroupPlan {
    let mut plan = GroupPlan::default();
    for (first, second) in matches(histories, &mut plan.single) {
        let (a, b) = (operands(&histories[first]), operands(&histories[second]));
        let mut lane = |key: (Operand, Operand)| match lanes.iter().position(|l| *l == key) {
            Some(id) => id,
            None => {
                lanes.push(key);
                plan.stores.push((lanes.len() - 1, key));
                lanes.len() - 1
            }
        };
        let (left, right) = (lane((a.0, b.0)), lane((a.1, b.1)));
        plan.pairs.push(Paired {
            first,
            second,
            left,
            right,
        });
    }
    plan
}

/// A product's (left, right) operands.
fn operands(h: &History) -> (Operand, Operand) {
    match *h {
        History::Product { left, right } => (left, right),
        History::Power { .. } => unreachable!("powers are never paired"),
    }
}

/// The pairs of products to sum together: those with the same right
/// operand first, in order of its first appearance, then the rest in
/// program order. What is left alone goes to `single`, in order.
fn matches(histories: &[History], single: &mut Vec<usize>) -> Vec<(usize, usize)> {
    let mut by_right: Vec<(Operand, Vec<usize>)> = Vec::new();
    for (i, h) in histories.iter().enumerate() {
        match *h {
            History::Product { right, .. } => {
                match by_right.iter_mut().find(|(r, _)| *r == right) {
                    Some((_, list)) => list.push(i),
                    None => by_right.push((right, vec![i])),
                }
            }
            History::Power { .. } => single.push(i),
        }
    }
    let mut pairs = Vec::new();
    let mut rest = Vec::new();
    for (_, list) in by_right {
        pair_up(&list, &mut pairs, &mut rest);
    }
    rest.sort_unstable();
    pair_up(&rest, &mut pairs, single);
    single.sort_unstable();
    pairs
}

/// `list` two by two into `pairs`, an odd one out into `left`.
fn pair_up(list: &[usize], pairs: &mut Vec<(usize, usize)>, left: &mut Vec<usize>) {
    for two in list.chunks(2) {
        match *two {
            [a, b] => pairs.push((a, b)),
            [a] => left.push(a),
            _ => unreachable!("chunks of two"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Operand::Series as S;

    fn product(left: Series, right: Series) -> History {
        History::Product {
            left: S(left),
            right: S(right),
        }
    }

    /// Products that share a right operand pair up first; the odd one out
    /// and powers stay single; every history is summed exactly once.
    #[test]
    fn pairs_by_right_operand_then_in_order() {
        let (a, b, c, d) = (Series::Temp(0), Series::Temp(1), Series::V(0), Series::Q(1));
        let histories = [
            product(a, b),
            product(c, d),
            History::Power {
                alpha: 0.5,
                a,
                dst: c,
            },
            product(c, b),
            product(a, a),
            product(d, c),
        ];
        let mut single = Vec::new();
        let pairs = matches(&histories, &mut single);
        assert_eq!(pairs, [(0, 3), (1, 4)]);
        assert_eq!(single, [2, 5]);
    }

    /// Two pairs with the same operands share their lanes, each stored
    /// once, by the group that reads it first.
    #[test]
    fn lanes_are_shared() {
        let (a, b, c, d) = (Series::Temp(0), Series::Temp(1), Series::V(0), Series::Q(1));
        let mut lanes = Vec::new();
        let first = assign(
            &[product(a, b), product(c, b), product(a, d), product(c, d)],
            &mut lanes,
        );
        // (a, c) on the left of both pairs; (b, b) and (d, d) on the right.
        assert_eq!(lanes, [(S(a), S(c)), (S(b), S(b)), (S(d), S(d))]);
        let ids: Vec<_> = first.pairs.iter().map(|p| (p.left, p.right)).collect();
        assert_eq!(ids, [(0, 1), (0, 2)]);
        assert_eq!(first.stores.len(), 3);
        assert!(first.single.is_empty());
        // A later group reads (a, c) and (b, b) again and stores nothing.
        let second = assign(&[product(a, b), product(c, b)], &mut lanes);
        assert_eq!(second.pairs[0].left, 0);
        assert_eq!(second.pairs[0].right, 1);
        assert!(second.stores.is_empty());
    }
}
