//! One program of a derivation ready to run: its tape and its own
//! registers, with the parameters in place, over f64 or over intervals.

use std::cell::RefCell;

use dalembert_runtime::interval::Interval;

use super::tape::Tape;
use crate::derive::Function;

/// One program with its own register file.
#[derive(Clone, Debug)]
pub(super) struct Compiled {
    pub(super) tape: Tape,
    /// Registers: parameters already in place, the rest filled per call.
    registers: RefCell<Vec<f64>>,
    /// Registers of an evaluation over intervals (filled per call from
    /// `registers`; room made by [`Compiled::with_bounds`]).
    bounds: RefCell<Vec<Interval>>,
    /// For rows and values: how many are in use.
    pub(super) rows: usize,
}

impl Compiled {
    pub(super) fn new(f: &Function, params: &[f64]) -> Self {
        let tape = Tape::new(&f.program);
        let mut registers = tape.init.clone();
        let np = params.len().min(tape.inputs);
        registers[..np].copy_from_slice(&params[..np]);
        Self {
            tape,
            registers: RefCell::new(registers),
            bounds: RefCell::new(Vec::new()),
            rows: f.rows,
        }
    }

    /// Runs on (parameters, `q`, `v`) and hands the outputs to `read`.
    pub(super) fn eval<R>(
        &self,
        np: usize,
        q: &[f64],
        v: &[f64],
        read: impl FnOnce(&[f64]) -> R,
    ) -> R {
        self.eval_parts(np, &[q, v], read)
    }

    /// Runs on the parameters followed by `parts` in turn (as many values
    /// as the program has inputs) and hands the outputs to `read`.
    pub(super) fn eval_parts<R>(
        &self,
        np: usize,
        parts: &[&[f64]],
        read: impl FnOnce(&[f64]) -> R,
    ) -> R {
        let mut r = self.registers.borrow_mut();
        let inputs = self.tape.inputs;
        let mut at = np;
        for part in parts {
            let k = part.len().min(inputs.saturating_sub(at));
            r[at..at + k].copy_from_slice(&part[..k]);
            at += k;
        }
        self.tape.run(&mut r);
        read(self.tape.outputs(&r))
    }

    /// With room for an evaluation over intervals ([`Compiled::eval_bounds`]
    /// then allocates nothing).
    pub(super) fn with_bounds(self) -> Self {
        let room = self.registers.borrow().len();
        *self.bounds.borrow_mut() = vec![Interval::point(0.0); room];
        self
    }

    /// Runs on the parameters (as points) and `q`, a box of coordinates,
    /// over intervals; hands the outputs to `read`.
    pub(super) fn eval_bounds<R>(
        &self,
        np: usize,
        q: &[Interval],
        read: impl FnOnce(&[Interval]) -> R,
    ) -> R {
        let mut b = self.bounds.borrow_mut();
        let r = self.registers.borrow();
        if b.len() != r.len() {
            b.resize(r.len(), Interval::point(0.0));
        }
        for (b, &x) in b.iter_mut().zip(r.iter()) {
            *b = Interval::point(x);
        }
        let k = q.len().min(self.tape.inputs.saturating_sub(np));
        b[np..np + k].copy_from_slice(&q[..k]);
        self.tape.run(&mut b);
        read(self.tape.outputs(&b))
    }

    pub(super) fn set_parameter(&mut self, index: usize, value: f64) {
        let r = self.registers.get_mut();
        if index < self.tape.inputs {
            r[index] = value;
        }
    }
}
