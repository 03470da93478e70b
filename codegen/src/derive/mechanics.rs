//! Pass 2: the mechanics in exact expressions. T and V parsed; G = ∂²T/∂v²;
//! the rows of A (the holonomic constraints' differentials first); the
//! Lagrange–d'Alembert equations' h and Ȧq̇; each wall's f, normal df,
//! vᵀ∇²f v and contact rows. Then, after lowering (pass 3), G exactly, the
//! symbolic-or-structured choice, and q̈ in closed form where G⁻¹ is exact.

use std::ops::Range;

use symbolica::prelude::*;

use super::atoms::size;
use super::budget::Over;
use super::build::Differentiate;
use super::echelon::Echelon;
use super::lower::{self, Lowering};
use super::symbols::Symbols;
use super::{Field, Rat, is_zero, rows_matrix};
use super::{bounded, budget, checks};
use crate::diag::{Collector, ErrorKind, Reported};
use crate::ir::{Kind, ProjectorMode, Wall};

/// The model's mechanics as expressions, before any exact linear algebra.
pub struct Raw {
    /// T.
    pub t: Atom,
    /// V.
    pub v: Atom,
    /// G, entry by entry.
    pub g: Vec<Vec<Atom>>,
    /// Rows of A: dh for every holonomic constraint, then the velocity-level
    /// constraints.
    pub a_rows: Vec<Vec<Atom>>,
    /// Where each row of A comes from.
    pub a_labels: Vec<String>,
    /// h(q).
    pub holonomic: Vec<Atom>,
    /// h(q, q̇) of G q̈ + h = Aᵀλ.
    pub forcing: Vec<Atom>,
    /// Ȧq̇, one per row of A.
    pub drift: Vec<Atom>,
    /// Per wall.
    pub walls: Vec<RawWall>,
}

/// One wall's geometry and contact rows as expressions.
pub struct RawWall {
    /// f (0 for an instantaneous model).
    pub surface: Atom,
    /// df, or the normal-velocity row of an instantaneous model.
    pub normal: Vec<Atom>,
    /// vᵀ∇²f(q)v (0 for an instantaneous model).
    pub hessian: Atom,
    /// The contact rows.
    pub contact: Vec<Vec<Atom>>,
}

impl Raw {
    /// Every expression that later becomes a rational function, so that the
    /// lowering sees all of them. The destructuring is exhaustive: a new
    /// field must be listed here or named as not needed.
    pub fn expressions(&self) -> Vec<&Atom> {
        let Raw {
            t,
            v,
            g,
            a_rows,
            a_labels: _,
            // Evaluated as they are, never as rational functions.
            holonomic: _,
            forcing,
            drift,
            walls,
        } = self;
        let mut out: Vec<&Atom> = g.iter().flatten().collect();
        out.extend(a_rows.iter().flatten());
        out.extend(forcing);
        out.extend(drift);
        out.extend([t, v]);
        for w in walls {
            let RawWall {
                surface: _,
                normal,
                hessian,
                contact,
            } = w;
            out.extend(normal);
            out.push(hessian);
            out.extend(contact.iter().flatten());
        }
        out
    }
}

/// Pass 2: parses T, V, the constraints and the walls, and derives G, A,
/// the equations of motion and each wall's geometry, checking each as it
/// goes (T quadratic, constraints linear, no velocity where none belongs).
#[allow(clippy::needless_range_loop)] // matrix code reads best with indices
pub fn raw(sym: &Symbols, cx: &mut Collector) -> Result<Raw, Reported> {
    let m = sym.model;
    let n = m.velocities.len();
    let t = sym.parse(&m.kinetic_energy, cx)?;
    // A velocity in V, h or a wall's f: reported, the other checks of
    // this pass go on, and the derivation stops at its end (the programs
    // of those quantities read the coordinates alone).
    let mut velocity = Ok(());
    let v = match &m.potential {
        Some(p) => {
            let v = sym.parse(p, cx)?;
            let found = checks::no_velocity(sym, cx, &v, &p.span, ErrorKind::VelocityInPotential);
            velocity = velocity.and(found);
            v
        }
        None => Atom::num(0),
    };
    let mut g = vec![vec![Atom::num(0); n]; n];
    for i in 0..n {
        let ti = t.d(sym.vels[i]);
        for j in 0..n {
            g[i][j] = budget::expand(
                &ti.d(sym.vels[j]),
                cx,
                &m.kinetic_energy.span,
                "the kinetic energy",
            )?;
        }
    }
    checks::kinetic_energy_quadratic(sym, cx, &t, &g);

    let mut a_rows = Vec::new();
    let mut a_labels = Vec::new();
    let mut a_spans = Vec::new();
    let mut holonomic = Vec::new();
    for (k, c) in m.holonomic.iter().enumerate() {
        let h = sym.parse(c, cx)?;
        let found = checks::no_velocity(sym, cx, &h, &c.span, ErrorKind::VelocityInHolonomic);
        velocity = velocity.and(found);
        let what = format!("holonomic constraint {}", k + 1);
        let mut row = Vec::with_capacity(n);
        let mut bound = budget::Running::default();
        for q in &sym.coords {
            let d = h.d(*q);
            bound.add(&d, cx, &c.span, &what)?;
            row.push(d.expand());
        }
        a_rows.push(row);
        a_labels.push(what);
        a_spans.push(c.span.clone());
        holonomic.push(h);
    }
    for (k, c) in m.constraints.iter().enumerate() {
        a_labels.push(format!("constraint {}", k + 1));
        a_spans.push(c.span.clone());
        let e = sym.parse(c, cx)?;
        a_rows.push(checks::linear_row(
            sym,
            cx,
            &e,
            &c.span,
            &a_labels[a_labels.len() - 1],
        )?);
    }
    let forcing = forcing(sym, cx, &t, &v)?;
    let drift = a_rows
        .iter()
        .zip(a_spans.iter().zip(&a_labels))
        .map(|(row, (span, what))| drift(sym, cx, row, span, what))
        .collect::<Result<Vec<_>, _>>()?;
    // Every wall's checks, then the first failure.
    let walls: Vec<Result<RawWall, Reported>> =
        m.walls.iter().map(|w| raw_wall(sym, cx, w)).collect();
    let walls = walls.into_iter().collect::<Result<Vec<_>, _>>()?;
    velocity?;
    Ok(Raw {
        t,
        v,
        g,
        a_rows,
        a_labels,
        holonomic,
        forcing,
        drift,
        walls,
    })
}

/// A wall's f, df (or its normal-velocity row), vᵀ∇²f v and contact rows.
fn raw_wall(sym: &Symbols, cx: &mut Collector, w: &Wall) -> Result<RawWall, Reported> {
    let n = sym.vels.len();
    let missing = |cx: &mut Collector, what: &str| {
        cx.error(
            ErrorKind::Structure(format!("wall `{}` has no `{what}`", w.name)),
            Some(w.span.clone()),
        )
    };
    let (surface, normal, hessian) = match sym.model.kind {
        Kind::Coordinates => {
            let e = w.surface.as_ref().ok_or_else(|| missing(cx, "surface"))?;
            let f = sym.parse(e, cx)?;
            checks::no_velocity(sym, cx, &f, &e.span, |v| ErrorKind::VelocityInSurface {
                wall: w.name.clone(),
                velocity: v,
            })?;
            let what = format!("wall `{}`'s surface", w.name);
            let mut row = vec![Atom::num(0); n];
            for (k, q) in sym.coords.iter().enumerate() {
                row[k] = budget::expand(&f.d(*q), cx, &e.span, &what)?;
            }
            let hessian = hessian_form(sym, &row, cx, &e.span, &what)?;
            (f, row, hessian)
        }
        Kind::Instantaneous => {
            let e = w
                .normal_velocity
                .as_ref()
                .ok_or_else(|| missing(cx, "normal_velocity"))?;
            let atom = sym.parse(e, cx)?;
            let what = format!("wall `{}`'s normal velocity", w.name);
            let row = checks::linear_row(sym, cx, &atom, &e.span, &what)?;
            (Atom::num(0), row, Atom::num(0))
        }
    };
    let mut contact = Vec::new();
    for (k, c) in w.contact.iter().enumerate() {
        let e = sym.parse(c, cx)?;
        let what = format!("wall `{}`'s contact row {}", w.name, k + 1);
        contact.push(checks::linear_row(sym, cx, &e, &c.span, &what)?);
    }
    Ok(RawWall {
        surface,
        normal,
        hessian,
        contact,
    })
}

/// ∂L/∂q = ∂T/∂q − ∂V/∂q, entry by entry: the momentum's rate ṗ where
/// p = G q̇ and there are no constraints (Taylor's method can follow p
/// instead of q̇, `program/taylor/solve.rs`).
pub fn lagrangian_gradient(sym: &Symbols, raw: &Raw) -> Vec<Atom> {
    sym.coords
        .iter()
        .map(|q| raw.t.d(*q) - raw.v.d(*q))
        .collect()
}

/// h of the Lagrange–d'Alembert equations G q̈ + h = Aᵀλ (with A q̇ = 0):
/// hᵢ = Σₖ ∂²T/∂q̇ᵢ∂qₖ q̇ₖ − ∂T/∂qᵢ + ∂V/∂qᵢ, within the budget (checked
/// after each derivative, at T's or V's declaration). An instantaneous
/// model has no motion between collisions: zero.
fn forcing(sym: &Symbols, cx: &mut Collector, t: &Atom, v: &Atom) -> Result<Vec<Atom>, Reported> {
    let n = sym.vels.len();
    let m = sym.model;
    if m.kind == Kind::Instantaneous {
        return Ok(vec![Atom::num(0); n]);
    }
    let t_span = &m.kinetic_energy.span;
    let v_span = m.potential.as_ref().map_or(t_span, |p| &p.span);
    let (mut t_bound, mut v_bound) = (budget::Running::default(), budget::Running::default());
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let q = sym.coords[i];
        let dv = v.d(q);
        v_bound.add(&dv, cx, v_span, "the potential")?;
        let dt = t.d(q);
        t_bound.add(&dt, cx, t_span, "the kinetic energy")?;
        let ti = t.d(sym.vels[i]);
        let mut h = dv - dt;
        for (k, qk) in sym.coords.iter().enumerate() {
            let d = ti.d(*qk);
            t_bound.add(&d, cx, t_span, "the kinetic energy")?;
            h += d * sym.vel(k);
        }
        out.push(h);
    }
    Ok(out)
}

/// Ȧq̇ of one row of A (differentiating A q̇ = 0 in time gives
/// A q̈ + Ȧq̇ = 0): Σⱼ ∂(A_row q̇)/∂qⱼ q̇ⱼ, within the budget (checked after
/// each derivative, at the row's declaration `span`, named `what`). Zero
/// for an instantaneous model.
fn drift(
    sym: &Symbols,
    cx: &mut Collector,
    row: &[Atom],
    span: &Range<usize>,
    what: &str,
) -> Result<Atom, Reported> {
    if sym.model.kind == Kind::Instantaneous {
        return Ok(Atom::num(0));
    }
    let mut e = Atom::num(0);
    for (k, a) in row.iter().enumerate() {
        e += a.clone() * sym.vel(k);
    }
    let mut c = Atom::num(0);
    let mut bound = budget::Running::default();
    let rate = format!("{what}'s rate");
    for (j, qj) in sym.coords.iter().enumerate() {
        let d = e.d(*qj);
        bound.add(&d, cx, span, &rate)?;
        c += d * sym.vel(j);
    }
    Ok(c)
}

/// vᵀ∇²f(q)v from the normal df = `row`: Σₖ (Σᵢ ∂ₖ∂ᵢf vᵢ) vₖ, expanded
/// within the budget (checked after each second derivative, so that a form
/// too large stops at its first entries, `what` at `span` named).
fn hessian_form(
    sym: &Symbols,
    row: &[Atom],
    cx: &mut Collector,
    span: &Range<usize>,
    what: &str,
) -> Result<Atom, Reported> {
    let mut form = Atom::num(0);
    let mut bound = budget::Running::default();
    for (k, entry) in row.iter().enumerate() {
        let mut rate = Atom::num(0);
        for (i, q) in sym.coords.iter().enumerate() {
            let d = entry.d(*q);
            bound.add(&d, cx, span, what)?;
            rate += d * sym.vel(i);
        }
        form += rate * sym.vel(k);
    }
    Ok(form.expand())
}

/// G and A as exact rational functions, and how P will be evaluated.
pub struct Exact {
    /// G with sin² + cos² reduced, entry by entry.
    pub g: Vec<Vec<Atom>>,
    /// G as an exact matrix.
    g_mat: Matrix<Field>,
    /// The field of G's entries.
    pub field: Field,
    /// Rows of A.
    pub a: Vec<Vec<Rat>>,
    /// G⁻¹ is not derived: every wall's P is solved at run time from G
    /// and B (with G⁻¹ exact, a wall may still be, by its own estimate).
    pub structured: bool,
}

/// G and A exactly, and the symbolic-or-structured choice.
pub fn exact(
    sym: &Symbols,
    low: &Lowering,
    raw: &Raw,
    cx: &mut Collector,
) -> Result<Exact, Reported> {
    let m = sym.model;
    let n = m.velocities.len();
    let t_span = &m.kinetic_energy.span;
    let g_rat: Vec<Rat> = (raw.g.iter().flatten().map(|a| low.to_rat(a)))
        .collect::<Result<_, _>>()
        .map_err(|o| o.report(cx, t_span, &lower::reduced("the mass matrix")))?;
    let field = Field::from_poly(&g_rat[0].numerator);
    let g_mat = Matrix::from_linear(g_rat, n as u32, n as u32, field.clone()).map_err(|e| {
        cx.error(
            ErrorKind::Symbolic(format!("the mass matrix: {e:?}")),
            Some(m.kinetic_energy.span.clone()),
        )
    })?;
    // A's rows: each holonomic constraint's, then the velocity-level ones.
    let mut declared = m.holonomic.iter().chain(&m.constraints);
    let a = (raw.a_rows.iter())
        .map(|r| {
            let span = declared.next().map_or(t_span, |d| &d.span);
            (r.iter().map(|x| low.to_rat(x)))
                .collect::<Result<Vec<Rat>, _>>()
                .map_err(|o| o.report(cx, span, &lower::reduced("a constraint row")))
        })
        .collect::<Result<Vec<Vec<Rat>>, _>>()?;
    independent_constraints(sym, low, &a, cx)?;
    let g = (raw.g.iter())
        .map(|r| r.iter().map(|x| low.reduce(x)).collect())
        .collect::<Result<Vec<Vec<Atom>>, _>>()
        .map_err(|o| {
            let what = lower::reduced("the mass matrix");
            o.report(cx, &m.kinetic_energy.span, &what)
        })?;
    // An exact G⁻¹ is attempted only within its budget: asked for, a
    // closed form past it is an error; chosen, it gives way to structured
    // evaluation.
    let terms = || budget::determinant_terms(&g);
    let structured = match m.projector {
        ProjectorMode::Symbolic if terms() > budget::MAX_DETERMINANT_TERMS => {
            return Err(cx.error(
                ErrorKind::Limit(format!(
                    "`projector = \"symbolic\"` needs G⁻¹ exactly, and det G may have up to {:.0} terms (the product of its entries' term counts over permutations), more than the {} a closed-form P is derived for; without it, P v is solved at run time from G and B (structured evaluation)",
                    terms(),
                    budget::MAX_DETERMINANT_TERMS
                )),
                Some(m.kinetic_energy.span.clone()),
            ));
        }
        ProjectorMode::Symbolic => false,
        ProjectorMode::Structured => true,
        ProjectorMode::Auto => {
            off_diagonal_entries(&g) > 2 * n || terms() > budget::MAX_DETERMINANT_TERMS
        }
    };
    Ok(Exact {
        g,
        g_mat,
        field,
        a,
        structured,
    })
}

impl Exact {
    /// G⁻¹ where P will be closed-form; `None` when it is structured (the
    /// exact G⁻¹ is what makes a symbolic P expensive, and structured
    /// evaluation never needs it: G > 0 is checked numerically).
    pub fn inverse(
        &self,
        sym: &Symbols,
        cx: &mut Collector,
    ) -> Result<Option<Matrix<Field>>, Reported> {
        if self.structured {
            return Ok(None);
        }
        let inv = self.g_mat.inv().map_err(|_| {
            cx.error(
                ErrorKind::NotPositiveDefinite {
                    at: "every configuration (G is singular)".into(),
                },
                Some(sym.model.kinetic_energy.span.clone()),
            )
        })?;
        Ok(Some(inv))
    }
}

/// Number of non-zero entries off the diagonal. A symbolic G⁻¹ (and so P)
/// stays small while G is this sparse; the chain family measures how fast
/// it grows when G is dense (docs/performance.md).
fn off_diagonal_entries(g: &[Vec<Atom>]) -> usize {
    g.iter()
        .enumerate()
        .map(|(i, row)| {
            row.iter()
                .enumerate()
                .filter(|(j, a)| i != *j && !is_zero(a))
                .count()
        })
        .sum()
}

/// An error at each row of A that is a combination of the rows before it
/// (exactly, sin² + cos² = 1 and cosh² − sinh² = 1 holding: a row may be
/// another's multiple only through them): such a row constrains nothing
/// more, and the equations of motion with it have no unique multipliers
/// (the derivation stops there).
fn independent_constraints(
    sym: &Symbols,
    low: &Lowering,
    a: &[Vec<Rat>],
    cx: &mut Collector,
) -> Result<(), Reported> {
    let m = sym.model;
    let mut echelon = Echelon::new(low);
    let mut refused = None;
    for (row, declared) in a.iter().zip(m.holonomic.iter().chain(&m.constraints)) {
        let independent = echelon
            .insert(row)
            .map_err(|o| o.report(cx, &declared.span, &lower::reduced("a constraint row")))?;
        if !independent {
            refused = Some(cx.error(
                ErrorKind::Structure(
                    "this constraint is a combination of the ones before it (holonomic constraints count by their differentials, and sin² + cos² = 1 may be needed to see it): it constrains nothing more; remove it".into(),
                ),
                Some(declared.span.clone()),
            ));
        }
    }
    refused.map_or(Ok(()), Err)
}

/// q̈ of the equations of motion in closed form, where G⁻¹ is exact and the
/// rows of A are independent; `None` otherwise (the run time then solves
/// numerically).
pub fn accelerations(
    sym: &Symbols,
    low: &Lowering,
    raw: &Raw,
    exact: &Exact,
    g_inv: Option<&Matrix<Field>>,
    cx: &mut Collector,
) -> Result<Option<Vec<Atom>>, Reported> {
    let (Some(g_inv), Kind::Coordinates) = (g_inv, sym.model.kind) else {
        return Ok(None);
    };
    let n = sym.vels.len();
    let span = Some(sym.model.kinetic_energy.span.clone());
    let mut fail = |what: &str| {
        cx.error(
            ErrorKind::Symbolic(format!("the equations of motion: {what}")),
            span.clone(),
        )
    };
    let column = |e: &[Atom]| {
        let r = (e.iter().map(|a| low.to_rat(&(-a.clone())))).collect::<Result<Vec<Rat>, _>>();
        Matrix::from_linear(r.ok()?, e.len() as u32, 1, exact.field.clone()).ok()
    };
    let neg_h = column(&raw.forcing).ok_or_else(|| fail("h as a column"))?;
    let constrained = if exact.a.is_empty() {
        None
    } else {
        let a = rows_matrix(&exact.a, n, &exact.field).ok_or_else(|| fail("A as a matrix"))?;
        let c = column(&raw.drift).ok_or_else(|| fail("Ȧq̇ as a column"))?;
        Some((a, c))
    };
    // Past the budget of its steps or of its terms or size, q̈ is solved
    // at run time instead.
    let Ok(Some(x)) = solve_motion(g_inv, constrained.as_ref(), &neg_h) else {
        return Ok(None);
    };
    let terms = |r: &Rat| (r.numerator.nterms() + r.denominator.nterms()) as f64;
    if (0..n).any(|i| terms(&x[(i as u32, 0)]) > budget::MAX_CLOSED_FORM_TERMS) {
        return Ok(None);
    }
    let q_ddot = (0..n).map(|i| low.simplify(&x[(i as u32, 0)]));
    let q_ddot = q_ddot.collect::<Result<Vec<_>, _>>().map_err(|o| {
        let what = lower::reduced("the accelerations q̈");
        o.report(cx, &sym.model.kinetic_energy.span, &what)
    })?;
    // Written out with its exponentials expanded, a closed form within
    // the terms can still be huge to compile.
    let largest = (q_ddot.iter().map(|a| size(a.as_view()))).max();
    Ok((largest <= Some(budget::MAX_CLOSED_FORM_SIZE)).then_some(q_ddot))
}

/// q̈ of G q̈ + h = Aᵀλ, A q̈ + Ȧq̇ = 0, from −h and (A, −Ȧq̇): with
/// z = −G⁻¹h and Y = G⁻¹Aᵀ, (AY)λ = −Ȧq̇ − Az and q̈ = z + Yλ. `None` when
/// AY is singular (dependent rows of A), [`Over`] where a product or
/// inverse is past the budget ([`bounded`]).
fn solve_motion(
    g_inv: &Matrix<Field>,
    constraints: Option<&(Matrix<Field>, Matrix<Field>)>,
    neg_h: &Matrix<Field>,
) -> Result<Option<Matrix<Field>>, Over> {
    let z = bounded::mul(g_inv, neg_h)?;
    let Some((a, neg_c)) = constraints else {
        return Ok(Some(z));
    };
    let y = bounded::mul(g_inv, &a.transpose())?;
    let Some(ay_inv) = bounded::inv(&bounded::mul(a, &y)?)? else {
        return Ok(None);
    };
    let lambda = bounded::mul(&ay_inv, &(neg_c - &bounded::mul(a, &z)?))?;
    Ok(Some(&z + &bounded::mul(&y, &lambda)?))
}
