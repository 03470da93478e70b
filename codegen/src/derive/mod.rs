//! Stage 2: exact derivation, as named passes. The only part of the
//! generator that uses symbolica.
//!
//! 1. [`symbols`]: names to symbols, definitions substituted;
//! 2. [`mechanics`]: G = ∂²T/∂v², the rows of A, the Lagrange–d'Alembert
//!    equations and each wall's geometry as expressions ([`checks`] run on
//!    each as it is made);
//! 3. [`lower`]: function applications to symbols, so that entries are
//!    rational functions; sin² + cos² = 1 and cosh² − sinh² = 1 reduced;
//! 4. [`walls`]: B, the hypotheses (1.3), P = G⁻¹Bᵀ(BG⁻¹Bᵀ)⁻¹B (Lemma 1,
//!    eq. 2.4) and (I − 2P)v (eq. 2.13), exactly;
//! 5. [`evaluate`]: each emitted function to an optimised straight-line
//!    program (symbolica's evaluator: common subexpressions, Horner), also
//!    with its parameter-only coefficients named first ([`coefficients`]),
//!    the cheaper of the two kept;
//! 6. [`tangents`]: q̈'s and each collision map's program differentiated
//!    forward ([`Program::tangent`], no symbolica).
//!
//! The result is plain data ([`Derivation`]); [`inspect`] has symbolic
//! helpers for front ends and tests.

mod atoms;
mod bounded;
mod budget;
mod build;
mod checks;
mod coefficients;
mod echelon;
mod elimination;
mod evaluate;
pub mod inspect;
mod lower;
mod mechanics;
mod output;
mod probe;
mod sample;
mod symbols;
mod walls;

pub(crate) use build::make_places;
use std::ops::Range;

use symbolica::prelude::*;

use build::Differentiate;

pub use output::{
    Choice, Derivation, Form, Function, Geometry, MotionSystem, Projection, WallDerivation,
};
pub use symbols::sample_configuration;

use crate::diag::{Collector, ErrorKind, ModelErrors, Reported};
use crate::ir::{Kind, Model};
use crate::program::Program;
use crate::quantity::{Quantity, Shape};

type Rat = RationalPolynomial<IntegerRing, u16>;
type Field = RationalPolynomialField<IntegerRing, u16>;

/// Derives everything for `model`. A failure always carries at least one
/// diagnostic.
pub fn derive(model: &Model) -> Result<Derivation, ModelErrors> {
    let mut cx = Collector::new(&model.file, &model.source);
    let result = match crate::lock::acquire() {
        Ok(()) => {
            let _namespace = build::Namespace::enter(&model.source);
            run(model, &mut cx)
        }
        Err(e) => Err(cx.error(ErrorKind::Symbolic(e), None)),
    };
    cx.conclude(result)
}

/// The passes in order.
fn run(model: &Model, cx: &mut Collector) -> Result<Derivation, Reported> {
    let mut sym = symbols::Symbols::new(model, cx)?;
    let raw = mechanics::raw(&sym, cx)?;
    sym.sample = sample::configuration(&sym, &raw);
    let low = lower::Lowering::new(&sym, &raw);
    let exact = mechanics::exact(&sym, &low, &raw, cx)?;
    let t_span = &model.kinetic_energy.span;
    let compile = Compiler {
        inputs: sym.inputs(),
        params: sym.params.len(),
        coords: sym.coords.len(),
        kind: model.kind,
        blame: Blame {
            sym: &sym,
            raw: &raw,
        },
    };
    let g_flat: Vec<Atom> = exact.g.iter().flatten().cloned().collect();
    let mass_matrix = compile.program(cx, Quantity::MassMatrix, &[&g_flat], 0, t_span)?;
    checks::positive_definite(&sym, &raw, cx, &mass_matrix.program);
    let g_inv = exact.inverse(&sym, cx)?;
    let context = walls::Context {
        sym: &sym,
        low: &low,
        raw: &raw,
        exact: &exact,
        g_inv: g_inv.as_ref(),
        compile: &compile,
    };
    let walls = walls::derive(&context, cx)?;
    let accelerations = mechanics::accelerations(&sym, &low, &raw, &exact, g_inv.as_ref(), cx)?;
    let a_flat: Vec<Atom> = raw.a_rows.iter().flatten().cloned().collect();
    let mut functions = vec![Some(mass_matrix)];
    let reduced_t = (low.reduce_or_keep(&raw.t))
        .map_err(|o| o.report(cx, t_span, &lower::reduced("the kinetic energy")))?;
    let v_span = model.potential.as_ref().map_or(t_span, |v| &v.span);
    let reduced_v = (low.reduce_or_keep(&raw.v))
        .map_err(|o| o.report(cx, v_span, &lower::reduced("the potential")))?;
    // A's rows and their rates as written, or reduced where that is
    // cheaper: a rolling disk's rows divide by its centre's height, which
    // the reduction cancels.
    let or_reduced = |outputs: Vec<Atom>| {
        low.evaluated_forms(outputs.clone())
            .unwrap_or_else(|_| vec![outputs])
    };
    for (quantity, forms, rows) in [
        (Quantity::KineticEnergy, vec![vec![reduced_t]], 0),
        (Quantity::Potential, vec![vec![reduced_v]], 0),
        (Quantity::Constraints, or_reduced(a_flat), raw.a_rows.len()),
        (
            Quantity::Holonomic,
            vec![raw.holonomic.clone()],
            raw.holonomic.len(),
        ),
        (Quantity::Forcing, vec![raw.forcing.clone()], 0),
        (Quantity::ConstraintDrift, or_reduced(raw.drift.clone()), 0),
    ] {
        let forms: Vec<&[Atom]> = forms.iter().map(|f| &f[..]).collect();
        functions.push(compile.applicable_of(cx, quantity, &forms, rows, t_span)?);
    }
    let mut motion_systems = Vec::new();
    let moving = model.kind == Kind::Coordinates && raw.drift.len() >= raw.a_rows.len();
    // Without constraint rows Taylor's method may solve G per order instead
    // of following q̈'s own program, closed form or not: the systems of h
    // and of the momentum, for `Derivation::series` to weigh.
    let unconstrained = moving && raw.a_rows.is_empty();
    match &accelerations {
        Some(x) => {
            functions.push(compile.applicable(cx, Quantity::Accelerations, x, 0, t_span)?);
            // h's system only: beside the closed form, the elimination's
            // own q̈ is not emitted.
            if unconstrained
                && let Some((_, system)) = elimination::motion(&exact, &raw, &compile, cx, t_span)?
            {
                motion_systems.push(system);
            }
        }
        // No exact closed form (a dense G): the solve written out.
        None if moving => {
            if let Some((f, system)) = elimination::motion(&exact, &raw, &compile, cx, t_span)? {
                functions.push(Some(f));
                motion_systems.push(system);
            }
        }
        None => {}
    }
    // The momentum's system wherever h's is (G's pivots are not
    // structurally zero).
    if unconstrained && !motion_systems.is_empty() {
        let gradient = mechanics::lagrangian_gradient(&sym, &raw);
        let m = elimination::momentum(&exact, &gradient, &compile, cx, t_span)?;
        motion_systems.extend(m);
    }
    functions.push(initial_state(&sym, &compile, cx)?);
    functions.extend(start_rates(&sym, &compile, cx)?);
    let mut functions = functions.into_iter().flatten().collect();
    let mut walls = walls;
    let dims = (
        sym.params.len(),
        model.coordinates.len(),
        model.velocities.len(),
    );
    let (tangents_left_out, parameter_tangents_left_out) =
        tangents(&mut functions, &mut walls, dims);
    Ok(Derivation {
        model: model.clone(),
        mass_matrix: strings(&exact.g),
        constraint_rows: strings(&raw.a_rows),
        holonomic: raw.holonomic.iter().map(|h| h.to_string()).collect(),
        accelerations: accelerations.map(|x| x.iter().map(|a| a.to_string()).collect()),
        walls,
        functions,
        tangents_left_out,
        parameter_tangents_left_out,
        motion_systems,
    })
}

/// Pass 6: the tangent functions, each placed after the function it
/// differentiates: q̈'s and each collision map's program differentiated
/// forward along the phase (the inputs after the `params` parameters), then
/// along the parameters with each wall's f (what a collision instant's
/// dependence on them needs). Each group is about three times the code of
/// what it differentiates: where the phase's would take the model past
/// [`crate::MAX_GENERATED_INSTRUCTIONS`], all are left out (the model then
/// has no derivatives, and its header says why; a model past the bound
/// without them is refused as before); where only the parameters' would,
/// those are. A model without parameters has no tangents along them.
/// Returns the instructions each left-out case would have added: (all
/// tangents, the parameters' alone).
fn tangents(
    functions: &mut Vec<Function>,
    walls: &mut [WallDerivation],
    (params, nq, nv): (usize, usize, usize),
) -> (Option<usize>, Option<usize>) {
    // (differentiated, tangent), for the model and for each wall: along
    // the phase, then along the parameters.
    type Rows = &'static [(Quantity, Quantity)];
    const PHASE: (Rows, Rows) = (
        &[(Quantity::Accelerations, Quantity::AccelerationsTangent)],
        &[(Quantity::Collide, Quantity::CollideTangent)],
    );
    const PARAMETERS: (Rows, Rows) = (
        &[(
            Quantity::Accelerations,
            Quantity::AccelerationsParameterTangent,
        )],
        &[
            (Quantity::Collide, Quantity::CollideParameterTangent),
            (Quantity::Surface, Quantity::SurfaceParameterTangent),
        ],
    );
    let group = |functions: &[Function], walls: &[WallDerivation], (model, wall): (Rows, Rows)| {
        let make = |list: &[Function], rows: Rows| -> Vec<Function> {
            rows.iter()
                .filter_map(|&(of, quantity)| {
                    let f = list.iter().find(|f| f.quantity == of)?;
                    let source = (f.program).with_inputs(of.spec().inputs.width(params, nq, nv));
                    let program = match quantity {
                        Quantity::AccelerationsTangent | Quantity::CollideTangent => {
                            source.tangent(params)
                        }
                        _ => source.tangent_over(0..params),
                    };
                    Some(Function {
                        quantity,
                        program,
                        rows: 0,
                    })
                })
                .collect()
        };
        let per_wall: Vec<_> = walls.iter().map(|w| make(&w.functions, wall)).collect();
        (make(functions, model), per_wall)
    };
    let size = |fs: &[Function]| fs.iter().map(|f| f.program.instrs.len()).sum::<usize>();
    let total = |(model, walls): &(Vec<Function>, Vec<Vec<Function>>)| {
        size(model) + walls.iter().map(|fs| size(fs)).sum::<usize>()
    };
    let phase = group(functions, walls, PHASE);
    let by_parameters = if params == 0 {
        // Nothing to differentiate by.
        (Vec::new(), vec![Vec::new(); walls.len()])
    } else {
        group(functions, walls, PARAMETERS)
    };
    let now = size(functions) + walls.iter().map(|w| size(&w.functions)).sum::<usize>();
    let bound = crate::MAX_GENERATED_INSTRUCTIONS;
    let (phase_size, parameters_size) = (total(&phase), total(&by_parameters));
    if now + phase_size > bound {
        return (Some(phase_size + parameters_size), None);
    }
    let mut place = |(model, per_wall): (Vec<Function>, Vec<Vec<Function>>), rows: (Rows, Rows)| {
        insert_after_sources(functions, model, rows.0);
        for (w, fs) in walls.iter_mut().zip(per_wall) {
            insert_after_sources(&mut w.functions, fs, rows.1);
        }
    };
    place(phase, PHASE);
    if now + phase_size + parameters_size > bound {
        return (None, Some(parameters_size));
    }
    place(by_parameters, PARAMETERS);
    (None, None)
}

/// Each tangent placed after the function it differentiates (and after
/// that function's tangents placed before it).
fn insert_after_sources(
    list: &mut Vec<Function>,
    tangents: Vec<Function>,
    rows: &[(Quantity, Quantity)],
) {
    let is_tangent = |f: &Function| {
        let spec = f.quantity.spec();
        matches!(spec.shape, Shape::Tangent | Shape::ScalarTangent)
    };
    for t in tangents {
        let of = rows.iter().find(|r| r.1 == t.quantity).map(|r| r.0);
        let source = list.iter().position(|f| Some(f.quantity) == of);
        let after = source.map_or(list.len(), |i| {
            i + 1 + list[i + 1..].iter().take_while(|f| is_tangent(f)).count()
        });
        list.insert(after, t);
    }
}

/// The `[initial]` state as a function of the parameters, so that it
/// follows them (zero where the file is silent).
fn initial_state(
    sym: &symbols::Symbols,
    compile: &Compiler,
    cx: &mut Collector,
) -> Result<Option<Function>, Reported> {
    let exprs = &sym.model.initial_state;
    let mut outputs = Vec::with_capacity(exprs.len());
    for e in exprs {
        outputs.push(match e {
            Some(e) => sym.parse(e, cx)?,
            None => Atom::num(0),
        });
    }
    let span = exprs
        .iter()
        .flatten()
        .next()
        .map_or(&sym.model.kinetic_energy.span, |e| &e.span);
    compile.applicable(cx, Quantity::InitialState, &outputs, 0, span)
}

/// The conditions `[initial]` puts on rates that are not velocities: each
/// named definition's row L(q) (it must be linear in the velocities, as a
/// constraint) and its value as a function of the parameters. Nothing for
/// a file without them.
fn start_rates(
    sym: &symbols::Symbols,
    compile: &Compiler,
    cx: &mut Collector,
) -> Result<Vec<Option<Function>>, Reported> {
    let rates = &sym.model.start_rates;
    let Some(first) = rates.first() else {
        return Ok(Vec::new());
    };
    let (mut rows, mut values) = (Vec::new(), Vec::new());
    for r in rates {
        let e = sym.parse(&r.rate, cx)?;
        let what = format!("[initial] `{}`", r.name);
        rows.extend(checks::linear_row(sym, cx, &e, &r.rate.span, &what)?);
        values.push(sym.parse(&r.value, cx)?);
    }
    let k = rates.len();
    Ok(vec![
        compile.applicable(cx, Quantity::StartRows, &rows, k, &first.rate.span)?,
        compile.applicable(cx, Quantity::StartValues, &values, k, &first.value.span)?,
    ])
}

/// Turns expressions into the emitted functions of one model.
pub(crate) struct Compiler<'a> {
    inputs: Vec<Atom>,
    /// How many of the inputs are parameters (they come first), and how
    /// many coordinates follow them.
    params: usize,
    coords: usize,
    kind: Kind,
    blame: Blame<'a>,
}

/// Where a failure to compile a quantity is reported. Each quantity has
/// a declaration to report at (q̈, h and Ȧq̇, which come from several, at
/// the kinetic energy; a wall's at the wall), but a constant that
/// overflows only once V or a constraint is differentiated (`10^308*y^2`:
/// its gradient's 2·10^308) belongs to that declaration wherever it
/// surfaces. So on a failure V's and the constraints' own derivatives are
/// compiled alone, and the first that fails takes the error; else the
/// quantity's own place does. Only on the failure path: a model that
/// derives compiles nothing more.
struct Blame<'a> {
    sym: &'a symbols::Symbols<'a>,
    raw: &'a mechanics::Raw,
}

impl Blame<'_> {
    /// The place for a failure first reported at `span`.
    fn place(&self, span: &Range<usize>) -> Range<usize> {
        let (model, raw) = (self.sym.model, self.raw);
        let fails = |derived: &[Atom]| evaluate::program(derived, &self.sym.inputs()).is_err();
        if let Some(v) = &model.potential {
            let mut derived = vec![raw.v.clone()];
            derived.extend(self.sym.coords.iter().map(|q| raw.v.d(*q)));
            if fails(&derived) {
                return v.span.clone();
            }
        }
        // A's rows: each holonomic constraint's dh, then the velocity-level
        // constraints, each with its Ȧq̇.
        let declared = model.holonomic.iter().chain(&model.constraints);
        for (i, e) in declared.enumerate() {
            let mut derived = raw.a_rows.get(i).cloned().unwrap_or_default();
            derived.extend(raw.drift.get(i).cloned());
            derived.extend(raw.holonomic.get(i).cloned());
            if fails(&derived) {
                return e.span.clone();
            }
        }
        span.clone()
    }
}

impl Compiler<'_> {
    /// The function for `quantity`: the cheapest program of every form of
    /// its outputs (`rows` of them in use, for rows and values); a failure
    /// is reported at `span`.
    fn program(
        &self,
        cx: &mut Collector,
        quantity: Quantity,
        forms: &[&[Atom]],
        rows: usize,
        span: &Range<usize>,
    ) -> Result<Function, Reported> {
        let mut candidates = Vec::new();
        for outputs in forms {
            candidates.extend(
                evaluate::programs(outputs, &self.inputs, self.params)
                    .map_err(|e| cx.error(ErrorKind::Symbolic(e), Some(self.blame.place(span))))?,
            );
        }
        Ok(Function {
            quantity,
            program: self.cheapest(quantity, candidates),
            rows,
        })
    }

    /// The cheapest of programs that compute the same outputs, the first
    /// on a tie: per call (parameter-only work done once) for every
    /// function but q̈. Taylor's method spends its time in q̈'s series,
    /// where a convolution costs a loop over the orders so far and any
    /// other series operation one step, so for q̈ the series' work at the
    /// default tolerance's order, 20 ([`Transform::cost`]; the simulator
    /// may step at a higher one), decides first, then the per-call cost.
    ///
    /// [`Transform::cost`]: crate::program::Transform::cost
    fn cheapest(&self, quantity: Quantity, candidates: Vec<Program>) -> Program {
        let per_call = |p: &Program| p.split(self.params, 0).op_counts(p).0.cost();
        let order = dalembert_runtime::simulate::Taylor::default().order();
        let key = |p: &Program| match quantity {
            Quantity::Accelerations => {
                (p.taylor(self.params, self.coords).cost(order), per_call(p))
            }
            _ => (0, per_call(p)),
        };
        candidates
            .into_iter()
            .min_by_key(key)
            .expect("at least one program")
    }

    /// As [`Compiler::program`], where the model has the quantity (an
    /// instantaneous model has no motion and no surfaces).
    pub(crate) fn applicable(
        &self,
        cx: &mut Collector,
        quantity: Quantity,
        outputs: &[Atom],
        rows: usize,
        span: &Range<usize>,
    ) -> Result<Option<Function>, Reported> {
        self.applicable_of(cx, quantity, &[outputs], rows, span)
    }

    /// As [`Compiler::applicable`], of the cheapest of several forms of
    /// the same outputs (the first on a tie).
    pub(crate) fn applicable_of(
        &self,
        cx: &mut Collector,
        quantity: Quantity,
        forms: &[&[Atom]],
        rows: usize,
        span: &Range<usize>,
    ) -> Result<Option<Function>, Reported> {
        if self.kind == Kind::Instantaneous && !quantity.spec().capability.instantaneous() {
            return Ok(None);
        }
        self.program(cx, quantity, forms, rows, span).map(Some)
    }
}

/// Whether `a` is zero as a rational function (a value at a point first,
/// which settles most "no"s without the expansion).
fn is_zero(a: &Atom) -> bool {
    if probe::nonzero(a) {
        return false;
    }
    let r: Rat = a.expand().to_rational_polynomial(&Q, &Z, None);
    r.numerator.is_zero()
}

/// Rows as an exact matrix.
fn rows_matrix(rows: &[Vec<Rat>], n: usize, field: &Field) -> Option<Matrix<Field>> {
    let flat: Vec<Rat> = rows.iter().flatten().cloned().collect();
    Matrix::from_linear(flat, rows.len() as u32, n as u32, field.clone()).ok()
}

/// Entries as text.
fn strings(m: &[Vec<Atom>]) -> Vec<Vec<String>> {
    m.iter()
        .map(|r| r.iter().map(|a| a.to_string()).collect())
        .collect()
}
