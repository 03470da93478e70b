//! Pass 1: the model's names as symbols, its definitions made free of each
//! other, and its expressions built with every definition substituted.

use std::collections::HashMap;

use symbolica::prelude::*;

pub use super::build::{build, model_symbol};
use crate::diag::{Collector, ErrorKind, Reported};
use crate::ir::{Expr, Model};

/// The model's symbols: parameters, coordinates and velocities, in the
/// order of every emitted function's inputs.
pub struct Symbols<'a> {
    /// The validated model.
    pub model: &'a Model,
    /// One per parameter.
    pub params: Vec<Symbol>,
    /// One per coordinate.
    pub coords: Vec<Symbol>,
    /// One per velocity.
    pub vels: Vec<Symbol>,
    /// Each definition, free of the others.
    definitions: HashMap<String, Atom>,
    /// Where the numeric checks evaluate: [`sample_configuration`], moved
    /// onto h(q) = 0 once the constraints are known
    /// ([`super::sample::configuration`]).
    pub sample: Vec<f64>,
}

impl<'a> Symbols<'a> {
    /// The symbols of `model`; its definitions are built in the validator's
    /// order (each refers only to earlier ones), so each is free of the
    /// others by construction.
    pub fn new(model: &'a Model, cx: &mut Collector) -> Result<Self, Reported> {
        // Symbols are made in this order (parameters, coordinates,
        // velocities, then definitions) because symbolica orders terms, and
        // so the emitted instructions, by when their symbols were made.
        let params: Vec<Symbol> = model.params.iter().map(|p| model_symbol(&p.name)).collect();
        let coords: Vec<Symbol> = model.coordinates.iter().map(|n| model_symbol(n)).collect();
        let vels: Vec<Symbol> = model.velocities.iter().map(|n| model_symbol(n)).collect();
        let mut definitions = HashMap::new();
        for (name, e) in &model.definitions {
            let a = build_in(e, &definitions, cx)?;
            definitions.insert(name.clone(), a);
        }
        let sample = sample_configuration(coords.len());
        Ok(Self {
            model,
            params,
            coords,
            vels,
            definitions,
            sample,
        })
    }

    /// The expression with every definition substituted.
    pub fn parse(&self, e: &Expr, cx: &mut Collector) -> Result<Atom, Reported> {
        build_in(e, &self.definitions, cx)
    }

    /// Velocity k as an expression.
    pub fn vel(&self, k: usize) -> Atom {
        Atom::from(self.vels[k])
    }

    /// The inputs of every emitted function: parameters, coordinates,
    /// velocities (the constants π and e are not inputs; the evaluation
    /// pass turns them into values).
    pub fn inputs(&self) -> Vec<Atom> {
        self.params
            .iter()
            .chain(&self.coords)
            .chain(&self.vels)
            .map(|s| Atom::from(*s))
            .collect()
    }

    /// The inputs at the sample point: the file's parameter values, the
    /// sample configuration, zero velocities.
    pub fn sample_inputs(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self.model.params.iter().map(|p| p.value).collect();
        v.extend(&self.sample);
        v.extend(std::iter::repeat_n(0.0, self.vels.len()));
        v
    }

    /// The sample point, described for people.
    pub fn sample_description(&self) -> String {
        self.point_description(&self.sample)
    }

    /// "m = 1, r = 1/2, x = 0.3, …": the file's parameter values and `q`.
    pub fn point_description(&self, q: &[f64]) -> String {
        let trim = |x: &f64| {
            let s = format!("{x:.6}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        };
        let params = self
            .model
            .params
            .iter()
            .map(|p| format!("{} = {}", p.name, p.written));
        let coords = self
            .model
            .coordinates
            .iter()
            .zip(q)
            .map(|(c, x)| format!("{c} = {}", trim(x)));
        params.chain(coords).collect::<Vec<_>>().join(", ")
    }
}

/// `e` as an expression, each name either a definition in `definitions` or
/// a model symbol; what cannot be built is reported at its place.
fn build_in(
    e: &Expr,
    definitions: &HashMap<String, Atom>,
    cx: &mut Collector,
) -> Result<Atom, Reported> {
    build(&e.node, definitions)
        .map_err(|b| cx.error(ErrorKind::Domain(b.message), Some(e.at(&b.span))))
}

/// Where G is checked for positive definiteness: qᵢ = 0.3 + 0.41·i
/// (away from the usual coordinate singularities at 0 and π/2 multiples).
pub fn sample_configuration(n: usize) -> Vec<f64> {
    (0..n).map(|i| 0.3 + 0.41 * i as f64).collect()
}
