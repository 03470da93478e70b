//! Pass 5: expressions to straight-line programs by symbolica's evaluator
//! optimisation (common subexpressions, Horner schemes), converted to the
//! generator's own [`Program`], which later stages use without symbolica.
//!
//! The evaluator's program (its groupings of sums and products, not only
//! the order of its instructions) depends on the symbols it is given, not
//! only on the expressions' structure, and so does the order symbolica
//! keeps the terms of a sum in, which the naming of coefficients walks: a
//! model derived in one process after others came out with other
//! groupings than alone. So every expression is first written in places
//! ([`place`]): symbols made once per process, before any other symbol of
//! ours, and the same in every process. Input `i` of a program is place
//! `2 + i`, π and e are places 0 and 1, and what the pass names on the way
//! (coefficients, applications of the functions of ours) takes the places
//! after the inputs. A model's programs then depend on the model alone,
//! whatever the process derived before.

use std::collections::HashMap;

use symbolica::evaluate::{Instruction, Slot as ESlot};
use symbolica::prelude::*;

use super::atoms::{argument, children};
use super::build::{constant_symbol, own_functions, place};
use super::coefficients;
use crate::ir::Constant;
use crate::program::{Function, Instr, Program, Slot};

/// The place of π, and the place of e ([`place`]).
const PI: usize = 0;
const E: usize = 1;
/// The place of input 0.
const FIRST_INPUT: usize = 2;

/// The places of `n` inputs.
fn input_places(n: usize) -> Vec<Symbol> {
    (FIRST_INPUT..FIRST_INPUT + n).map(place).collect()
}

/// Programs for `outputs` (inputs: the `params` parameters first, then
/// the coordinates and velocities): the evaluator's over the expressions as
/// they are, then, where they have parameter-only coefficients to name, its
/// over the expressions with those named ([`coefficients`]), preceded by
/// the program of the coefficients. The caller keeps the cheaper.
pub fn programs(outputs: &[Atom], inputs: &[Atom], params: usize) -> Result<Vec<Program>, String> {
    let outputs = placed(outputs, inputs)?;
    let plain = program_in_places(&outputs, inputs.len())?;
    let places = input_places(inputs.len());
    let first_name = FIRST_INPUT + inputs.len();
    let named = coefficients::name(&outputs, &places[params..], |k| place(first_name + k));
    if named.symbols.is_empty() {
        return Ok(vec![plain]);
    }
    let first = program_in_places(&named.coefficients, params)?;
    let all_inputs = inputs.len() + named.symbols.len();
    let then = program_in_places(&named.outputs, all_inputs)?.fed_by(&first, inputs.len());
    Ok(vec![plain, then])
}

/// An optimised program for `outputs` in terms of `inputs` (symbols).
pub fn program(outputs: &[Atom], inputs: &[Atom]) -> Result<Program, String> {
    program_in_places(&placed(outputs, inputs)?, inputs.len())
}

/// `outputs` written in places: `inputs[i]` as place `2 + i`, π and e (ours
/// and symbolica's) as places 0 and 1.
fn placed(outputs: &[Atom], inputs: &[Atom]) -> Result<Vec<Atom>, String> {
    let mut to = HashMap::with_capacity(inputs.len() + 4);
    for (input, p) in inputs.iter().zip(input_places(inputs.len())) {
        let AtomView::Var(v) = input.as_view() else {
            return Err(format!(
                "an input of the evaluator is not a symbol: {input}"
            ));
        };
        to.insert(v.get_symbol(), Atom::from(p));
    }
    for (c, ours, theirs) in [(PI, Constant::Pi, Symbol::PI), (E, Constant::E, Symbol::E)] {
        to.insert(constant_symbol(ours), Atom::from(place(c)));
        to.insert(theirs, Atom::from(place(c)));
    }
    Ok(outputs.iter().map(|o| renamed(o.as_view(), &to)).collect())
}

/// `a` with each symbol in `to` replaced by its image.
fn renamed(a: AtomView, to: &HashMap<Symbol, Atom>) -> Atom {
    match a {
        AtomView::Var(v) => to
            .get(&v.get_symbol())
            .cloned()
            .unwrap_or_else(|| a.to_owned()),
        AtomView::Fun(f) => {
            let args: Vec<Atom> = f.iter().map(|x| renamed(x, to)).collect();
            FunctionBuilder::new(f.get_symbol())
                .add_args(&args)
                .finish()
        }
        AtomView::Add(s) => s.iter().fold(Atom::num(0), |acc, x| acc + renamed(x, to)),
        AtomView::Mul(m) => m.iter().fold(Atom::num(1), |acc, x| acc * renamed(x, to)),
        AtomView::Pow(p) => {
            let (b, e) = p.get_base_exp();
            renamed(b, to).pow(renamed(e, to))
        }
        _ => a.to_owned(),
    }
}

/// An optimised program for `outputs`, written in places, in terms of the
/// first `inputs` input places.
///
/// symbolica's evaluator knows sin, cos, exp and log; the functions of ours
/// ([`own_functions`]) reach it as values: each application whose argument
/// has none of them becomes a new input (the places after the inputs),
/// computed before by a program of its own (the arguments, then a call of
/// the function on each), and so on outwards through nested applications.
fn program_in_places(outputs: &[Atom], inputs: usize) -> Result<Program, String> {
    let ours: Vec<Symbol> = own_functions().collect();
    // Applications computed so far, each with the place standing for it.
    let mut known: Vec<(Atom, Symbol)> = Vec::new();
    let replaced = |a: &Atom, known: &[(Atom, Symbol)]| {
        // Innermost first: each was found with the earlier ones replaced.
        known.iter().fold(a.clone(), |a, (app, s)| {
            a.replace(app.clone()).with(Atom::from(*s))
        })
    };
    let mut stage: Option<Program> = None;
    loop {
        let mut ready: Vec<(Atom, Function)> = Vec::new();
        for o in outputs {
            innermost(replaced(o, &known).as_view(), &ours, &mut ready);
        }
        if ready.is_empty() {
            break;
        }
        let mut unique: Vec<(Atom, Function)> = Vec::new();
        for r in ready {
            if !unique.iter().any(|u| u.0 == r.0) {
                unique.push(r);
            }
        }
        // This stage: the values so far passed on, then each argument,
        // each then replaced by its function's value.
        let mut stage_outputs: Vec<Atom> = known.iter().map(|(_, s)| Atom::from(*s)).collect();
        stage_outputs.extend(unique.iter().map(|(app, _)| argument(app)));
        let mut p = plain_program(&stage_outputs, inputs + known.len())?;
        for (k, (_, f)) in unique.iter().enumerate() {
            let out = Slot::Out(known.len() + k);
            p.instrs.push(Instr::Fun(out, *f, out));
        }
        stage = Some(match stage {
            None => p,
            Some(first) => p.fed_by(&first, inputs),
        });
        for (app, _) in unique {
            let s = place(FIRST_INPUT + inputs + known.len());
            known.push((app, s));
        }
    }
    let Some(first) = stage else {
        return plain_program(outputs, inputs);
    };
    let outputs: Vec<Atom> = outputs.iter().map(|o| replaced(o, &known)).collect();
    Ok(plain_program(&outputs, inputs + known.len())?.fed_by(&first, inputs))
}

/// The applications of the functions `ours` in `a` whose argument has none
/// of them, each with its function.
fn innermost(a: AtomView, ours: &[Symbol], out: &mut Vec<(Atom, Function)>) {
    let parts = children(a);
    if let AtomView::Fun(f) = a
        && ours.contains(&f.get_symbol())
        && !parts.iter().any(|x| contains_own(*x, ours))
    {
        let symbol = f.get_symbol();
        let func = Function::from_name(symbol.get_stripped_name()).expect("a function of ours");
        out.push((a.to_owned(), func));
        return;
    }
    parts.into_iter().for_each(|x| innermost(x, ours, out));
}

/// Whether `a` applies one of the functions `ours`.
fn contains_own(a: AtomView, ours: &[Symbol]) -> bool {
    matches!(a, AtomView::Fun(f) if ours.contains(&f.get_symbol()))
        || children(a).into_iter().any(|x| contains_own(x, ours))
}

/// [`program_in_places`] for outputs in the functions symbolica's
/// evaluator knows. π and e (places 0 and 1) enter as two extra inputs,
/// which become constants of the program with their values; every
/// constant is checked to be a finite real number.
fn plain_program(outputs: &[Atom], inputs: usize) -> Result<Program, String> {
    if outputs.is_empty() {
        return Ok(Program {
            inputs,
            consts: Vec::new(),
            instrs: Vec::new(),
            outputs: 0,
        });
    }
    let constants = [Constant::Pi, Constant::E];
    let mut all_inputs: Vec<Atom> = input_places(inputs).into_iter().map(Atom::from).collect();
    all_inputs.extend([PI, E].map(|c| Atom::from(place(c))));
    let ev = Atom::evaluator_multiple(outputs, &all_inputs)
        .optimization_settings(OptimizationSettings::default())
        .build()
        .map_err(|e| format!("{e:?}"))?;
    let ex = ev.export_instructions();
    let mut consts = Vec::with_capacity(ex.constants.len() + 2);
    for c in &ex.constants {
        let (re, im) = (c.re.to_f64(), c.im.to_f64());
        if im != 0.0 {
            return Err(format!(
                "the expression is not real (a constant {re} + {im}i)"
            ));
        }
        if !re.is_finite() {
            return Err("a constant of the expression is too large for f64 (or infinite)".into());
        }
        consts.push(re);
    }
    // The extra inputs become the last constants.
    let first_constant = consts.len();
    consts.extend(constants.map(Constant::value));
    let slot = |s: &ESlot| match s {
        ESlot::Param(i) if *i >= inputs => Slot::Const(first_constant + i - inputs),
        ESlot::Param(i) => Slot::Input(*i),
        ESlot::Const(i) => Slot::Const(*i),
        ESlot::Temp(i) => Slot::Temp(*i),
        ESlot::Out(i) => Slot::Out(*i),
    };
    let slots = |v: &[ESlot]| v.iter().map(slot).collect::<Vec<_>>();
    // Temporaries past the evaluator's own, for what one of its
    // instructions becomes in several.
    let mut fresh = ex
        .instructions
        .iter()
        .flat_map(|ins| match ins {
            Instruction::Add(d, s, _) | Instruction::Mul(d, s, _) => {
                std::iter::once(d).chain(s.iter()).collect::<Vec<_>>()
            }
            Instruction::Pow(d, s, _, _) | Instruction::Assign(d, s) => vec![d, s],
            Instruction::Powf(d, s, e, _) => vec![d, s, e],
            Instruction::Fun(d, call, _) => std::iter::once(d).chain(call.2.iter()).collect(),
            // (Refused below.)
            _ => Vec::new(),
        })
        .filter_map(|s| match s {
            ESlot::Temp(i) => Some(*i + 1),
            _ => None,
        })
        .max()
        .unwrap_or(0);
    let mut instrs = Vec::new();
    for ins in &ex.instructions {
        let one = match ins {
            Instruction::Add(d, s, _) => Instr::Add(slot(d), slots(s)),
            Instruction::Mul(d, s, _) => Instr::Mul(slot(d), slots(s)),
            Instruction::Pow(d, s, n, _) => Instr::Pow(slot(d), slot(s), *n),
            Instruction::Powf(d, s, e, _) => match (slot(s), slot(e)) {
                (_, Slot::Const(k)) => Instr::Powf(slot(d), slot(s), consts[k]),
                // symbolica writes exp(x) as e^x.
                (Slot::Const(k), x) if k == first_constant + 1 => {
                    Instr::Fun(slot(d), Function::Exp, x)
                }
                // b^x with x varying (symbolica's form of exp(x·log b)):
                // written back as exp(x·log b), in the functions the
                // language has.
                (b, x) => {
                    let (log, product) = (Slot::Temp(fresh), Slot::Temp(fresh + 1));
                    fresh += 2;
                    instrs.push(Instr::Fun(log, Function::Log, b));
                    instrs.push(Instr::Mul(product, vec![x, log]));
                    Instr::Fun(slot(d), Function::Exp, product)
                }
            },
            Instruction::Assign(d, s) => Instr::Assign(slot(d), slot(s)),
            Instruction::Fun(d, call, _) => {
                let (f, _, args) = call.as_ref();
                let name = f.get_stripped_name();
                let func = Function::from_name(name)
                    .ok_or_else(|| format!("unsupported function `{name}` in evaluator"))?;
                let [arg] = args.as_slice() else {
                    return Err(format!("`{name}` takes one argument"));
                };
                Instr::Fun(slot(d), func, slot(arg))
            }
            other => return Err(format!("unsupported evaluator instruction {other:?}")),
        };
        instrs.push(one);
    }
    Ok(Program {
        inputs,
        consts,
        instrs,
        outputs: ex.output_count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::derive::build::{Namespace, own_symbol};

    /// A power with a varying exponent, alone and among functions whose
    /// results take the evaluator's temporaries, evaluates as exp(x·log y):
    /// the temporaries it is written in are fresh.
    #[test]
    fn varying_exponents_are_exp_of_log() {
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("evaluate test");
        let [x, y] = ["x", "y"].map(|n| Atom::from(own_symbol(n)));
        let power = function!(Symbol::EXP, &x * function!(Symbol::LOG, &y));
        let sin_xy = function!(Symbol::SIN, &x * &y);
        let outputs = [
            power.clone(),
            function!(Symbol::SIN, &power + function!(Symbol::COS, &x * &y)) * &power
                + function!(Symbol::SIN, &x),
            // A function's result read after the power.
            &power * &sin_xy + &sin_xy,
        ];
        let p = program(&outputs, &[x, y]).unwrap();
        for (a, b) in [(0.3, 1.7), (-1.2, 0.4), (2.5, 3.0)] {
            let z = f64::powf(b, a);
            let s = (a * b).sin();
            let want = [z, (z + (a * b).cos()).sin() * z + a.sin(), z * s + s];
            let got = p.eval(&[a, b]);
            for (g, w) in got.iter().zip(want) {
                // (sin of 16 carries the rounding of z, about 1e-15, times 16.)
                assert!(
                    (g - w).abs() <= 1e-12 * w.abs().max(1.0),
                    "{got:?} against {want:?}"
                );
            }
        }
    }

    /// The functions symbolica does not know reach the program as calls,
    /// nested ones outwards from the innermost, each computed once; their
    /// derivatives are written out by their rules.
    #[test]
    fn functions_of_ours_and_their_derivatives() {
        use crate::derive::build::{Differentiate, own_functions};
        crate::lock::acquire().unwrap();
        let _ns = Namespace::enter("functions of ours test");
        let [x, y] = ["x", "y"].map(|n| Atom::from(own_symbol(n)));
        let [atan, asin, acos, sinh, cosh, tanh] = {
            let v: Vec<Symbol> = own_functions().collect();
            [v[0], v[1], v[2], v[3], v[4], v[5]]
        };
        let third = Atom::num(1) / Atom::num(3);
        let e = function!(atan, function!(tanh, &x * &y) + &x)
            + function!(asin, &x * &third) * function!(cosh, &y)
            + function!(acos, &y * &third) * function!(sinh, &x * &x)
            + function!(tanh, &x * &y);
        let outputs = [e.clone(), e.d(own_symbol("x")), e.d(own_symbol("y"))];
        let p = program(&outputs, &[x, y]).unwrap();
        let calls = p
            .instrs
            .iter()
            .filter(|i| matches!(i, Instr::Fun(_, Function::Tanh, _)))
            .count();
        assert_eq!(calls, 1, "tanh(xy) computed once");
        let f = |a: f64, b: f64| {
            ((a * b).tanh() + a).atan()
                + (a / 3.0).asin() * b.cosh()
                + (b / 3.0).acos() * (a * a).sinh()
                + (a * b).tanh()
        };
        let h = 1e-5;
        for (a, b) in [(0.3, 1.7), (-1.2, 0.4), (2.5, -2.0)] {
            let got = p.eval(&[a, b]);
            let dx = (f(a + h, b) - f(a - h, b)) / (2.0 * h);
            let dy = (f(a, b + h) - f(a, b - h)) / (2.0 * h);
            for (g, w, tol) in [
                (got[0], f(a, b), 1e-14),
                (got[1], dx, 1e-8),
                (got[2], dy, 1e-8),
            ] {
                assert!(
                    (g - w).abs() <= tol * w.abs().max(1.0),
                    "{got:?} against {:?}",
                    (f(a, b), dx, dy)
                );
            }
        }
    }
}
