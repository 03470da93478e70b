//! Pass 4b: each wall's collision map written out by elimination, over one
//! program for G and B, and the choice between it and the exact closed
//! forms by per-call cost; and q̈ written out the same way where it has no
//! exact closed form (a dense G).

use std::ops::Range;

use symbolica::prelude::*;

use super::mechanics::{Exact, Raw};
use super::output::{Choice, Form, Function, MotionSystem};
use super::symbols::Symbols;
use super::{Compiler, is_zero};
use crate::diag::{Collector, Reported};
use crate::program::Layout;
use crate::quantity::Quantity;

/// The outputs of one program: the entries that are not identically zero,
/// each placed once.
#[derive(Default)]
struct Outputs(Vec<Atom>);

impl Outputs {
    fn place(&mut self, a: &Atom) -> Option<usize> {
        (!is_zero(a)).then(|| {
            self.0.push(a.clone());
            self.0.len() - 1
        })
    }

    /// G's lower triangle and `rows`, placed.
    fn layout(&mut self, exact: &Exact, rows: &[Vec<Atom>]) -> Layout {
        let n = exact.g.len();
        let mut g = Vec::with_capacity(n * (n + 1) / 2);
        for i in 0..n {
            for j in 0..=i {
                g.push(self.place(&exact.g[i][j]));
            }
        }
        let rows = rows
            .iter()
            .map(|r| r.iter().map(|a| self.place(a)).collect())
            .collect();
        Layout { n, g, rows }
    }
}

/// A wall's collision map by elimination over B's rows, the cheaper of
/// its `forms` (each zero in the same entries, so that one layout places
/// them all). `None` where the model has no such function or a pivot is
/// structurally zero.
pub fn collision(
    sym: &Symbols,
    exact: &Exact,
    compile: &Compiler<'_>,
    cx: &mut Collector,
    forms: &[Vec<Vec<Atom>>],
    span: &Range<usize>,
) -> Result<Option<Function>, Reported> {
    let placed: Vec<(Outputs, Layout)> = (forms.iter())
        .map(|b| {
            let mut outputs = Outputs::default();
            let layout = outputs.layout(exact, b);
            (outputs, layout)
        })
        .collect();
    let layout = placed[0].1.clone();
    debug_assert!(placed.iter().all(|(_, l)| *l == layout));
    let outputs: Vec<&[Atom]> = placed.iter().map(|(o, _)| &o.0[..]).collect();
    let Some(f) = compile.applicable_of(cx, Quantity::Collide, &outputs, 0, span)? else {
        return Ok(None);
    };
    let v = sym.params.len() + sym.coords.len();
    Ok(f.program
        .reflect_by_elimination(&layout, v)
        .map(|program| Function { program, ..f }))
}

/// q̈ of G q̈ + h = Aᵀλ, A q̈ + Ȧq̇ = 0 by elimination (G = LDLᵀ and the
/// constrained solve written out over one program for G, A, h and Ȧq̇), for
/// a model whose q̈ has no exact closed form, with that program and where
/// it places G and h (Taylor's method may solve per order instead; beside a
/// closed form only that system is kept). `None` where a pivot is
/// structurally zero.
pub fn motion(
    exact: &Exact,
    raw: &Raw,
    compile: &Compiler<'_>,
    cx: &mut Collector,
    span: &Range<usize>,
) -> Result<Option<(Function, MotionSystem)>, Reported> {
    let mut outputs = Outputs::default();
    let layout = outputs.layout(exact, &raw.a_rows);
    let forcing: Vec<Option<usize>> = raw.forcing.iter().map(|h| outputs.place(h)).collect();
    let drift: Vec<Option<usize>> = raw
        .drift
        .iter()
        .take(raw.a_rows.len())
        .map(|c| outputs.place(c))
        .collect();
    let Some(f) = compile.applicable(cx, Quantity::Accelerations, &outputs.0, 0, span)? else {
        return Ok(None);
    };
    Ok(f.program
        .motion_by_elimination(&layout, &forcing, &drift)
        .map(|program| {
            let system = MotionSystem {
                program: f.program.clone(),
                layout,
                rhs: forcing,
                momentum: false,
            };
            (Function { program, ..f }, system)
        }))
}

/// Without constraints, the motion as G q̇ = p with ṗ = ∂L/∂q: one program
/// for G's lower triangle and `gradient` (∂L/∂q, entry by entry).
pub fn momentum(
    exact: &Exact,
    gradient: &[Atom],
    compile: &Compiler<'_>,
    cx: &mut Collector,
    span: &Range<usize>,
) -> Result<Option<MotionSystem>, Reported> {
    let mut outputs = Outputs::default();
    let layout = outputs.layout(exact, &[]);
    let rhs: Vec<Option<usize>> = gradient.iter().map(|f| outputs.place(f)).collect();
    let Some(f) = compile.applicable(cx, Quantity::Accelerations, &outputs.0, 0, span)? else {
        return Ok(None);
    };
    Ok(Some(MotionSystem {
        program: f.program,
        layout,
        rhs,
        momentum: true,
    }))
}

/// The cheapest candidate per call (parameter-only work done once, as
/// emitted), with every candidate's cost; the first listed wins a tie.
pub fn choose(params: usize, candidates: Vec<(Form, Function)>) -> Option<(Choice, Function)> {
    let costs: Vec<(Form, usize)> = candidates
        .iter()
        .map(|(form, f)| {
            let split = f.program.split(params, 0);
            (*form, split.op_counts(&f.program).0.cost())
        })
        .collect();
    let best = (0..candidates.len()).min_by_key(|&k| costs[k].1)?;
    let (form, f) = candidates.into_iter().nth(best)?;
    Some((Choice { form, costs }, f))
}
