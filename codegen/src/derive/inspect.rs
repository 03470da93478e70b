//! Symbolic helpers for front ends and tests: equality of expressions,
//! symbolica's own evaluation (an independent path from emitted code),
//! substitution and LaTeX. Each takes the generator's lock first.

use symbolica::prelude::*;

use super::is_zero;

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
