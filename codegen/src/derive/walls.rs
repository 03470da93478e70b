//! Pass 4: each wall's B (the normal velocity, A's rows, the contact rows,
//! dependent rows removed), the hypotheses (1.3) checked, and P and the
//! collision map (I − 2P)v in closed form (eqs. 2.4 and 2.13) where G⁻¹ is
//! exact.

use symbolica::prelude::*;

use super::checks::{self, WallRows};
use super::elimination;
use super::lower::Lowering;
use super::mechanics::{Exact, Raw, RawWall};
use super::output::{Form, Function, Geometry, Projection, WallDerivation};
use super::symbols::Symbols;
use super::{Field, Rat, is_zero, rows_matrix, strings};
use crate::diag::{Collector, ErrorKind, Reported};
use crate::ir::{Kind, Wall};
use crate::program::Entry;
use crate::quantity::Quantity;

/// What every wall shares: the model's symbols, lowering, exact G and A,
/// and G⁻¹ where P is closed-form.
pub struct Context<'c, 'a> {
    /// Symbols.
    pub sym: &'c Symbols<'a>,
    /// Lowering.
    pub low: &'c Lowering,
    /// The mechanics as expressions.
    pub raw: &'c Raw,
    /// G and A exactly.
    pub exact: &'c Exact,
    /// G⁻¹, or `None` for structured evaluation.
    pub g_inv: Option<&'c Matrix<Field>>,
    /// Makes the emitted functions.
    pub compile: &'c super::Compiler,
}

/// Every wall's derivation (a wall whose rows are all dependent has
/// already failed a hypothesis check and is left out).
pub fn derive(c: &Context, cx: &mut Collector) -> Result<Vec<WallDerivation>, Reported> {
    let mut out = Vec::new();
    for (w, raw) in c.sym.model.walls.iter().zip(&c.raw.walls) {
        if let Some(d) = wall(c, cx, w, raw)? {
            out.push(d);
        }
    }
    Ok(out)
}

fn wall(
    c: &Context,
    cx: &mut Collector,
    w: &Wall,
    raw: &RawWall,
) -> Result<Option<WallDerivation>, Reported> {
    let (sym, low) = (c.sym, c.low);
    let span = Some(w.span.clone());
    let Some(b) = rows(c, cx, w, raw)? else {
        return Ok(None);
    };
    let (b_mat, b_atoms, kept, dropped) = (b.matrix, b.atoms, b.origin, b.dropped);
    let closed = match c.g_inv {
        Some(g_inv) => Some(closed_form(sym, low, g_inv, &b_mat).ok_or_else(|| {
            cx.error(
                ErrorKind::Structure(format!(
                    "wall `{}`: BG⁻¹Bᵀ is singular for generic parameters and configurations, so P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B does not exist",
                    w.name
                )),
                span.clone(),
            )
        })?),
        None => None,
    };
    let normal: Vec<Atom> = raw.normal.iter().map(|a| low.reduce(a)).collect();
    let mut normal_velocity = Atom::num(0);
    for (k, row) in normal.iter().enumerate() {
        normal_velocity += row.clone() * sym.vel(k);
    }
    let b_flat: Vec<Atom> = b_atoms.iter().flatten().cloned().collect();
    let mut functions = Vec::new();
    for (quantity, outputs, rows) in [
        (Quantity::Surface, vec![raw.surface.clone()], 0),
        (Quantity::Normal, normal, 0),
        (Quantity::NormalVelocity, vec![normal_velocity], 0),
        (Quantity::SurfaceHessian, vec![low.reduce(&raw.hessian)], 0),
        (Quantity::WallRows, b_flat, b_atoms.len()),
    ] {
        functions.extend(
            c.compile
                .applicable(cx, quantity, &outputs, rows, &w.span)?,
        );
    }
    let mut candidates = Vec::new();
    let projection = match &closed {
        Some((p, collide)) => {
            let flat: Vec<Atom> = p.iter().flatten().cloned().collect();
            functions.extend(
                c.compile
                    .applicable(cx, Quantity::Projector, &flat, 0, &w.span)?,
            );
            if let Some(f) = linear_collision(c, cx, p, &w.span)? {
                candidates.push((Form::Linear, f));
            }
            if let Some(f) = c
                .compile
                .applicable(cx, Quantity::Collide, collide, 0, &w.span)?
            {
                candidates.push((Form::ClosedForm, f));
            }
            Projection::ClosedForm {
                projector: strings(p),
                collision: collide
                    .iter()
                    .map(|x| low.collect_velocities(sym, x))
                    .collect(),
            }
        }
        None => Projection::Structured,
    };
    if let Some(f) = elimination::collision(c.sym, c.exact, c.compile, cx, &b_atoms, &w.span)? {
        candidates.push((Form::Elimination, f));
    }
    let collision = elimination::choose(sym.params.len(), candidates);
    functions.extend(collision.as_ref().map(|(_, f)| f.clone()));
    let geometry = match sym.model.kind {
        Kind::Coordinates => Geometry::Surface(raw.surface.to_string()),
        Kind::Instantaneous => {
            Geometry::NormalVelocity(raw.normal.iter().map(|a| a.to_string()).collect())
        }
    };
    Ok(Some(WallDerivation {
        name: w.name.clone(),
        doc: w.doc.clone(),
        geometry,
        b_rows: strings(&b_atoms),
        b_origin: kept,
        dropped,
        projection,
        collision: collision.map(|(choice, _)| choice),
        functions,
    }))
}

/// A wall's B: its independent rows and where they came from.
struct WallB {
    matrix: Matrix<Field>,
    /// The rows as expressions, functions raised.
    atoms: Vec<Vec<Atom>>,
    origin: Vec<String>,
    dropped: Vec<String>,
}

/// B's candidate rows (the normal velocity, A's rows, the contact rows)
/// with the dependent ones removed, the hypotheses (1.3) checked for
/// generic q and at a point of the wall; `None` when no row is left (a
/// hypothesis check has then failed).
fn rows(
    c: &Context,
    cx: &mut Collector,
    w: &Wall,
    raw: &RawWall,
) -> Result<Option<WallB>, Reported> {
    let (sym, low, exact) = (c.sym, c.low, c.exact);
    let n = sym.vels.len();
    let normal_r: Vec<Rat> = raw.normal.iter().map(|a| low.to_rat(a)).collect();
    let mut candidates = vec![(normal_r, "the normal velocity".to_string())];
    for (r, label) in exact.a.iter().zip(&c.raw.a_labels) {
        candidates.push((r.clone(), label.clone()));
    }
    for (k, row) in raw.contact.iter().enumerate() {
        let r = row.iter().map(|a| low.to_rat(a)).collect();
        candidates.push((r, format!("contact constraint {}", k + 1)));
    }
    let (kept, dropped) = independent_rows(&candidates, n, &exact.field);
    let b: Vec<Vec<Rat>> = kept.iter().map(|(r, _)| r.clone()).collect();
    checks::wall_hypotheses(cx, w, &b, &exact.a, &candidates[0].0, &exact.field);
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
    if sym.model.kind == Kind::Coordinates {
        let rows = WallRows {
            surface: &raw.surface,
            normal: &raw.normal,
            holonomic: &c.raw.holonomic,
            a: &c.raw.a_rows,
            b: &atoms,
        };
        checks::on_wall(sym, cx, w, &rows);
    }
    Ok(Some(WallB {
        matrix,
        atoms,
        origin: kept.into_iter().map(|(_, o)| o).collect(),
        dropped,
    }))
}

/// P entry by entry and (I − 2P)v, simplified; `None` when BG⁻¹Bᵀ is
/// singular.
#[allow(clippy::type_complexity, clippy::needless_range_loop)]
fn closed_form(
    sym: &Symbols,
    low: &Lowering,
    g_inv: &Matrix<Field>,
    b: &Matrix<Field>,
) -> Option<(Vec<Vec<Atom>>, Vec<Atom>)> {
    let n = sym.vels.len();
    let p = projector(g_inv, b)?;
    let p_atoms: Vec<Vec<Atom>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| low.simplify(&p[(i as u32, j as u32)]))
                .collect()
        })
        .collect();
    let collide = (0..n)
        .map(|i| {
            let mut s = sym.vel(i);
            for j in 0..n {
                s -= Atom::num(2) * p_atoms[i][j].clone() * sym.vel(j);
            }
            s
        })
        .collect();
    Some((p_atoms, collide))
}

/// The collision map as v⁺ = M v with M = I − 2P, where P does not depend
/// on the coordinates: M's entries are then parameter-only work, done once,
/// and a call is one multiplication per entry that is not 0 or ±1. `None`
/// where P depends on q (there (I − 2P)v as an expression of q and v is
/// cheaper than M's n² entries).
fn linear_collision(
    c: &Context,
    cx: &mut Collector,
    p: &[Vec<Atom>],
    span: &std::ops::Range<usize>,
) -> Result<Option<Function>, Reported> {
    let sym = c.sym;
    let varies = |e: &Atom| sym.coords.iter().any(|q| !is_zero(&e.derivative(*q)));
    if p.iter().flatten().any(varies) {
        return Ok(None);
    }
    let n = sym.vels.len();
    let mut entries = Vec::with_capacity(n * n);
    let mut general = Vec::new();
    for (i, row) in p.iter().enumerate() {
        for (j, pij) in row.iter().enumerate() {
            let delta = Atom::num(i64::from(i == j));
            let m = delta - Atom::num(2) * pij.clone();
            entries.push(if is_zero(&m) {
                Entry::Zero
            } else if is_zero(&(m.clone() - Atom::num(1))) {
                Entry::One
            } else if is_zero(&(m.clone() + Atom::num(1))) {
                Entry::MinusOne
            } else {
                general.push(m);
                Entry::General
            });
        }
    }
    let Some(f) = c
        .compile
        .applicable(cx, Quantity::Collide, &general, 0, span)?
    else {
        return Ok(None);
    };
    let velocities = sym.params.len() + sym.coords.len();
    Ok(Some(Function {
        program: f.program.times_vector(&entries, n, velocities),
        ..f
    }))
}

/// P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B.
fn projector(g_inv: &Matrix<Field>, b: &Matrix<Field>) -> Option<Matrix<Field>> {
    let x = g_inv * &b.transpose();
    let m = b * &x;
    let m_inv = m.inv().ok()?;
    Some(&(&x * &m_inv) * b)
}

/// Keeps each candidate row that raises the rank (exactly, over the field of
/// rational functions), in order; returns the kept rows and the descriptions
/// of the dropped ones.
#[allow(clippy::type_complexity)]
fn independent_rows(
    candidates: &[(Vec<Rat>, String)],
    n: usize,
    field: &Field,
) -> (Vec<(Vec<Rat>, String)>, Vec<String>) {
    let mut kept: Vec<(Vec<Rat>, String)> = Vec::new();
    let mut dropped = Vec::new();
    for (row, origin) in candidates {
        let mut trial: Vec<Vec<Rat>> = kept.iter().map(|(r, _)| r.clone()).collect();
        trial.push(row.clone());
        let rank = rows_matrix(&trial, n, field).map(|m| m.rank()).unwrap_or(0);
        if rank == trial.len() {
            kept.push((row.clone(), origin.clone()));
        } else {
            dropped.push(origin.clone());
        }
    }
    (kept, dropped)
}
