//! Pass 4: each wall's B (the normal velocity, A's rows, the contact rows,
//! dependent rows removed) and the hypotheses (1.3), in [`rows`]; then P
//! and the collision map (I − 2P)v in closed form (eqs. 2.4 and 2.13) where
//! G⁻¹ is exact, and the collision map in every other form that applies.

use symbolica::prelude::*;

mod rows;

use super::bounded;
use super::budget::{self, Over};
use super::build::Differentiate;
use super::elimination;
use super::lower::{self, Lowering};
use super::mechanics::{Exact, Raw, RawWall};
use super::output::{Form, Function, Geometry, Projection, WallDerivation};
use super::symbols::Symbols;
use super::{Field, Rat, is_zero, rows_matrix, strings};
use crate::diag::{Collector, ErrorKind, Reported};
use crate::ir::{Kind, ProjectorMode, Wall};
use crate::program::{Entry, stored_signs};
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
    pub compile: &'c super::Compiler<'c>,
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
    let Some(b) = rows::of(c, cx, w, raw)? else {
        return Ok(None);
    };
    let (b_mat, b_atoms, b_forms, kept, dropped, steady) =
        (b.matrix, b.atoms, b.forms, b.origin, b.dropped, b.steady);
    // `auto` weighs B too: a closed-form P divides by det(BG⁻¹Bᵀ), and a
    // wall whose estimate is past the budget is solved at run time (where
    // the kept rows span the rest everywhere; elsewhere only the closed
    // form is right).
    let g_inv = c.g_inv.filter(|_| {
        sym.model.projector != ProjectorMode::Auto
            || !steady
            || budget::bordered_terms(&c.exact.g, &b.rats) <= budget::MAX_DETERMINANT_TERMS
    });
    if !steady && g_inv.is_none() {
        return Err(cx.error(
            ErrorKind::Structure(format!(
                "wall `{}`: the rows of B kept ({}) become dependent where the removed ones ({}) do not, so P solved from them at run time would be wrong there; derive P exactly (`projector = \"symbolic\"`) or write rows that stay independent on the wall",
                w.name,
                kept.join("; "),
                dropped.join("; ")
            )),
            span.clone(),
        ));
    }
    // Chosen (`auto`), a closed form whose steps are past the budget gives
    // way to P solved at run time too, where the kept rows allow it.
    let closed = match g_inv.map(|g_inv| closed_form(sym, low, g_inv, &b_mat)) {
        Some(Ok(Some(closed))) => Some(closed),
        Some(Ok(None)) => {
            return Err(cx.error(
                ErrorKind::Structure(format!(
                    "wall `{}`: BG⁻¹Bᵀ is singular for generic parameters and configurations, so P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B does not exist",
                    w.name
                )),
                span.clone(),
            ));
        }
        Some(Err(_)) if sym.model.projector == ProjectorMode::Auto && steady => None,
        Some(Err(o)) => return Err(reduced(o, cx, w, "the projector P")),
        None => None,
    };
    let normal =
        (low.evaluated_forms(raw.normal.clone())).map_err(|o| reduced(o, cx, w, "the normal"))?;
    let hessian = (low.evaluated_forms(vec![raw.hessian.clone()]))
        .map_err(|o| reduced(o, cx, w, "the Hessian form"))?;
    let normal_velocity: Vec<Vec<Atom>> = (normal.iter())
        .map(|n| {
            let mut v = Atom::num(0);
            for (k, row) in n.iter().enumerate() {
                v += row.clone() * sym.vel(k);
            }
            vec![v]
        })
        .collect();
    let b_flat: Vec<Vec<Atom>> = (b_forms.iter())
        .map(|f| f.iter().flatten().cloned().collect())
        .collect();
    let mut functions = Vec::new();
    for (quantity, forms, rows) in [
        (Quantity::Surface, vec![vec![raw.surface.clone()]], 0),
        (Quantity::Normal, normal, 0),
        (Quantity::NormalVelocity, normal_velocity, 0),
        (Quantity::SurfaceHessian, hessian, 0),
        (Quantity::WallRows, b_flat, b_atoms.len()),
    ] {
        let forms: Vec<&[Atom]> = forms.iter().map(|f| &f[..]).collect();
        functions.extend(
            c.compile
                .applicable_of(cx, quantity, &forms, rows, &w.span)?,
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
            // Where P does not depend on q, M = I − 2P is parameter-only
            // work, done once, and a call is one multiplication per entry
            // that is not 0 or ±1: M v, and M shortened by A's rows. (Where
            // P depends on q, (I − 2P)v as an expression of q and v is
            // cheaper than M's n² entries.)
            if !p.iter().flatten().any(|e| varies(c, e)) {
                let m = reflection(p);
                if let Some(f) = linear_map(c, cx, &m, &vec![false; m.len()], &w.span)? {
                    candidates.push((Form::Linear, f));
                }
                if let Some(f) = admissible_collision(c, cx, &m, w)? {
                    candidates.push((Form::Admissible, f));
                }
            }
            if let Some(f) = c
                .compile
                .applicable(cx, Quantity::Collide, collide, 0, &w.span)?
            {
                candidates.push((Form::ClosedForm, f));
            }
            Projection::ClosedForm {
                projector: strings(p),
                collision: (collide.iter())
                    .map(|x| low.collect_velocities(sym, x))
                    .collect::<Result<_, _>>()
                    .map_err(|o| reduced(o, cx, w, "the collision map"))?,
            }
        }
        None => Projection::Structured,
    };
    // Elimination evaluates B's kept rows: only where they span the rest.
    if steady
        && let Some(f) = elimination::collision(c.sym, c.exact, c.compile, cx, &b_forms, &w.span)?
    {
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

/// P entry by entry and (I − 2P)v, simplified; `None` when BG⁻¹Bᵀ is
/// singular, [`Over`] where a step of P or its simplification is past
/// the budget.
#[allow(clippy::type_complexity, clippy::needless_range_loop)]
fn closed_form(
    sym: &Symbols,
    low: &Lowering,
    g_inv: &Matrix<Field>,
    b: &Matrix<Field>,
) -> Result<Option<(Vec<Vec<Atom>>, Vec<Atom>)>, Over> {
    let n = sym.vels.len();
    let Some(p) = projector(g_inv, b)? else {
        return Ok(None);
    };
    let p_atoms = simplified(low, &p, n, n)?;
    let collide = (0..n)
        .map(|i| {
            let mut s = sym.vel(i);
            for j in 0..n {
                s -= Atom::num(2) * p_atoms[i][j].clone() * sym.vel(j);
            }
            s
        })
        .collect();
    Ok(Some((p_atoms, collide)))
}

/// The collision map on admissible velocities (A v = 0, the only ones a
/// collision meets) from M = I − 2P (free of q, kept with the parameters),
/// shortened twice by A's rows. On the inputs: A v =
/// 0 writes k components v_D (A_D invertible) through the others, so M's
/// columns D fold into the rest, M̃ = M − M_D A_D⁻¹A, zero in the columns D
/// and equal to M on ker A. On the outputs: v⁺ is admissible too (A P = A,
/// so A v⁺ = −A v = 0), so k components v⁺_E (A_E invertible) can instead be
/// computed from the others, v⁺_E = −(A_E⁻¹A)_Ē v⁺_Ē, where that row is
/// cheaper. Of every such D and E (or none), the pair with the fewest
/// operations per call; `None` without constraints, where A_D⁻¹A varies
/// with q, or where nothing is saved against M v.
fn admissible_collision(
    c: &Context,
    cx: &mut Collector,
    m: &[Vec<Atom>],
    w: &Wall,
) -> Result<Option<Function>, Reported> {
    let (a, field, low) = (&c.exact.a, &c.exact.field, c.low);
    let (n, k) = (c.sym.vels.len(), a.len());
    if k == 0 || k >= n {
        return Ok(None);
    }
    let Some(a_mat) = rows_matrix(a, n, field) else {
        return Ok(None);
    };
    // A_D⁻¹A for every D with A_D invertible and A_D⁻¹A free of q.
    let mut through: Vec<(Vec<usize>, Vec<Vec<Atom>>)> = Vec::new();
    for d in subsets(n, k) {
        let a_d: Vec<Rat> = a
            .iter()
            .flat_map(|row| d.iter().map(|&j| row[j].clone()))
            .collect();
        let Ok(a_d) = Matrix::from_linear(a_d, k as u32, k as u32, field.clone()) else {
            continue;
        };
        let Ok(inv) = a_d.inv() else {
            continue;
        };
        let t = simplified(low, &(&inv * &a_mat), k, n).map_err(|o| reduced(o, cx, w, ON_KER_A))?;
        if !t.iter().flatten().any(|e| varies(c, e)) {
            through.push((d, t));
        }
    }
    let mut best: Option<(usize, Vec<Vec<Atom>>, Vec<bool>)> = None;
    for (d, t) in &through {
        let folded: Vec<Vec<Atom>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let mut e = m[i][j].clone();
                        for (s, &ds) in d.iter().enumerate() {
                            e -= m[i][ds].clone() * t[s][j].clone();
                        }
                        low.to_rat(&e).and_then(|r| low.simplify(&r))
                    })
                    .collect()
            })
            .collect::<Result<_, _>>()
            .map_err(|o| reduced(o, cx, w, ON_KER_A))?;
        let rows: Vec<usize> = folded.iter().map(|r| row_cost(r)).collect();
        // Outputs E computed from the others (rows over v⁺), each where
        // that is cheaper; E = ∅ first.
        let mut options: Vec<(Vec<Vec<Atom>>, Vec<bool>)> = vec![(folded.clone(), vec![false; n])];
        for (e, te) in &through {
            let mut rows_e = folded.clone();
            let mut over = vec![false; n];
            for (s, &es) in e.iter().enumerate() {
                let from_outputs: Vec<Atom> = (0..n)
                    .map(|j| {
                        if e.contains(&j) {
                            Atom::num(0)
                        } else {
                            -te[s][j].clone()
                        }
                    })
                    .collect();
                if row_cost(&from_outputs) < rows[es] {
                    rows_e[es] = from_outputs;
                    over[es] = true;
                }
            }
            options.push((rows_e, over));
        }
        for (rows_e, over) in options {
            let total: usize = rows_e.iter().map(|r| row_cost(r)).sum();
            if best.as_ref().is_none_or(|(b, _, _)| total < *b) {
                best = Some((total, rows_e, over));
            }
        }
    }
    let plain: usize = m.iter().map(|r| row_cost(r)).sum();
    match best {
        Some((total, rows, over)) if total < plain => linear_map(c, cx, &rows, &over, &w.span),
        _ => Ok(None),
    }
}

/// Operations per call of one row of a linear map: a multiplication per
/// entry that is not 0 or ±1, an addition or subtraction per further term,
/// and a negation where every term is subtracted (all entries −1).
fn row_cost(row: &[Atom]) -> usize {
    let terms = row.iter().filter(|x| !is_zero(x)).count();
    let ones = |sign: i64| {
        row.iter()
            .filter(|x| is_zero(&((*x).clone() - Atom::num(sign))))
            .count()
    };
    let (plus, minus) = (ones(1), ones(-1));
    let negation = usize::from(terms > 0 && minus == terms);
    (terms - plus - minus) + terms.saturating_sub(1) + negation
}

/// What the admissible collision map's reductions name in their errors.
const ON_KER_A: &str = "the collision map on admissible velocities";

/// The error of `o`, a step past the budget in `what` of wall `w`, at the
/// wall.
fn reduced(o: Over, cx: &mut Collector, w: &Wall, what: &str) -> Reported {
    let what = format!("{what} of wall `{}`", w.name);
    let what = match o {
        Over::Product(_) => what,
        _ => lower::reduced(&what),
    };
    o.report(cx, &w.span, &what)
}

/// The entries of a rows × cols matrix, simplified.
fn simplified(
    low: &Lowering,
    m: &Matrix<Field>,
    rows: usize,
    cols: usize,
) -> Result<Vec<Vec<Atom>>, Over> {
    (0..rows)
        .map(|i| {
            (0..cols)
                .map(|j| low.simplify(&m[(i as u32, j as u32)]))
                .collect()
        })
        .collect()
}

/// Whether `e` depends on the coordinates.
fn varies(c: &Context, e: &Atom) -> bool {
    c.sym.coords.iter().any(|q| !is_zero(&e.d(*q)))
}

/// M = I − 2P.
fn reflection(p: &[Vec<Atom>]) -> Vec<Vec<Atom>> {
    p.iter()
        .enumerate()
        .map(|(i, row)| {
            row.iter()
                .enumerate()
                .map(|(j, pij)| Atom::num(i64::from(i == j)) - Atom::num(2) * pij.clone())
                .collect()
        })
        .collect()
}

/// The k-element subsets of 0..n in lexicographic order.
fn subsets(n: usize, k: usize) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    let mut d: Vec<usize> = (0..k).collect();
    loop {
        out.push(d.clone());
        let Some(t) = (0..k).rev().find(|&t| d[t] < n - k + t) else {
            return out;
        };
        d[t] += 1;
        for u in t + 1..k {
            d[u] = d[u - 1] + 1;
        }
    }
}

/// v⁺ = M v as a function: M's entries that are not 0 or ±1 are, up to
/// sign, the program's (parameter-only) outputs, each distinct value once
/// with the signs that need no negation (`stored_signs`); one
/// multiplication per entry per call. The rows `over_outputs` multiply v⁺
/// (the other rows) instead of v.
fn linear_map(
    c: &Context,
    cx: &mut Collector,
    m: &[Vec<Atom>],
    over_outputs: &[bool],
    span: &std::ops::Range<usize>,
) -> Result<Option<Function>, Reported> {
    let sym = c.sym;
    let n = sym.vels.len();
    // Each entry that is not 0 or ±1 is ± one of the distinct values, kept
    // once each whatever its sign.
    let mut entries = Vec::with_capacity(n * n);
    let mut values: Vec<Atom> = Vec::new();
    for m in m.iter().flatten() {
        entries.push(if is_zero(m) {
            Entry::Zero
        } else if is_zero(&(m.clone() - Atom::num(1))) {
            Entry::One
        } else if is_zero(&(m.clone() + Atom::num(1))) {
            Entry::MinusOne
        } else if let Some(k) = values.iter().position(|g| is_zero(&(m.clone() - g))) {
            Entry::Value { k, negated: false }
        } else if let Some(k) = values.iter().position(|g| is_zero(&(m.clone() + g))) {
            Entry::Value { k, negated: true }
        } else {
            values.push(m.clone());
            Entry::Value {
                k: values.len() - 1,
                negated: false,
            }
        });
    }
    let general: Vec<Atom> = stored_signs(&mut entries, n, values.len())
        .into_iter()
        .map(|(k, negated)| {
            if negated {
                -values[k].clone()
            } else {
                values[k].clone()
            }
        })
        .collect();
    let Some(f) = c
        .compile
        .applicable(cx, Quantity::Collide, &general, 0, span)?
    else {
        return Ok(None);
    };
    let velocities = sym.params.len() + sym.coords.len();
    Ok(Some(Function {
        program: f
            .program
            .times_vector_folded(&entries, over_outputs, n, velocities),
        ..f
    }))
}

/// P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B, each step within the budget ([`bounded`]);
/// `None` where BG⁻¹Bᵀ is singular.
fn projector(g_inv: &Matrix<Field>, b: &Matrix<Field>) -> Result<Option<Matrix<Field>>, Over> {
    let x = bounded::mul(g_inv, &b.transpose())?;
    let Some(m_inv) = bounded::inv(&bounded::mul(b, &x)?)? else {
        return Ok(None);
    };
    Ok(Some(bounded::mul(&bounded::mul(&x, &m_inv)?, b)?))
}
