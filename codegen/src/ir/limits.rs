//! Bounds on a model's size, so that validation and derivation take bounded
//! time and memory: each is refused with an error at the text that passes
//! it, never met as a hang.

use std::ops::Range;

use super::file::Dynamics;
use crate::diag::{Collector, ErrorKind};

/// Most definitions a model may have.
pub(super) const MAX_DEFINITIONS: usize = 1000;

/// Largest size (in nodes) of a definition once the definitions it uses are
/// substituted.
pub(super) const MAX_EXPANDED_SIZE: u64 = 200_000;

/// Most coordinates (or velocities of an instantaneous model). Derivation
/// grows about as the cube of their number: 64 coordinates with a diagonal
/// T take 1.6 s and 128 take 16 s (`dalembert derive`, 2026-11-23), and
/// 250 ran past a minute.
pub(super) const MAX_VARIABLES: usize = 100;

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
