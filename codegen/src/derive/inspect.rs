//! Symbolic helpers for front ends and tests: equality of expressions,
//! evaluation by the generator's own programs (an independent path from
//! emitted code), substitution and LaTeX. Expressions are read with the
//! model language's parser (and what symbolica prints reads back). Each
//! takes the generator's lock first.

use std::collections::HashMap;

use symbolica::prelude::*;

use super::budget;
use super::build::{build, model_symbol};
use super::evaluate::program;
use super::lower::vanishes;

/// `text` as an expression of the model language.
fn atom(text: &str) -> Result<Atom, String> {
    atom_with(text, &HashMap::new())
}

/// `text` as an expression, each name in `definitions` standing for its
/// expression.
fn atom_with(text: &str, definitions: &HashMap<String, Atom>) -> Result<Atom, String> {
    let node = crate::ir::expr::parse(text).map_err(|e| format!("`{text}`: {}", e.message))?;
    if let Some((span, what)) = node.constant_problem() {
        let part = text.get(span).unwrap_or_default();
        return Err(format!("`{text}`: `{part}` is {what}"));
    }
    build(&node, definitions).map_err(|e| format!("`{text}`: {}", e.message))
}

/// Whether two expressions (in the model's names) are equal as rational
/// functions of the names and the function applications, sin² + cos² = 1
/// and cosh² − sinh² = 1 taken into account.
pub fn same(a: &str, b: &str) -> Result<bool, String> {
    same_with(a, b, &[])
}

/// [`same`], where each name in `definitions` (name and expression, each
/// in terms of the names before it, as a model's derived parameters and
/// definitions are) stands for its expression on both sides.
pub fn same_with(a: &str, b: &str, definitions: &[(String, String)]) -> Result<bool, String> {
    crate::lock::acquire()?;
    let mut defs = HashMap::new();
    for (name, text) in definitions {
        let value = atom_with(text, &defs)?;
        defs.insert(name.clone(), value);
    }
    vanishes(&(atom_with(a, &defs)? - atom_with(b, &defs)?)).map_err(|over| match over {
        budget::Over::Terms(bound) => format!(
            "the difference, reduced by sin² + cos² = 1, may expand to {bound:.0} terms; the limit is {:.0}",
            budget::MAX_EXPANDED_TERMS
        ),
        // (A zero test multiplies no matrices and divides by nothing.)
        budget::Over::Product(_) | budget::Over::VanishingDenominator => "the difference has no value".to_string(),
    })
}

/// `a` and `b` (with `definitions` as in [`same_with`]) evaluated at each
/// of `points` (a value for each of `names`, in order): the largest
/// |a − b| / max(1, |a|, |b|) over the points where both are finite, and
/// how many points those were. For equalities the symbolic reduction does
/// not prove (multiple angles, say), as evidence and not as proof.
pub fn numeric_difference(
    a: &str,
    b: &str,
    definitions: &[(String, String)],
    names: &[&str],
    points: &[Vec<f64>],
) -> Result<(f64, usize), String> {
    crate::lock::acquire()?;
    let mut defs = HashMap::new();
    for (name, text) in definitions {
        let value = atom_with(text, &defs)?;
        defs.insert(name.clone(), value);
    }
    let outputs = [atom_with(a, &defs)?, atom_with(b, &defs)?];
    let inputs: Vec<Atom> = names.iter().map(|n| Atom::from(model_symbol(n))).collect();
    let p = program(&outputs, &inputs)?;
    let (mut worst, mut finite) = (0.0f64, 0);
    for x in points {
        let v = p.eval(x);
        if v.iter().all(|y| y.is_finite()) {
            finite += 1;
            worst = worst.max((v[0] - v[1]).abs() / 1f64.max(v[0].abs()).max(v[1].abs()));
        }
    }
    Ok((worst, finite))
}

/// Evaluates `expr` at the given values.
pub fn eval(expr: &str, values: &[(&str, f64)]) -> Result<f64, String> {
    crate::lock::acquire()?;
    let e = atom(expr)?;
    let inputs: Vec<Atom> = values
        .iter()
        .map(|(n, _)| Atom::from(model_symbol(n)))
        .collect();
    let p = program(std::slice::from_ref(&e), &inputs)?;
    let xs: Vec<f64> = values.iter().map(|(_, v)| *v).collect();
    Ok(p.eval(&xs)[0])
}

/// `expr` with each named symbol replaced by an expression.
pub fn substitute(expr: &str, subs: &[(&str, &str)]) -> Result<String, String> {
    crate::lock::acquire()?;
    let mut e = atom(expr)?;
    for (name, value) in subs {
        e = e.replace(Atom::from(model_symbol(name))).with(atom(value)?);
    }
    Ok(e.to_string())
}

/// `expr` typeset as LaTeX by symbolica's printer.
pub fn latex(expr: &str) -> Result<String, String> {
    crate::lock::acquire()?;
    let e = atom(expr)?;
    Ok(format!("{}", e.printer(PrintOptions::latex())))
}
