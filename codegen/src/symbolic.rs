//! Stage 2: exact derivation. The only module that uses symbolica.
//!
//! From a validated model: G = Hessian of T in the velocities; the rows of A
//! and of each wall's B by differentiating the velocity-level constraints;
//! P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B (Lemma 1, eq. 2.4) and the collision map (I − 2P)v
//! (eq. 2.13), in exact rational-function arithmetic, with sin² + cos² = 1
//! reduced; the paper's hypotheses checked; and every emitted function turned
//! into an optimised straight-line [`Program`] by symbolica's evaluator
//! (common subexpressions, Horner schemes).
//!
//! Function applications (sin(θ), cos(q₁ − q₂), …) are replaced by fresh
//! symbols while the matrices are computed, so every entry is a rational
//! function of symbols; a sin/cos pair of the same argument is then reduced
//! modulo s² + c² − 1, and the functions are put back before evaluation.

use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;

use symbolica::evaluate::{Instruction, Slot as ESlot};
use symbolica::prelude::*;

use crate::diag::{Collector, ErrorKind, ModelErrors};
use crate::ir::{Expr, FUNCTIONS, Kind, Model, ProjectorMode};
use crate::program::{Func, Instr, OpCount, Program, Slot};

type Rat = RationalPolynomial<IntegerRing, u16>;
type Field = RationalPolynomialField<IntegerRing, u16>;

/// Everything derived for one model.
#[derive(Debug, Clone)]
pub struct Derivation {
    /// The validated model.
    pub model: Model,
    /// G, entry by entry.
    pub mass_matrix: Vec<Vec<String>>,
    /// Rows of A: the differentials of the holonomic constraints first.
    pub constraint_rows: Vec<Vec<String>>,
    /// The holonomic constraints h(q).
    pub holonomic: Vec<String>,
    /// q̈ in closed form, component by component (see
    /// [`Programs::accelerations`]).
    pub accelerations: Option<Vec<String>>,
    /// Per wall.
    pub walls: Vec<WallDerivation>,
    /// Programs for the model-wide functions.
    pub programs: Programs,
    /// The float type the emitter writes (an emission choice, kept here so
    /// that every emitting function sees it; `F64` from `derive`).
    pub scalar: crate::emit::Scalar,
}

/// Programs for the model-wide functions.
#[derive(Debug, Clone)]
pub struct Programs {
    /// G (n² outputs, row-major).
    pub mass_matrix: Program,
    /// T.
    pub kinetic_energy: Program,
    /// V.
    pub potential: Program,
    /// A (k·n outputs, row-major).
    pub constraints: Program,
    /// h(q), one output per holonomic constraint.
    pub holonomic: Program,
    /// h(q, q̇) of G q̈ + h = Aᵀλ (n outputs; zero for instantaneous models).
    pub forcing: Program,
    /// Ȧq̇, one output per row of A (zero for instantaneous models).
    pub constraint_drift: Program,
    /// q̈ of the equations of motion in closed form (n outputs), where G⁻¹
    /// is derived exactly; `None` for an instantaneous model, a structured
    /// G, or dependent rows of A (the run time then solves numerically).
    pub accelerations: Option<Program>,
}

/// Programs for one wall.
#[derive(Debug, Clone)]
pub struct WallPrograms {
    /// f.
    pub surface: Program,
    /// B (rows·n outputs).
    pub rows: Program,
    /// The wall's normal df(q) (B's first row; n outputs).
    pub normal: Program,
    /// The normal velocity df·v.
    pub normal_velocity: Program,
    /// vᵀ∇²f(q)v: with df·q̈, the second time derivative of f along a motion.
    pub surface_hessian: Program,
    /// P (n² outputs).
    pub projector: Program,
    /// (I − 2P)v (n outputs).
    pub collide: Program,
}

/// What was derived for one wall.
#[derive(Debug, Clone)]
pub struct WallDerivation {
    /// Its name.
    pub name: String,
    /// Its doc text.
    pub doc: String,
    /// f (0 for an instantaneous model).
    pub surface: String,
    /// The independent rows of B: the normal velocity, then A's, then the
    /// contact rows, dependent rows removed.
    pub b_rows: Vec<Vec<String>>,
    /// Where each kept row came from.
    pub b_origin: Vec<String>,
    /// The rows that were removed as dependent, with where they came from.
    pub dropped: Vec<String>,
    /// P entry by entry.
    pub projector: Vec<Vec<String>>,
    /// v⁺ component by component, in terms of v⁻ (named as the velocities).
    pub collision: Vec<String>,
    /// P v is solved at run time from G and B (no closed form; `projector`
    /// and `collision` are empty).
    pub structured: bool,
    /// Programs.
    pub programs: WallPrograms,
}

impl Derivation {
    /// Operation counts of every emitted function.
    pub fn op_counts(&self) -> Vec<(String, OpCount)> {
        crate::emit::op_counts(self)
    }
}

/// Derives everything for `model`.
pub fn derive(model: &Model) -> Result<Derivation, ModelErrors> {
    let mut cx = Collector::new(&model.file, &model.source);
    if let Err(e) = crate::lock::acquire() {
        cx.error(ErrorKind::Symbolic(e), None);
        return Err(cx.into_errors());
    }
    let d = Deriver::new(model, &mut cx).and_then(|mut d| d.run());
    match d {
        Some(d) if !cx.has_errors() => Ok(d),
        _ => Err(cx.into_errors()),
    }
}

/// A function application replaced by a symbol while matrices are computed.
struct Lowered {
    symbol: Symbol,
    function: Atom,
}

struct Deriver<'a> {
    model: &'a Model,
    cx: &'a mut Collector,
    params: Vec<Symbol>,
    coords: Vec<Symbol>,
    vels: Vec<Symbol>,
    definitions: Vec<(Symbol, Atom)>,
    lowered: Vec<Lowered>,
    /// (sin symbol, cos symbol) of the same argument.
    trig_pairs: Vec<(Symbol, Symbol)>,
}

impl<'a> Deriver<'a> {
    fn new(model: &'a Model, cx: &'a mut Collector) -> Option<Self> {
        let sym = |n: &String| symbol!(n.as_str());
        let mut d = Self {
            model,
            cx,
            params: model.params.iter().map(|p| sym(&p.name)).collect(),
            coords: model.coordinates.iter().map(sym).collect(),
            vels: model.velocities.iter().map(sym).collect(),
            definitions: Vec::new(),
            lowered: Vec::new(),
            trig_pairs: Vec::new(),
        };
        // Definitions, each made free of the others (the validator rejected
        // cycles, so as many rounds as there are definitions suffice).
        let mut defs = Vec::new();
        for (name, e) in &model.definitions {
            defs.push((symbol!(name.as_str()), d.parse_raw(e)?));
        }
        for _ in 0..defs.len() {
            let snapshot = defs.clone();
            for (_, a) in defs.iter_mut() {
                for (s, v) in &snapshot {
                    *a = a.replace(Atom::from(*s)).with(v.clone());
                }
            }
        }
        d.definitions = defs;
        Some(d)
    }

    fn parse_raw(&mut self, e: &Expr) -> Option<Atom> {
        match try_parse!(e.text.as_str()) {
            Ok(a) => Some(a),
            Err(msg) => {
                let first = msg.lines().next().unwrap_or("").to_string();
                self.cx
                    .error(ErrorKind::Syntax(first), Some(e.span.clone()));
                None
            }
        }
    }

    /// The expression with every definition substituted.
    fn parse(&mut self, e: &Expr) -> Option<Atom> {
        let mut a = self.parse_raw(e)?;
        for (s, v) in &self.definitions {
            a = a.replace(Atom::from(*s)).with(v.clone());
        }
        Some(a)
    }

    #[allow(clippy::needless_range_loop)] // matrix code reads best with indices
    fn run(&mut self) -> Option<Derivation> {
        let m = self.model;
        let n = m.velocities.len();
        let t = self.parse(&m.kinetic_energy)?;
        let v_atom = match &m.potential {
            Some(p) => self.parse(p)?,
            None => Atom::num(0),
        };
        if let Some(p) = &m.potential {
            self.no_velocity(&v_atom, &p.span, ErrorKind::VelocityInPotential);
        }

        // G = ∂²T/∂v∂v, and T must equal ½ vᵀ G v.
        let mut g = vec![vec![Atom::num(0); n]; n];
        for i in 0..n {
            let ti = t.derivative(self.vels[i]);
            for j in 0..n {
                g[i][j] = ti.derivative(self.vels[j]).expand();
            }
        }
        self.check_quadratic(&t, &g);

        // A: dh for every holonomic constraint, then one row per
        // velocity-level constraint.
        let mut a_rows = Vec::new();
        let mut a_labels = Vec::new();
        let mut holonomic = Vec::new();
        for (k, c) in m.holonomic.iter().enumerate() {
            let h = self.parse(c)?;
            self.no_velocity(&h, &c.span, ErrorKind::VelocityInHolonomic);
            a_rows.push(
                self.coords
                    .iter()
                    .map(|q| h.derivative(*q).expand())
                    .collect::<Vec<_>>(),
            );
            a_labels.push(format!("holonomic constraint {}", k + 1));
            holonomic.push(h);
        }
        for (k, c) in m.constraints.iter().enumerate() {
            a_labels.push(format!("constraint {}", k + 1));
            let e = self.parse(c)?;
            a_rows.push(self.linear_row(&e, &c.span)?);
        }

        let (forcing, drift) = self.equations_of_motion(&t, &v_atom, &a_rows);

        // Lower function applications in everything the matrices use.
        let mut everything: Vec<Atom> = g.iter().flatten().cloned().collect();
        everything.extend(a_rows.iter().flatten().cloned());
        everything.extend(forcing.iter().cloned());
        everything.extend(drift.iter().cloned());
        everything.extend([t.clone(), v_atom.clone()]);
        let mut walls_raw = Vec::new();
        for w in &m.walls {
            let (surface, normal, hessian) = match m.kind {
                Kind::Coordinates => {
                    let f = self.parse(w.surface.as_ref()?)?;
                    let span = w
                        .surface
                        .as_ref()
                        .map(|s| s.span.clone())
                        .unwrap_or(w.span.clone());
                    self.no_velocity(&f, &span, |v| ErrorKind::VelocityInSurface {
                        wall: w.name.clone(),
                        velocity: v,
                    });
                    let mut row = vec![Atom::num(0); n];
                    for (k, q) in self.coords.iter().enumerate() {
                        row[k] = f.derivative(*q).expand();
                    }
                    let hessian = self.hessian_form(&row);
                    (f, row, hessian)
                }
                Kind::Instantaneous => {
                    let e = w.normal_velocity.as_ref()?;
                    let atom = self.parse(e)?;
                    (Atom::num(0), self.linear_row(&atom, &e.span)?, Atom::num(0))
                }
            };
            let mut contact = Vec::new();
            for c in &w.contact {
                let e = self.parse(c)?;
                contact.push(self.linear_row(&e, &c.span)?);
            }
            everything.extend(normal.iter().cloned());
            everything.push(hessian.clone());
            everything.extend(contact.iter().flatten().cloned());
            walls_raw.push((surface, normal, hessian, contact));
        }
        self.lower_functions(&everything);

        let vars = self.var_map();
        let to_rat = |d: &Self, a: &Atom| -> Rat { d.rat(&d.lower(a), &vars) };
        let g_rat: Vec<Rat> = g.iter().flatten().map(|a| to_rat(self, a)).collect();
        let field = Field::from_poly(&g_rat[0].numerator);
        let g_mat = Matrix::from_linear(g_rat, n as u32, n as u32, field.clone()).ok()?;
        let a_rat: Vec<Vec<Rat>> = a_rows
            .iter()
            .map(|r| r.iter().map(|a| to_rat(self, a)).collect())
            .collect();

        let g_simpl: Vec<Vec<Atom>> = g
            .iter()
            .map(|r| r.iter().map(|a| self.reduce_atom(a, &vars)).collect())
            .collect();
        let inputs = self.inputs();
        let mass_matrix = self.program(
            &g_simpl.iter().flatten().cloned().collect::<Vec<_>>(),
            &inputs,
        )?;
        self.check_positive_definite(&mass_matrix, n);
        let structured = match m.projector {
            ProjectorMode::Symbolic => false,
            ProjectorMode::Structured => true,
            ProjectorMode::Auto => off_diagonal_entries(&g_simpl) > 2 * n,
        };
        // The exact G⁻¹ is what makes a symbolic P expensive; structured
        // evaluation never needs it (G > 0 is checked numerically above).
        let g_inv = if structured {
            None
        } else {
            match g_mat.inv() {
                Ok(i) => Some(i),
                Err(_) => {
                    self.cx.error(
                        ErrorKind::NotPositiveDefinite {
                            at: "every configuration (G is singular)".into(),
                        },
                        Some(m.kinetic_energy.span.clone()),
                    );
                    return None;
                }
            }
        };

        let mut walls = Vec::new();
        for (w, (surface, normal, hessian, contact)) in m.walls.iter().zip(walls_raw) {
            let normal_r: Vec<Rat> = normal.iter().map(|a| to_rat(self, a)).collect();
            let contact_r: Vec<Vec<Rat>> = contact
                .iter()
                .map(|r| r.iter().map(|a| to_rat(self, a)).collect())
                .collect();
            let mut candidates = vec![(normal_r, "the normal velocity".to_string())];
            for (r, label) in a_rat.iter().zip(&a_labels) {
                candidates.push((r.clone(), label.clone()));
            }
            for (k, r) in contact_r.iter().enumerate() {
                candidates.push((r.clone(), format!("contact constraint {}", k + 1)));
            }
            let (kept, dropped) = independent_rows(&candidates, n, &field);
            self.check_wall_hypotheses(w, &kept, &a_rat, &candidates[0].0, n, &field);
            if kept.is_empty() {
                continue;
            }
            let b = rows_matrix(
                &kept.iter().map(|(r, _)| r.clone()).collect::<Vec<_>>(),
                n,
                &field,
            )?;
            let b_atoms: Vec<Vec<Atom>> = kept
                .iter()
                .map(|(r, _)| r.iter().map(|x| self.raise(&x.to_expression())).collect())
                .collect();
            if m.kind == Kind::Coordinates {
                self.check_on_wall(w, &surface, &normal, &a_rows, &b_atoms);
            }
            // Symbolic: P and (I − 2P)v in closed form. Structured: neither;
            // the emitter solves for P v at run time from G and B.
            let (p_atoms, collide) = match &g_inv {
                Some(g_inv) => {
                    let p = projector(g_inv, &b)?;
                    let p_atoms: Vec<Vec<Atom>> = (0..n)
                        .map(|i| {
                            (0..n)
                                .map(|j| self.simplify(&p[(i as u32, j as u32)], &vars))
                                .collect()
                        })
                        .collect();
                    let collide: Vec<Atom> = (0..n)
                        .map(|i| {
                            let mut s = Atom::from(self.vels[i]);
                            for j in 0..n {
                                s -=
                                    Atom::num(2) * p_atoms[i][j].clone() * Atom::from(self.vels[j]);
                            }
                            s
                        })
                        .collect();
                    (p_atoms, collide)
                }
                None => (Vec::new(), Vec::new()),
            };
            let normal: Vec<Atom> = normal.iter().map(|a| self.reduce_atom(a, &vars)).collect();
            let mut normal_velocity = Atom::num(0);
            for (k, row) in normal.iter().enumerate() {
                normal_velocity += row.clone() * Atom::from(self.vels[k]);
            }
            let programs = WallPrograms {
                surface: self.program(std::slice::from_ref(&surface), &inputs)?,
                normal: self.program(&normal, &inputs)?,
                normal_velocity: self.program(std::slice::from_ref(&normal_velocity), &inputs)?,
                surface_hessian: self.program(&[self.reduce_atom(&hessian, &vars)], &inputs)?,
                rows: self.program(
                    &b_atoms.iter().flatten().cloned().collect::<Vec<_>>(),
                    &inputs,
                )?,
                projector: self.program(
                    &p_atoms.iter().flatten().cloned().collect::<Vec<_>>(),
                    &inputs,
                )?,
                collide: self.program(&collide, &inputs)?,
            };
            walls.push(WallDerivation {
                name: w.name.clone(),
                doc: w.doc.clone(),
                surface: surface.to_string(),
                b_rows: strings2(&b_atoms),
                b_origin: kept.iter().map(|(_, o)| o.clone()).collect(),
                dropped,
                projector: strings2(&p_atoms),
                collision: collide.iter().map(|c| self.collect_velocities(c)).collect(),
                structured: g_inv.is_none(),
                programs,
            });
        }

        let accelerations: Option<Vec<Atom>> = match (&g_inv, m.kind) {
            (Some(g_inv), Kind::Coordinates) => {
                let column = |d: &Self, e: &[Atom]| {
                    let r: Vec<Rat> = e.iter().map(|a| to_rat(d, &(-a.clone()))).collect();
                    Matrix::from_linear(r, e.len() as u32, 1, field.clone()).ok()
                };
                let neg_h = column(self, &forcing)?;
                let constrained = match a_rat.is_empty() {
                    true => None,
                    false => Some((rows_matrix(&a_rat, n, &field)?, column(self, &drift)?)),
                };
                solve_motion(g_inv, constrained.as_ref(), &neg_h).map(|x| {
                    (0..n)
                        .map(|i| self.simplify(&x[(i as u32, 0)], &vars))
                        .collect()
                })
            }
            _ => None,
        };
        let programs = Programs {
            accelerations: match &accelerations {
                Some(x) => Some(self.program(x, &inputs)?),
                None => None,
            },
            forcing: self.program(&forcing, &inputs)?,
            constraint_drift: self.program(&drift, &inputs)?,
            mass_matrix,
            kinetic_energy: self.program(&[self.reduce_atom(&t, &vars)], &inputs)?,
            potential: self.program(&[self.reduce_atom(&v_atom, &vars)], &inputs)?,
            constraints: self.program(
                &a_rows.iter().flatten().cloned().collect::<Vec<_>>(),
                &inputs,
            )?,
            holonomic: self.program(&holonomic, &inputs)?,
        };
        Some(Derivation {
            scalar: crate::emit::Scalar::F64,
            model: m.clone(),
            mass_matrix: strings2(&g_simpl),
            constraint_rows: strings2(&a_rows),
            holonomic: holonomic.iter().map(|h| h.to_string()).collect(),
            accelerations: accelerations
                .as_deref()
                .map(|x| x.iter().map(|a| a.to_string()).collect()),
            walls,
            programs,
        })
    }

    /// The Lagrange–d'Alembert equations G q̈ + h = Aᵀλ with A q̇ = 0:
    /// hᵢ = Σₖ ∂²T/∂q̇ᵢ∂qₖ q̇ₖ − ∂T/∂qᵢ + ∂V/∂qᵢ, and differentiating A q̇ = 0
    /// in time gives A q̈ + Ȧq̇ = 0 with (Ȧq̇)ᵣ = Σⱼ ∂(Aᵣq̇)/∂qⱼ q̇ⱼ.
    /// An instantaneous model has no motion between collisions: both are zero.
    fn equations_of_motion(
        &self,
        t: &Atom,
        v: &Atom,
        a_rows: &[Vec<Atom>],
    ) -> (Vec<Atom>, Vec<Atom>) {
        let n = self.vels.len();
        if self.model.kind == Kind::Instantaneous {
            return (vec![Atom::num(0); n], vec![Atom::num(0); a_rows.len()]);
        }
        let qdot = |k: usize| Atom::from(self.vels[k]);
        let forcing = (0..n)
            .map(|i| {
                let q = self.coords[i];
                let ti = t.derivative(self.vels[i]);
                let mut h = v.derivative(q) - t.derivative(q);
                for (k, qk) in self.coords.iter().enumerate() {
                    h += ti.derivative(*qk) * qdot(k);
                }
                h
            })
            .collect();
        let drift = a_rows
            .iter()
            .map(|row| {
                let mut e = Atom::num(0);
                for (k, a) in row.iter().enumerate() {
                    e += a.clone() * qdot(k);
                }
                let mut c = Atom::num(0);
                for (j, qj) in self.coords.iter().enumerate() {
                    c += e.derivative(*qj) * qdot(j);
                }
                c
            })
            .collect();
        (forcing, drift)
    }

    // ------------------------------------------------------------ checks

    fn check_quadratic(&mut self, t: &Atom, g: &[Vec<Atom>]) {
        let span = self.model.kinetic_energy.span.clone();
        for row in g {
            for e in row {
                for (k, v) in self.vels.iter().enumerate() {
                    if !is_zero(&e.derivative(*v)) {
                        self.cx.error(
                            ErrorKind::NotQuadratic(format!(
                                "its second derivatives still depend on `{}` (terms of degree > 2)",
                                self.model.velocities[k]
                            )),
                            Some(span),
                        );
                        return;
                    }
                }
            }
        }
        let mut quad = Atom::num(0);
        for (i, vi) in self.vels.iter().enumerate() {
            for (j, vj) in self.vels.iter().enumerate() {
                quad += g[i][j].clone() * Atom::from(*vi) * Atom::from(*vj);
            }
        }
        let rest = (t.clone() - quad / Atom::num(2)).expand();
        if !is_zero(&rest) {
            self.cx.error(
                ErrorKind::NotQuadratic(format!(
                    "T − ½vᵀGv = {rest} (terms of degree 0 or 1 in the velocities)"
                )),
                Some(span),
            );
        }
    }

    /// vᵀ∇²f(q)v from the normal df = `row`: Σₖ (Σᵢ ∂ₖ∂ᵢf vᵢ) vₖ.
    fn hessian_form(&self, row: &[Atom]) -> Atom {
        let mut form = Atom::num(0);
        for (k, entry) in row.iter().enumerate() {
            let mut rate = Atom::num(0);
            for (i, q) in self.coords.iter().enumerate() {
                rate += entry.derivative(*q) * Atom::from(self.vels[i]);
            }
            form += rate * Atom::from(self.vels[k]);
        }
        form.expand()
    }

    /// The coefficient row of a velocity-level expression, which must be
    /// linear and homogeneous in the velocities.
    fn linear_row(&mut self, e: &Atom, span: &Range<usize>) -> Option<Vec<Atom>> {
        let row: Vec<Atom> = self
            .vels
            .iter()
            .map(|v| e.derivative(*v).expand())
            .collect();
        for c in &row {
            for (k, v) in self.vels.iter().enumerate() {
                if !is_zero(&c.derivative(*v)) {
                    self.cx.error(
                        ErrorKind::NotLinear(format!(
                            "its coefficients depend on the velocity `{}`",
                            self.model.velocities[k]
                        )),
                        Some(span.clone()),
                    );
                    return None;
                }
            }
        }
        let mut lin = Atom::num(0);
        for (c, v) in row.iter().zip(&self.vels) {
            lin += c.clone() * Atom::from(*v);
        }
        let rest = (e.clone() - lin).expand();
        if !is_zero(&rest) {
            self.cx.error(
                ErrorKind::NotLinear(format!("it has a part free of the velocities: {rest}")),
                Some(span.clone()),
            );
            return None;
        }
        if row.iter().all(is_zero) {
            self.cx.error(
                ErrorKind::NotLinear("it does not involve any velocity".into()),
                Some(span.clone()),
            );
            return None;
        }
        Some(row)
    }

    fn no_velocity(&mut self, e: &Atom, span: &Range<usize>, kind: impl Fn(String) -> ErrorKind) {
        for (k, v) in self.vels.iter().enumerate() {
            if !is_zero(&e.derivative(*v)) {
                self.cx
                    .error(kind(self.model.velocities[k].clone()), Some(span.clone()));
                return;
            }
        }
    }

    /// G positive definite at the sample point (file's parameter values,
    /// [`sample_configuration`]): a Cholesky factorisation must succeed.
    fn check_positive_definite(&mut self, prog: &Program, n: usize) {
        let values = self.sample_inputs();
        let vals = prog.eval(&values);
        let gm = nalgebra::DMatrix::from_row_slice(n, n, &vals);
        let symmetric = (0..n).all(|i| {
            (0..n).all(|j| (gm[(i, j)] - gm[(j, i)]).abs() <= 1e-12 * (1.0 + gm[(i, j)].abs()))
        });
        if !symmetric || gm.clone().cholesky().is_none() || vals.iter().any(|x| !x.is_finite()) {
            let at = self.sample_description();
            self.cx.error(
                ErrorKind::NotPositiveDefinite { at },
                Some(self.model.kinetic_energy.span.clone()),
            );
        }
    }

    /// (1.3): ker B ⊆ ker A (A's rows lie in B's row space) and
    /// ker A ⊄ TN (the normal row is not in A's row space), checked exactly
    /// for generic parameters and configurations.
    fn check_wall_hypotheses(
        &mut self,
        w: &crate::ir::Wall,
        kept: &[(Vec<Rat>, String)],
        a: &[Vec<Rat>],
        normal: &[Rat],
        n: usize,
        field: &Field,
    ) {
        let at = "generic parameters and configurations".to_string();
        let b: Vec<Vec<Rat>> = kept.iter().map(|(r, _)| r.clone()).collect();
        let rank = |rows: &[Vec<Rat>]| -> usize {
            if rows.is_empty() {
                return 0;
            }
            rows_matrix(rows, n, field).map(|m| m.rank()).unwrap_or(0)
        };
        let rb = rank(&b);
        let mut ba = b.clone();
        ba.extend(a.iter().cloned());
        if rank(&ba) > rb {
            self.cx.error(
                ErrorKind::Hypothesis {
                    wall: w.name.clone(),
                    condition:
                        "ker B ⊆ ker A (1.3): some constraint row is not implied by the wall's rows"
                            .into(),
                    at: at.clone(),
                },
                Some(w.span.clone()),
            );
        }
        let ra = rank(a);
        let mut an = a.to_vec();
        an.push(normal.to_vec());
        if rank(&an) == ra {
            self.cx.error(
                ErrorKind::Hypothesis {
                    wall: w.name.clone(),
                    condition: "ker A ⊄ TₓN (1.3): the constraints already forbid motion across the wall, or its normal velocity is zero".into(),
                    at,
                },
                Some(w.span.clone()),
            );
        }
    }

    /// (1.3) and B's rank at a point of the wall itself: the sample
    /// configuration moved onto N = {f = 0} by Newton steps along ∇f, at the
    /// file's parameter values. Catches models that satisfy the hypotheses for
    /// generic q but break them on N.
    fn check_on_wall(
        &mut self,
        w: &crate::ir::Wall,
        surface: &Atom,
        normal: &[Atom],
        a: &[Vec<Atom>],
        b: &[Vec<Atom>],
    ) {
        let n = self.vels.len();
        let inputs = self.inputs();
        let mut outputs = vec![surface.clone()];
        outputs.extend(normal.iter().cloned());
        outputs.extend(a.iter().flatten().cloned());
        outputs.extend(b.iter().flatten().cloned());
        let Some(prog) = self.program(&outputs, &inputs) else {
            return;
        };
        let np = self.params.len();
        let mut x = self.sample_inputs();
        let mut on_wall = false;
        for _ in 0..100 {
            let out = prog.eval(&x);
            let f = out[0];
            let grad = &out[1..1 + n];
            let g2: f64 = grad.iter().map(|g| g * g).sum();
            let scale = 1.0 + x[np..np + n].iter().fold(0.0_f64, |m, q| m.max(q.abs()));
            if f.abs() <= 1e-12 * scale {
                on_wall = true;
                break;
            }
            if g2.is_nan() || g2 <= 0.0 || !f.is_finite() {
                break;
            }
            for k in 0..n {
                x[np + k] -= f * grad[k] / g2;
            }
        }
        if !on_wall {
            // No point of N found near the sample: the generic checks stand.
            return;
        }
        let out = prog.eval(&x);
        let rows = |from: usize, count: usize| -> nalgebra::DMatrix<f64> {
            nalgebra::DMatrix::from_fn(count, n, |i, j| out[from + i * n + j])
        };
        let normal_m = rows(1, 1);
        let a_m = rows(1 + n, a.len());
        let b_m = rows(1 + n + a.len() * n, b.len());
        let stack = |p: &nalgebra::DMatrix<f64>, q: &nalgebra::DMatrix<f64>| {
            let mut m = nalgebra::DMatrix::zeros(p.nrows() + q.nrows(), n);
            m.rows_mut(0, p.nrows()).copy_from(p);
            m.rows_mut(p.nrows(), q.nrows()).copy_from(q);
            m
        };
        let at = format!(
            "the point {} of the wall",
            self.point_description(&x[np..np + n])
        );
        let rb = numeric_rank(&b_m);
        let mut failures = Vec::new();
        if rb < b.len() {
            failures.push("B of full row rank");
        }
        if numeric_rank(&stack(&b_m, &a_m)) > rb {
            failures.push("ker B ⊆ ker A (1.3)");
        }
        if numeric_rank(&stack(&a_m, &normal_m)) == numeric_rank(&a_m) {
            failures.push("ker A ⊄ TₓN (1.3): the constraints forbid motion across the wall there");
        }
        for condition in failures {
            self.cx.error(
                ErrorKind::Hypothesis {
                    wall: w.name.clone(),
                    condition: condition.into(),
                    at: at.clone(),
                },
                Some(w.span.clone()),
            );
        }
    }

    // ------------------------------------------------------------ functions

    /// Finds every application of a model function and gives it a symbol;
    /// sin and cos of the same argument are paired for the reduction.
    fn lower_functions(&mut self, atoms: &[Atom]) {
        let mut seen: HashMap<String, usize> = HashMap::new();
        let mut args_by_fn: HashMap<String, (Option<Symbol>, Option<Symbol>)> = HashMap::new();
        for f in FUNCTIONS {
            let Ok(pat) = try_parse!(format!("{f}(x__dalembert_arg_)").as_str()) else {
                continue;
            };
            let pattern = pat.to_pattern();
            for a in atoms {
                let mut it = a.pattern_match(&pattern, None, None);
                while let Some(found) = it.next_detailed() {
                    for (_, v) in found.match_stack {
                        let Match::Single(arg) = v else { continue };
                        let arg = arg.to_owned();
                        let Ok(app) = try_parse!(format!("{f}({arg})").as_str()) else {
                            continue;
                        };
                        let key = app.to_string();
                        if seen.contains_key(&key) {
                            continue;
                        }
                        let s = symbol!(format!("fn__{}", self.lowered.len()).as_str());
                        seen.insert(key, self.lowered.len());
                        self.lowered.push(Lowered {
                            symbol: s,
                            function: app,
                        });
                        let pair = args_by_fn.entry(arg.to_string()).or_default();
                        match *f {
                            "sin" => pair.0 = Some(s),
                            "cos" => pair.1 = Some(s),
                            _ => {}
                        }
                    }
                }
            }
        }
        let mut pairs: Vec<(Symbol, Symbol)> = args_by_fn
            .into_values()
            .filter_map(|(s, c)| Some((s?, c?)))
            .collect();
        pairs.sort_by_key(|(s, _)| s.to_string());
        self.trig_pairs = pairs;
    }

    fn lower(&self, a: &Atom) -> Atom {
        let mut a = a.clone();
        for l in &self.lowered {
            a = a.replace(l.function.clone()).with(Atom::from(l.symbol));
        }
        a
    }

    fn raise(&self, a: &Atom) -> Atom {
        let mut a = a.clone();
        for l in &self.lowered {
            a = a.replace(Atom::from(l.symbol)).with(l.function.clone());
        }
        a
    }

    fn var_map(&self) -> Arc<Vec<PolyVariable>> {
        let mut v: Vec<PolyVariable> = Vec::new();
        for s in self.params.iter().chain(&self.coords).chain(&self.vels) {
            v.push(PolyVariable::Symbol(*s));
        }
        for l in &self.lowered {
            v.push(PolyVariable::Symbol(l.symbol));
        }
        Arc::new(v)
    }

    fn rat(&self, a: &Atom, vars: &Arc<Vec<PolyVariable>>) -> Rat {
        a.to_rational_polynomial(&Q, &Z, Some(vars.clone()))
    }

    /// Reduces a polynomial modulo c² + s² − 1 for every sin/cos pair:
    /// cⁿ → cⁿ⁻²(1 − s²) until no power of c above 1 is left.
    fn reduce_trig(&self, a: &Atom) -> Atom {
        let mut a = a.expand();
        for (s, c) in &self.trig_pairs {
            let n = symbol!("n__dalembert_pow_");
            let cond = n.restrict(WildcardRestriction::filter(|m: &Match| match m {
                Match::Single(x) => x.to_owned() > Atom::num(1),
                _ => false,
            }));
            let Ok(lhs) = try_parse!(format!("{c}^n__dalembert_pow_").as_str()) else {
                continue;
            };
            let Ok(rhs) = try_parse!(format!("{c}^(n__dalembert_pow_-2)*(1-{s}^2)").as_str())
            else {
                continue;
            };
            for _ in 0..64 {
                let next = a
                    .replace(lhs.clone())
                    .when(&cond)
                    .with(rhs.clone())
                    .expand();
                if next == a {
                    break;
                }
                a = next;
            }
        }
        a
    }

    /// A P entry in lowest terms, sin² + cos² = 1 reduced, functions raised.
    fn simplify(&self, r: &Rat, vars: &Arc<Vec<PolyVariable>>) -> Atom {
        let num = self.reduce_trig(&r.numerator.to_expression());
        let den = self.reduce_trig(&r.denominator.to_expression());
        let reduced = self.rat(&(num / den), vars);
        self.raise(&reduced.to_expression())
    }

    fn reduce_atom(&self, a: &Atom, vars: &Arc<Vec<PolyVariable>>) -> Atom {
        self.simplify(&self.rat(&self.lower(a), vars), vars)
    }

    // ------------------------------------------------------------ numerics

    fn inputs(&self) -> Vec<Atom> {
        self.params
            .iter()
            .chain(&self.coords)
            .chain(&self.vels)
            .map(|s| Atom::from(*s))
            .collect()
    }

    fn sample_inputs(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self.model.params.iter().map(|p| p.value.to_f64()).collect();
        v.extend(sample_configuration(self.coords.len()));
        v.extend(std::iter::repeat_n(0.0, self.vels.len()));
        v
    }

    fn sample_description(&self) -> String {
        self.point_description(&sample_configuration(self.coords.len()))
    }

    /// "m = 1, r = 1/2, x = 0.3, …": the file's parameter values and `q`.
    fn point_description(&self, q: &[f64]) -> String {
        let trim = |x: &f64| {
            let s = format!("{x:.6}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        };
        let params = self
            .model
            .params
            .iter()
            .map(|p| format!("{} = {}", p.name, p.value));
        let coords = self
            .model
            .coordinates
            .iter()
            .zip(q)
            .map(|(c, x)| format!("{c} = {}", trim(x)));
        params.chain(coords).collect::<Vec<_>>().join(", ")
    }

    /// An optimised program for `outputs` in terms of `inputs`.
    fn program(&mut self, outputs: &[Atom], inputs: &[Atom]) -> Option<Program> {
        match program(outputs, inputs) {
            Ok(p) => Some(p),
            Err(e) => {
                self.cx.error(ErrorKind::Symbolic(e), None);
                None
            }
        }
    }

    /// v⁺ component printed as a combination of the velocities.
    fn collect_velocities(&self, c: &Atom) -> String {
        let mut terms = Vec::new();
        let vars = self.var_map();
        for (k, v) in self.vels.iter().enumerate() {
            let coeff = self.reduce_atom(&c.derivative(*v), &vars);
            if is_zero(&coeff) {
                continue;
            }
            let name = &self.model.velocities[k];
            if is_zero(&(coeff.clone() - Atom::num(1))) {
                terms.push(name.clone());
            } else if is_zero(&(coeff.clone() + Atom::num(1))) {
                terms.push(format!("-{name}"));
            } else {
                terms.push(format!("({coeff})*{name}"));
            }
        }
        if terms.is_empty() {
            "0".into()
        } else {
            terms.join(" + ")
        }
    }
}

/// Where G is checked for positive definiteness: qᵢ = 0.3 + 0.41·i
/// (away from the usual coordinate singularities at 0 and π/2 multiples).
pub fn sample_configuration(n: usize) -> Vec<f64> {
    (0..n).map(|i| 0.3 + 0.41 * i as f64).collect()
}

/// Rank by singular values, relative to the largest.
fn numeric_rank(m: &nalgebra::DMatrix<f64>) -> usize {
    if m.nrows() == 0 {
        return 0;
    }
    let sv = m.clone().svd(false, false).singular_values;
    let max = sv.iter().fold(0.0_f64, |a, b| a.max(*b));
    sv.iter().filter(|s| **s > 1e-9 * max.max(1e-300)).count()
}

fn rows_matrix(rows: &[Vec<Rat>], n: usize, field: &Field) -> Option<Matrix<Field>> {
    let flat: Vec<Rat> = rows.iter().flatten().cloned().collect();
    Matrix::from_linear(flat, rows.len() as u32, n as u32, field.clone()).ok()
}

/// Keeps each candidate row that raises the rank (exactly, over the field of
/// rational functions), in order; returns the kept rows and the descriptions
/// of the dropped ones.
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

/// P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B.
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

fn projector(g_inv: &Matrix<Field>, b: &Matrix<Field>) -> Option<Matrix<Field>> {
    let x = g_inv * &b.transpose();
    let m = b * &x;
    let m_inv = m.inv().ok()?;
    Some(&(&x * &m_inv) * b)
}

/// q̈ of G q̈ + h = Aᵀλ, A q̈ + Ȧq̇ = 0, from −h and (A, −Ȧq̇): with
/// z = −G⁻¹h and Y = G⁻¹Aᵀ, (AY)λ = −Ȧq̇ − Az and q̈ = z + Yλ. `None` when
/// AY is singular (dependent rows of A).
fn solve_motion(
    g_inv: &Matrix<Field>,
    constraints: Option<&(Matrix<Field>, Matrix<Field>)>,
    neg_h: &Matrix<Field>,
) -> Option<Matrix<Field>> {
    let z = g_inv * neg_h;
    let Some((a, neg_c)) = constraints else {
        return Some(z);
    };
    let y = g_inv * &a.transpose();
    let lambda = &(a * &y).inv().ok()? * &(neg_c - &(a * &z));
    Some(&z + &(&y * &lambda))
}

fn is_zero(a: &Atom) -> bool {
    let r: Rat = a.expand().to_rational_polynomial(&Q, &Z, None);
    r.numerator.is_zero()
}

fn strings2(m: &[Vec<Atom>]) -> Vec<Vec<String>> {
    m.iter()
        .map(|r| r.iter().map(|a| a.to_string()).collect())
        .collect()
}

/// Builds symbolica's optimised evaluator for `outputs` and converts its
/// instruction list.
fn program(outputs: &[Atom], inputs: &[Atom]) -> Result<Program, String> {
    if outputs.is_empty() {
        return Ok(Program {
            inputs: inputs.len(),
            consts: Vec::new(),
            instrs: Vec::new(),
            outputs: 0,
        });
    }
    let ev = Atom::evaluator_multiple(outputs, inputs)
        .optimization_settings(OptimizationSettings::default())
        .build()
        .map_err(|e| format!("{e:?}"))?;
    let ex = ev.export_instructions();
    let consts: Vec<f64> = ex.constants.iter().map(|c| c.re.to_f64()).collect();
    let slot = |s: &ESlot| -> Result<Slot, String> {
        Ok(match s {
            ESlot::Param(i) => Slot::Input(*i),
            ESlot::Const(i) => Slot::Const(*i),
            ESlot::Temp(i) => Slot::Temp(*i),
            ESlot::Out(i) => Slot::Out(*i),
        })
    };
    let slots = |v: &[ESlot]| v.iter().map(slot).collect::<Result<Vec<_>, _>>();
    let mut instrs = Vec::new();
    for ins in &ex.instructions {
        instrs.push(match ins {
            Instruction::Add(d, s, _) => Instr::Add(slot(d)?, slots(s)?),
            Instruction::Mul(d, s, _) => Instr::Mul(slot(d)?, slots(s)?),
            Instruction::Pow(d, s, n, _) => Instr::Pow(slot(d)?, slot(s)?, *n),
            Instruction::Assign(d, s) => Instr::Assign(slot(d)?, slot(s)?),
            Instruction::Fun(d, call, _) => {
                let (f, _, args) = call.as_ref();
                let name = f.get_stripped_name();
                let func = Func::from_name(name)
                    .ok_or_else(|| format!("unsupported function `{name}` in evaluator"))?;
                let [arg] = args.as_slice() else {
                    return Err(format!("`{name}` takes one argument"));
                };
                Instr::Fun(slot(d)?, func, slot(arg)?)
            }
            other => return Err(format!("unsupported evaluator instruction {other:?}")),
        });
    }
    Ok(Program {
        inputs: inputs.len(),
        consts,
        instrs,
        outputs: ex.output_count,
    })
}

// ---------------------------------------------------------------- for tests and front ends

/// Whether two expressions (in the model's names) are equal as rational
/// functions.
pub fn same(a: &str, b: &str) -> Result<bool, String> {
    crate::lock::acquire()?;
    let a = try_parse!(a)?;
    let b = try_parse!(b)?;
    Ok(is_zero(&(a - b)))
}

/// Evaluates `expr` at the given values with symbolica's own evaluator (an
/// independent path from the emitted code).
pub fn eval(expr: &str, values: &[(&str, f64)]) -> Result<f64, String> {
    crate::lock::acquire()?;
    let e = try_parse!(expr)?;
    let inputs: Vec<Atom> = values
        .iter()
        .map(|(n, _)| Atom::from(symbol!(*n)))
        .collect();
    let ev = Atom::evaluator_multiple(std::slice::from_ref(&e), &inputs)
        .optimization_settings(OptimizationSettings::default())
        .build()
        .map_err(|e| format!("{e:?}"))?;
    let mut ev = ev.map_coeff(&|x| x.re.to_f64());
    let xs: Vec<f64> = values.iter().map(|(_, v)| *v).collect();
    let mut out = [0.0];
    ev.evaluate(&xs, &mut out);
    Ok(out[0])
}

/// `expr` with each named symbol replaced by an expression.
pub fn substitute(expr: &str, subs: &[(&str, &str)]) -> Result<String, String> {
    crate::lock::acquire()?;
    let mut e = try_parse!(expr)?;
    for (name, value) in subs {
        let v = try_parse!(*value)?;
        e = e.replace(Atom::from(symbol!(*name))).with(v);
    }
    Ok(e.to_string())
}

/// `expr` typeset as LaTeX by symbolica's printer.
pub fn latex(expr: &str) -> Result<String, String> {
    crate::lock::acquire()?;
    let e = try_parse!(expr)?;
    Ok(format!("{}", e.printer(PrintOptions::latex())))
}
