//! Where the numeric checks look: the sample configuration moved onto the
//! model's holonomic constraints h(q) = 0 (and, for a wall's checks, onto
//! its surface f(q) = 0 as well), so that a check is made at a state the
//! model can be in.

use symbolica::prelude::*;

use super::evaluate::program;
use super::mechanics::Raw;
use super::symbols::{Symbols, sample_configuration};
use crate::program::Program;

/// Gauss–Newton steps at most.
const STEPS: usize = 100;

/// The inputs `x` (parameters, then `n` coordinates, then velocities) moved
/// onto r(q) = 0, where the program's first `k` outputs are r and the next
/// k·n their gradients (row by row), by minimum-norm Gauss–Newton steps in
/// the coordinates; `None` when that does not converge.
pub fn onto(prog: &Program, mut x: Vec<f64>, np: usize, n: usize, k: usize) -> Option<Vec<f64>> {
    for _ in 0..STEPS {
        let out = prog.eval(&x);
        let r = nalgebra::DVector::from_column_slice(&out[..k]);
        let j = nalgebra::DMatrix::from_row_slice(k, n, &out[k..k + k * n]);
        let scale = 1.0 + x[np..np + n].iter().fold(0.0_f64, |m, q| m.max(q.abs()));
        if r.amax() <= 1e-12 * scale {
            return Some(x);
        }
        if !r.iter().chain(j.iter()).all(|v| v.is_finite()) {
            return None;
        }
        let lambda = (&j * j.transpose()).lu().solve(&r)?;
        let step = j.transpose() * lambda;
        for i in 0..n {
            x[np + i] -= step[i];
        }
    }
    None
}

/// A configuration on h(q) = 0 near [`sample_configuration`] (that one
/// itself for a model without holonomic constraints, or when no point is
/// found).
pub fn configuration(sym: &Symbols, raw: &Raw) -> Vec<f64> {
    let n = sym.coords.len();
    let start = sample_configuration(n);
    let k = raw.holonomic.len();
    if k == 0 || n == 0 {
        return start;
    }
    // The first k rows of A are dh.
    let mut outputs: Vec<Atom> = raw.holonomic.clone();
    outputs.extend(raw.a_rows[..k].iter().flatten().cloned());
    let Ok(prog) = program(&outputs, &sym.inputs()) else {
        return start;
    };
    let np = sym.params.len();
    let mut x = sym.sample_inputs();
    x[np..np + n].copy_from_slice(&start);
    match onto(&prog, x, np, n, k) {
        Some(x) => x[np..np + n].to_vec(),
        None => start,
    }
}
