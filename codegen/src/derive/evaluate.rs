//! Pass 5: expressions to straight-line programs by symbolica's evaluator
//! optimisation (common subexpressions, Horner schemes), converted to the
//! generator's own [`Program`], which later stages use without symbolica.

use symbolica::evaluate::{Instruction, Slot as ESlot};
use symbolica::prelude::*;

use super::build::{constant_symbol, own_constants};
use super::coefficients;
use crate::ir::Constant;
use crate::program::{Func, Instr, Program, Slot};

/// Programs for `outputs` (inputs: the `params` parameters first, then
/// the coordinates and velocities): the evaluator's over the expressions as
/// they are, then, where they have parameter-only coefficients to name, its
/// over the expressions with those named ([`coefficients`]), preceded by
/// the program of the coefficients. The caller keeps the cheaper.
pub fn programs(outputs: &[Atom], inputs: &[Atom], params: usize) -> Result<Vec<Program>, String> {
    let plain = program(outputs, inputs)?;
    let varying: Vec<Symbol> = inputs[params..]
        .iter()
        .filter_map(|a| match a.as_view() {
            AtomView::Var(v) => Some(v.get_symbol()),
            _ => None,
        })
        .collect();
    let named = coefficients::name(outputs, &varying);
    if named.symbols.is_empty() {
        return Ok(vec![plain]);
    }
    let first = program(&named.coefficients, &inputs[..params])?;
    let mut all_inputs = inputs.to_vec();
    all_inputs.extend(named.symbols.iter().map(|s| Atom::from(*s)));
    let then = program(&named.outputs, &all_inputs)?.fed_by(&first, inputs.len());
    Ok(vec![plain, then])
}

/// An optimised program for `outputs` in terms of `inputs`. π and e enter
/// as two extra inputs, which become constants of the program with their
/// values; every constant is checked to be a finite real number.
pub fn program(outputs: &[Atom], inputs: &[Atom]) -> Result<Program, String> {
    if outputs.is_empty() {
        return Ok(Program {
            inputs: inputs.len(),
            consts: Vec::new(),
            instrs: Vec::new(),
            outputs: 0,
        });
    }
    let constants = [Constant::Pi, Constant::E];
    let mut all_inputs = inputs.to_vec();
    all_inputs.extend(constants.map(|c| Atom::from(constant_symbol(c))));
    let outputs: Vec<Atom> = outputs.iter().map(own_constants).collect();
    let ev = Atom::evaluator_multiple(&outputs, &all_inputs)
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
        ESlot::Param(i) if *i >= inputs.len() => Slot::Const(first_constant + i - inputs.len()),
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
                (Slot::Const(k), x) if k == first_constant + 1 => Instr::Fun(slot(d), Func::Exp, x),
                // b^x with x varying (symbolica's form of exp(x·log b)):
                // written back as exp(x·log b), in the functions the
                // language has.
                (b, x) => {
                    let (log, product) = (Slot::Temp(fresh), Slot::Temp(fresh + 1));
                    fresh += 2;
                    instrs.push(Instr::Fun(log, Func::Log, b));
                    instrs.push(Instr::Mul(product, vec![x, log]));
                    Instr::Fun(slot(d), Func::Exp, product)
                }
            },
            Instruction::Assign(d, s) => Instr::Assign(slot(d), slot(s)),
            Instruction::Fun(d, call, _) => {
                let (f, _, args) = call.as_ref();
                let name = f.get_stripped_name();
                let func = Func::from_name(name)
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
        inputs: inputs.len(),
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
}
