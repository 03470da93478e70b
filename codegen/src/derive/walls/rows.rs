//! A wall's B: the candidate rows (the normal velocity, A's rows, the
//! contact rows), the independent ones kept exactly and whether they span
//! the dropped ones everywhere, the hypotheses (1.3) read off that choice
//! and checked at a point of the wall, and the forms the kept rows are
//! evaluated in.

use symbolica::prelude::*;

use super::super::budget::Over;
use super::super::checks::{self, WallRows};
use super::super::echelon::Echelon;
use super::super::lower::{self, Lowering};
use super::super::mechanics::RawWall;
use super::super::{Field, Rat, is_zero, rows_matrix};
use super::{Context, reduced, varies};
use crate::diag::{Collector, ErrorKind, Reported};
use crate::ir::{Kind, Wall};

/// A wall's B: its independent rows and where they came from.
pub(super) struct WallB {
    pub(super) matrix: Matrix<Field>,
    /// The rows as rational functions.
    pub(super) rats: Vec<Vec<Rat>>,
    /// The rows as expressions, functions raised.
    pub(super) atoms: Vec<Vec<Atom>>,
    /// The rows to evaluate ([`row_forms`]), the cheaper compiled.
    pub(super) forms: Vec<Vec<Vec<Atom>>>,
    pub(super) origin: Vec<String>,
    pub(super) dropped: Vec<String>,
    /// Whether the kept rows span the dropped ones everywhere ([`steady`]).
    pub(super) steady: bool,
}

/// B's candidate rows (the normal velocity, A's rows, the contact rows)
/// with the dependent ones removed, the hypotheses (1.3) checked for
/// generic q and at a point of the wall; `None` when no row is left (a
/// hypothesis check has then failed).
pub(super) fn of(
    c: &Context,
    cx: &mut Collector,
    w: &Wall,
    raw: &RawWall,
) -> Result<Option<WallB>, Reported> {
    let (sym, low, exact) = (c.sym, c.low, c.exact);
    let n = sym.vels.len();
    let normal_r: Vec<Rat> = (raw.normal.iter().map(|a| low.to_rat(a)))
        .collect::<Result<_, _>>()
        .map_err(|o| reduced(o, cx, w, "the normal"))?;
    let mut candidates = vec![(normal_r, "the normal velocity".to_string())];
    // Each candidate as written, to be evaluated where that is cheaper.
    let mut written = vec![raw.normal.clone()];
    for ((r, label), row) in exact.a.iter().zip(&c.raw.a_labels).zip(&c.raw.a_rows) {
        candidates.push((r.clone(), label.clone()));
        written.push(row.clone());
    }
    for (k, row) in raw.contact.iter().enumerate() {
        let r = (row.iter().map(|a| low.to_rat(a)))
            .collect::<Result<_, _>>()
            .map_err(|o| reduced(o, cx, w, "a contact row"))?;
        candidates.push((r, format!("contact constraint {}", k + 1)));
        written.push(row.clone());
    }
    let (kept_at, dropped_at) =
        independent_rows(&candidates, low).map_err(|o| reduced(o, cx, w, "the rows of B"))?;
    let (kept, dropped): (Vec<_>, Vec<_>) = (
        kept_at.iter().map(|&i| candidates[i].clone()).collect(),
        dropped_at.iter().map(|&i| candidates[i].clone()).collect(),
    );
    let b: Vec<Vec<Rat>> = kept.iter().map(|(r, _)| r.clone()).collect();
    let spans = steady(
        c,
        &b,
        &dropped.iter().map(|(r, _)| r.clone()).collect::<Vec<_>>(),
        n,
    )
    .map_err(|o| reduced(o, cx, w, "the rows of B"))?;
    let dropped: Vec<String> = dropped.into_iter().map(|(_, o)| o).collect();
    checks::wall_hypotheses(cx, w, &dropped_at, exact.a.len());
    if kept.is_empty() {
        return Ok(None);
    }
    let matrix = rows_matrix(&b, n, &exact.field).ok_or_else(|| {
        cx.error(
            ErrorKind::Symbolic(format!("wall `{}`: B as a matrix", w.name)),
            Some(w.span.clone()),
        )
    })?;
    let atoms: Vec<Vec<Atom>> = b
        .iter()
        .map(|r| r.iter().map(|x| low.raise(&x.to_expression())).collect())
        .collect();
    let written: Vec<Vec<Atom>> = kept_at.iter().map(|&i| written[i].clone()).collect();
    if sym.model.kind == Kind::Coordinates {
        // Evaluated only, so as written: the same functions as the reduced
        // rows, which can be far larger (a wall through nested atan).
        let rows = WallRows {
            surface: &raw.surface,
            normal: &raw.normal,
            holonomic: &c.raw.holonomic,
            a: &c.raw.a_rows,
            b: &written,
        };
        checks::on_wall(sym, cx, w, &rows);
    }
    let forms = row_forms(written, &atoms);
    Ok(Some(WallB {
        matrix,
        rats: b,
        atoms,
        forms,
        origin: kept.into_iter().map(|(_, o)| o).collect(),
        dropped,
        steady: spans,
    }))
}

/// B's kept rows to evaluate: as `written` where each entry is zero
/// exactly where the `reduced` row's is (the elimination places the
/// entries that are not zero, and a written entry that vanishes only by
/// sin² + cos² = 1 would be placed), then reduced, by
/// [`lower::worth_compiling`] (the reduced alone where the
/// zeros differ).
fn row_forms(written: Vec<Vec<Atom>>, reduced: &[Vec<Atom>]) -> Vec<Vec<Vec<Atom>>> {
    let same_zeros = (written.iter().flatten())
        .zip(reduced.iter().flatten())
        .all(|(w, r)| is_zero(w) == is_zero(r));
    if !same_zeros {
        return vec![reduced.to_vec()];
    }
    let keep = lower::worth_compiling(written.iter().flatten(), reduced.iter().flatten());
    std::iter::once(written)
        .chain(Some(reduced.to_vec()).filter(|_| keep))
        .collect()
}

/// Keeps each candidate row that raises the rank (exactly, the identities
/// holding: [`Echelon`]), in order; returns the kept rows and the dropped
/// ones, by their places among the candidates.
fn independent_rows(
    candidates: &[(Vec<Rat>, String)],
    low: &Lowering,
) -> Result<(Vec<usize>, Vec<usize>), Over> {
    let mut echelon = Echelon::new(low);
    let (mut kept, mut dropped) = (Vec::new(), Vec::new());
    for (k, (row, _)) in candidates.iter().enumerate() {
        if echelon.insert(row)? {
            kept.push(k);
        } else {
            dropped.push(k);
        }
    }
    Ok((kept, dropped))
}

/// Whether the kept rows span every dropped row with coefficients free of
/// q: λᵀ = d Kᵀ (K Kᵀ)⁻¹ for each dropped row d. Where a coefficient
/// varies, it has a pole somewhere, and there the kept rows may span less
/// than all the candidates do (three no-slip rows of a ball in a spherical
/// wall with the normal velocity: any three of the four degenerate on a
/// great circle of the wall). P itself is the same rational function for
/// any basis of the span, so the closed form stays right everywhere; what
/// evaluates B's kept rows at run time does not.
fn steady(c: &Context, kept: &[Vec<Rat>], dropped: &[Vec<Rat>], n: usize) -> Result<bool, Over> {
    if dropped.is_empty() {
        return Ok(true);
    }
    let field = &c.exact.field;
    let Some(k) = rows_matrix(kept, n, field) else {
        return Ok(false);
    };
    let Ok(inverse) = (&k * &k.transpose()).inv() else {
        return Ok(false);
    };
    for d in dropped {
        let Some(row) = rows_matrix(std::slice::from_ref(d), n, field) else {
            return Ok(false);
        };
        let lambda = &(&row * &k.transpose()) * &inverse;
        for i in 0..kept.len() {
            if varies(c, &c.low.simplify(&lambda[(0, i as u32)])?) {
                return Ok(false);
            }
        }
    }
    Ok(true)
}
