//! The model's checks, one function each. Every failed check records an
//! error at the offending text and the derivation goes on where it can, so
//! that one run reports everything it finds.
//!
//! | check | where it runs |
//! |---|---|
//! | [`kinetic_energy_quadratic`]: T = ½ vᵀG v | pass 2, on T |
//! | [`linear_row`]: a velocity-level constraint is linear and homogeneous in v | pass 2, on each constraint and contact row |
//! | [`no_velocity`]: V, h and f do not depend on v | pass 2 |
//! | [`positive_definite`]: G > 0 at the sample point (on h = 0), with a hint where G fails only across h = 0 | after the mass matrix's program |
//! | [`wall_hypotheses`]: (1.3) ker B ⊆ ker A (by construction) and ker A ⊄ TN, exactly | per wall, for generic q, from B's exact elimination |
//! | [`on_wall`]: B of full rank and (1.3) at a point of N (and h = 0) itself | per wall with a surface |

use std::ops::Range;

use symbolica::prelude::*;

use super::build::Differentiate;
use super::evaluate::program;
use super::mechanics::Raw;
use super::sample::onto;
use super::symbols::Symbols;
use super::{budget, is_zero};
use crate::diag::{Collector, ErrorKind, Reported};
use crate::ir::Wall;
use crate::program::Program;

/// T must equal ½ vᵀ G v: G's entries free of velocities, nothing of degree
/// 0 or 1 left over.
pub fn kinetic_energy_quadratic(sym: &Symbols, cx: &mut Collector, t: &Atom, g: &[Vec<Atom>]) {
    let span = sym.model.kinetic_energy.span.clone();
    for e in g.iter().flatten() {
        for (k, v) in sym.vels.iter().enumerate() {
            if !is_zero(&e.d(*v)) {
                cx.error(
                    ErrorKind::NotQuadratic(format!(
                        "its second derivatives still depend on `{}` (terms of degree > 2)",
                        sym.model.velocities[k]
                    )),
                    Some(span),
                );
                return;
            }
        }
    }
    let mut quad = Atom::num(0);
    for (i, vi) in sym.vels.iter().enumerate() {
        for (j, vj) in sym.vels.iter().enumerate() {
            quad += g[i][j].clone() * Atom::from(*vi) * Atom::from(*vj);
        }
    }
    let Ok(rest) = budget::expand(
        &(t.clone() - quad / Atom::num(2)),
        cx,
        &span,
        "the kinetic energy",
    ) else {
        return;
    };
    if !is_zero(&rest) {
        cx.error(
            ErrorKind::NotQuadratic(format!(
                "T − ½vᵀGv = {rest} (terms of degree 0 or 1 in the velocities)"
            )),
            Some(span),
        );
    }
}

/// The coefficient row of a velocity-level expression, which must be
/// linear and homogeneous in the velocities (`what` at `span` names it
/// when its expansion is past the budget).
pub fn linear_row(
    sym: &Symbols,
    cx: &mut Collector,
    e: &Atom,
    span: &Range<usize>,
    what: &str,
) -> Result<Vec<Atom>, Reported> {
    let mut row = Vec::with_capacity(sym.vels.len());
    let mut bound = budget::Running::default();
    for v in &sym.vels {
        let d = e.d(*v);
        bound.add(&d, cx, span, what)?;
        row.push(d.expand());
    }
    for c in &row {
        for (k, v) in sym.vels.iter().enumerate() {
            if !is_zero(&c.d(*v)) {
                return Err(cx.error(
                    ErrorKind::NotLinear(format!(
                        "its coefficients depend on the velocity `{}`",
                        sym.model.velocities[k]
                    )),
                    Some(span.clone()),
                ));
            }
        }
    }
    let mut lin = Atom::num(0);
    for (c, v) in row.iter().zip(&sym.vels) {
        lin += c.clone() * Atom::from(*v);
    }
    let rest = budget::expand(&(e.clone() - lin), cx, span, what)?;
    if !is_zero(&rest) {
        return Err(cx.error(
            ErrorKind::NotLinear(format!("it has a part free of the velocities: {rest}")),
            Some(span.clone()),
        ));
    }
    if row.iter().all(is_zero) {
        return Err(cx.error(
            ErrorKind::NotLinear("it does not involve any velocity".into()),
            Some(span.clone()),
        ));
    }
    Ok(row)
}

/// `e` must not depend on any velocity (`kind` names the first it does).
pub fn no_velocity(
    sym: &Symbols,
    cx: &mut Collector,
    e: &Atom,
    span: &Range<usize>,
    kind: impl Fn(String) -> ErrorKind,
) -> Result<(), Reported> {
    for (k, v) in sym.vels.iter().enumerate() {
        if !is_zero(&e.d(*v)) {
            return Err(cx.error(kind(sym.model.velocities[k].clone()), Some(span.clone())));
        }
    }
    Ok(())
}

/// G positive definite at the sample point (file's parameter values, the
/// sample configuration on h(q) = 0: [`super::sample::configuration`]):
/// symmetric, finite, and a Cholesky factorisation succeeds. Where G fails
/// only across the holonomic constraints (positive on ker dh), the message
/// says so and how to regularise T.
pub fn positive_definite(sym: &Symbols, raw: &Raw, cx: &mut Collector, mass_matrix: &Program) {
    let n = sym.vels.len();
    let inputs = sym.sample_inputs();
    let vals = mass_matrix.eval(&inputs);
    let gm = nalgebra::DMatrix::from_row_slice(n, n, &vals);
    let symmetric = (0..n).all(|i| {
        (0..n).all(|j| (gm[(i, j)] - gm[(j, i)]).abs() <= 1e-12 * (1.0 + gm[(i, j)].abs()))
    });
    if symmetric && vals.iter().all(|x| x.is_finite()) && gm.clone().cholesky().is_some() {
        return;
    }
    let hint = match positive_on_constraints(sym, raw, &gm, &inputs) {
        _ if !vals.iter().all(|x| x.is_finite()) => {
            "; it has no value there (an entry is NaN or infinite: a function of the coordinates outside its domain, as asin of a number past 1)".to_string()
        }
        Some(h) => format!(
            "; it is positive on the velocities the holonomic constraints allow but not across them, and the equations of motion need G > 0 everywhere: add to T a term that vanishes on them, such as (d/dt h)^2/2 for h = {h}"
        ),
        None => String::new(),
    };
    cx.error(
        ErrorKind::NotPositiveDefinite {
            at: format!("{}{hint}", sym.sample_description()),
        },
        Some(sym.model.kinetic_energy.span.clone()),
    );
}

/// The first holonomic constraint's text, when G (symmetric, finite) is
/// positive definite on ker dh: Z G Z + s (I − Z) > 0 with Z the projector
/// onto ker dh and s a scale of G.
fn positive_on_constraints(
    sym: &Symbols,
    raw: &Raw,
    gm: &nalgebra::DMatrix<f64>,
    inputs: &[f64],
) -> Option<String> {
    let (n, k) = (gm.nrows(), raw.holonomic.len());
    if k == 0
        || !gm.iter().all(|x| x.is_finite())
        || (gm - gm.transpose()).amax() > 1e-12 * (1.0 + gm.amax())
    {
        return None;
    }
    let dh: Vec<Atom> = raw.a_rows[..k].iter().flatten().cloned().collect();
    let rows = program(&dh, &sym.inputs()).ok()?.eval(inputs);
    let d = nalgebra::DMatrix::from_row_slice(k, n, &rows);
    let across = d.transpose() * (&d * d.transpose()).lu().try_inverse()? * &d;
    let z = nalgebra::DMatrix::identity(n, n) - across;
    let s = 1.0 + gm.amax();
    let restricted = &z * gm * &z + (nalgebra::DMatrix::identity(n, n) - &z) * s;
    restricted.cholesky()?;
    Some(sym.model.holonomic[0].text.clone())
}

/// (1.3) for generic parameters and configurations, from which of B's
/// candidate rows (the normal velocity, then A's rows, then the contact
/// rows) the exact elimination kept: `dropped` their places, `a_rows`
/// how many rows A has.
///
/// - ker B ⊆ ker A (A's rows lie in B's row space) holds by construction:
///   every row of A is a candidate, and a candidate is dropped only as a
///   combination of the kept ones before it.
/// - ker A ⊄ TN (the normal row is not in A's row space): A's rows are
///   independent (the derivation stops otherwise), so the normal lies in
///   their span, or is zero, exactly where one of the first 1 + `a_rows`
///   candidates was dropped.
///
/// (Both were computed again by four more eliminations of the same rows.)
pub fn wall_hypotheses(cx: &mut Collector, w: &Wall, dropped: &[usize], a_rows: usize) {
    if dropped.iter().any(|&k| k <= a_rows) {
        cx.error(
            ErrorKind::Hypothesis {
                wall: w.name.clone(),
                condition: "ker A ⊄ TₓN (1.3): the constraints already forbid motion across the wall, or its normal velocity is zero".into(),
                at: "generic parameters and configurations".to_string(),
            },
            Some(w.span.clone()),
        );
    }
}

/// What [`on_wall`] evaluates: f, df, h and the rows of A and B.
pub struct WallRows<'r> {
    /// f.
    pub surface: &'r Atom,
    /// df.
    pub normal: &'r [Atom],
    /// The holonomic constraints h (their differentials are A's first rows).
    pub holonomic: &'r [Atom],
    /// Rows of A.
    pub a: &'r [Vec<Atom>],
    /// Independent rows of B.
    pub b: &'r [Vec<Atom>],
}

/// (1.3) and B's rank at a point of the wall itself: the sample
/// configuration moved onto N = {f = 0} and h(q) = 0 by Gauss–Newton steps,
/// at the file's parameter values. Catches models that satisfy the
/// hypotheses for generic q but break them on N.
pub fn on_wall(sym: &Symbols, cx: &mut Collector, w: &Wall, rows: &WallRows) {
    let n = sym.vels.len();
    let k = rows.holonomic.len();
    // f, h; df, dh; the rows of A; the rows of B.
    let mut outputs = vec![rows.surface.clone()];
    outputs.extend(rows.holonomic.iter().cloned());
    outputs.extend(rows.normal.iter().cloned());
    outputs.extend(rows.a[..k].iter().flatten().cloned());
    outputs.extend(rows.a.iter().flatten().cloned());
    outputs.extend(rows.b.iter().flatten().cloned());
    let prog = match program(&outputs, &sym.inputs()) {
        Ok(p) => p,
        Err(e) => {
            cx.error(ErrorKind::Symbolic(e), Some(w.span.clone()));
            return;
        }
    };
    let np = sym.params.len();
    let Some(x) = onto(&prog, sym.sample_inputs(), np, n, 1 + k) else {
        // No point of N found near the sample: the generic checks stand.
        return;
    };
    let out = prog.eval(&x);
    if !out.iter().all(|v| v.is_finite()) {
        // A row without a value there (asin of an angle past 1, say): no
        // rank to compare, and the generic checks stand.
        return;
    }
    let matrix = |from: usize, count: usize| -> nalgebra::DMatrix<f64> {
        nalgebra::DMatrix::from_fn(count, n, |i, j| out[from + i * n + j])
    };
    let gradients = 1 + k;
    let normal_m = matrix(gradients, 1);
    let a_from = gradients + gradients * n;
    let a_m = matrix(a_from, rows.a.len());
    let b_m = matrix(a_from + rows.a.len() * n, rows.b.len());
    let at = format!(
        "the point {} of the wall",
        sym.point_description(&x[np..np + n])
    );
    let ranks = [&b_m, &stack(&b_m, &a_m), &stack(&a_m, &normal_m), &a_m].map(numeric_rank);
    let [Some(rb), Some(rba), Some(ran), Some(ra)] = ranks else {
        return;
    };
    let mut failures = Vec::new();
    if rb < rows.b.len() {
        failures.push("B of full row rank");
    }
    if rba > rb {
        failures.push("ker B ⊆ ker A (1.3)");
    }
    if ran == ra {
        failures.push("ker A ⊄ TₓN (1.3): the constraints forbid motion across the wall there");
    }
    for condition in failures {
        cx.error(
            ErrorKind::Hypothesis {
                wall: w.name.clone(),
                condition: condition.into(),
                at: at.clone(),
            },
            Some(w.span.clone()),
        );
    }
}

/// The rows of `p` above those of `q`.
fn stack(p: &nalgebra::DMatrix<f64>, q: &nalgebra::DMatrix<f64>) -> nalgebra::DMatrix<f64> {
    let mut m = nalgebra::DMatrix::zeros(p.nrows() + q.nrows(), p.ncols());
    m.rows_mut(0, p.nrows()).copy_from(p);
    m.rows_mut(p.nrows(), q.nrows()).copy_from(q);
    m
}

/// The rank of `m` by its singular values, those above 1e-9 of the
/// largest counted; `None` where the decomposition does not settle within
/// a bounded number of sweeps (unbounded, a non-finite entry kept it
/// going for ever).
fn numeric_rank(m: &nalgebra::DMatrix<f64>) -> Option<usize> {
    if m.nrows() == 0 {
        return Some(0);
    }
    let sv = m
        .clone()
        .try_svd(false, false, f64::EPSILON, 1000)?
        .singular_values;
    let max = sv.iter().fold(0.0_f64, |a, b| a.max(*b));
    Some(sv.iter().filter(|s| **s > 1e-9 * max.max(1e-300)).count())
}
