//! Bounds on a model's size, so that validation and derivation take bounded
//! time and memory: each is refused with an error at the text that passes
//! it, never met as a hang.

use std::ops::Range;

use super::file::Dynamics;
use crate::diag::{Collector, ErrorKind};

/// Most definitions a model may have.
pub(super) const MAX_DEFINITIONS: usize = 1000;

/// Most parameters a model may have. Every program the derivation builds
/// takes them all as inputs, and its time grows about as the square of
/// their number: 2 000 unused parameters beside a falling point derive in
/// 0.55 s, 10 000 in 6.3 s and 0.23 GB, 100 000 ran past 180 s
/// (`dalembert derive`, 2026-12-05).
pub(super) const MAX_PARAMETERS: usize = 1000;

/// Largest size (in nodes) of a definition once the definitions it uses are
/// substituted.
pub(super) const MAX_EXPANDED_SIZE: u64 = 200_000;

/// Deepest nesting of an expression's tree once the definitions it uses
/// are substituted (four times the parser's limit for one expression's
/// text, [`super::expr::MAX_DEPTH`]): the derivation recurses through the
/// substituted tree, and 1000 definitions each dividing by the next
/// overflowed its stack.
pub(crate) const MAX_EXPANDED_DEPTH: u64 = 4 * super::expr::MAX_DEPTH as u64;

/// Most divisions nested inside one another in an expression, definitions
/// substituted. The derivation's cost grows about 1.7-fold with each level
/// of a continued fraction d₀ = 1/(1 + d₁), d₁ = 1/(1 + d₂), …: 10 levels
/// derived in 0.25 s, 14 in 0.73 s, 18 in 6.8 s and 31 ran past 120 s
/// (`dalembert derive`, 2026-12-04).
pub(crate) const MAX_NESTED_DIVISIONS: u64 = 12;

/// Most terms an expression may expand to as a polynomial (an upper bound:
/// see [`super::expr::Node::terms`]), definitions substituted. The largest
/// built-in model's are a few hundred. The derivation's time grows about as
/// the terms to the power 1.8: a wall (1 + x + y + z)^n - 2 of three free
/// coordinates derived in 0.58 s at n = 10 (286 terms), 6.4 s at 20 (1771),
/// 50 s at 30 (5456) and ran past 90 s at 40 (12 341); a six-coordinate
/// wall of 1716 terms in 7.2 s, a kinetic energy of 5313 in 22 s
/// (`dalembert derive`, 2026-12-05). At this limit a model derives in
/// seconds, well inside a minute.
pub(crate) const MAX_TERMS: u64 = 2_000;

/// How an expression expands as a polynomial, for the bounds on its size:
/// an upper bound on its terms (and on those of any part of it), and the
/// atoms it is a polynomial in (the names it reaches through definitions,
/// and its function applications and fractional powers).
#[derive(Clone, Debug, Default)]
pub(super) struct Expansion {
    /// The bound on the expression's own terms.
    pub terms: u64,
    /// The bound on the terms of the largest part of it (itself included).
    pub worst: u64,
    names: std::collections::BTreeSet<String>,
    applications: u64,
}

/// [`Expansion`] of `node` of polynomial degree at most `degree`, where
/// `defs` holds each definition's: the product-and-power bound of
/// [`Node::terms`](super::expr::Node::terms), capped by the number of
/// monomials of that degree in its v atoms, C(degree + v, v) (a power of a
/// sum of one variable has few terms however large the power).
pub(super) fn expansion(
    node: &super::expr::Node,
    degree: u64,
    defs: &std::collections::HashMap<&str, Expansion>,
) -> Expansion {
    let mut worst = 0;
    let terms = node.terms(&|n| defs.get(n).map_or(1, |e| e.terms), &mut worst);
    let mut names = std::collections::BTreeSet::new();
    node.visit_names(&mut |n, _| match defs.get(n) {
        Some(e) => names.extend(e.names.iter().cloned()),
        None => {
            names.insert(n.to_string());
        }
    });
    let applications = node.applications(&|n| defs.get(n).map_or(0, |e| e.applications));
    let atoms = (names.len() as u64).saturating_add(applications);
    let monomials = super::expr::multinomial(atoms.saturating_add(1), degree as u128);
    Expansion {
        terms: terms.min(monomials),
        worst: worst.min(monomials),
        names,
        applications,
    }
}

/// `n` in words for a message: a saturated count is "more than 10¹⁹".
pub(super) fn count(n: u64) -> String {
    if n == u64::MAX {
        "more than 10^19".into()
    } else {
        n.to_string()
    }
}

/// Most coordinates (or velocities of an instantaneous model). Derivation
/// grows about as the cube of their number: 64 coordinates with a diagonal
/// T take 1.6 s and 128 take 16 s (`dalembert derive`, 2026-11-23), and
/// 250 ran past a minute.
pub(super) const MAX_VARIABLES: usize = 100;

/// At most `limit` declarations of one kind (`count` of them, `what` they
/// are, and why there is a limit, if the message should say): false, with
/// an error at `first_past` (the first declaration past it), if there are
/// more.
pub(super) fn declarations(
    cx: &mut Collector,
    (count, limit): (usize, usize),
    what: &str,
    why: &str,
    first_past: Option<Range<usize>>,
) -> bool {
    if count <= limit {
        return true;
    }
    cx.error(
        ErrorKind::Limit(format!("{count} {what}; the limit is {limit}{why}")),
        first_past,
    );
    false
}

/// At most [`MAX_VARIABLES`] coordinates or velocities.
pub(super) fn variable_count(cx: &mut Collector, n: usize, span: Range<usize>) {
    if n > MAX_VARIABLES {
        cx.error(
            ErrorKind::Limit(format!(
                "{n} variables; the limit is {MAX_VARIABLES} (derivation time grows about as the cube of their number)"
            )),
            Some(span),
        );
    }
}

/// At most N constraint rows (holonomic and velocity ones): A has N
/// columns, so more cannot be independent.
pub(super) fn constraint_count(cx: &mut Collector, dynamics: &Dynamics, velocities: usize) {
    let rows = dynamics.holonomic.len() + dynamics.constraints.len();
    if rows <= velocities {
        return;
    }
    let extra = dynamics
        .holonomic
        .iter()
        .chain(&dynamics.constraints)
        .nth(velocities)
        .map(|c| c.span());
    cx.error(
        ErrorKind::Structure(format!(
            "{rows} constraint rows (holonomic and velocity constraints together) for {velocities} velocities: at most {velocities} can be independent; remove the dependent ones"
        )),
        extra,
    );
}
