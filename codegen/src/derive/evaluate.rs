//! Pass 5: expressions to straight-line programs by symbolica's evaluator
//! optimisation (common subexpressions, Horner schemes), converted to the
//! generator's own [`Program`], which later stages use without symbolica.

use symbolica::evaluate::{Instruction, Slot as ESlot};
use symbolica::prelude::*;

use crate::program::{Func, Instr, Program, Slot};

/// An optimised program for `outputs` in terms of `inputs`.
pub fn program(outputs: &[Atom], inputs: &[Atom]) -> Result<Program, String> {
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
    let slots = |v: &[ESlot]| v.iter().map(slot).collect::<Vec<_>>();
    let mut instrs = Vec::new();
    for ins in &ex.instructions {
        instrs.push(match ins {
            Instruction::Add(d, s, _) => Instr::Add(slot(d), slots(s)),
            Instruction::Mul(d, s, _) => Instr::Mul(slot(d), slots(s)),
            Instruction::Pow(d, s, n, _) => Instr::Pow(slot(d), slot(s), *n),
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
        });
    }
    Ok(Program {
        inputs: inputs.len(),
        consts,
        instrs,
        outputs: ex.output_count,
    })
}

fn slot(s: &ESlot) -> Slot {
    match s {
        ESlot::Param(i) => Slot::Input(*i),
        ESlot::Const(i) => Slot::Const(*i),
        ESlot::Temp(i) => Slot::Temp(*i),
        ESlot::Out(i) => Slot::Out(*i),
    }
}
