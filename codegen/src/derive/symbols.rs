//! Pass 1: the model's names as symbols, its definitions made free of each
//! other, and its expressions parsed with every definition substituted.

use symbolica::prelude::*;

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
    definitions: Vec<(Symbol, Atom)>,
}

impl<'a> Symbols<'a> {
    /// The symbols of `model`; its definitions are parsed and substituted
    /// into each other (the validator rejected cycles, so as many rounds as
    /// there are definitions suffice).
    pub fn new(model: &'a Model, cx: &mut Collector) -> Result<Self, Reported> {
        // Symbols are made in this order (parameters, coordinates,
        // velocities, then definitions) because symbolica orders terms, and
        // so the emitted instructions, by when their symbols were made.
        let sym = |n: &String| symbol!(n.as_str());
        let params = model.params.iter().map(|p| sym(&p.name)).collect();
        let coords = model.coordinates.iter().map(sym).collect();
        let vels = model.velocities.iter().map(sym).collect();
        let mut defs = Vec::new();
        for (name, e) in &model.definitions {
            defs.push((symbol!(name.as_str()), parse_raw(e, cx)?));
        }
        for _ in 0..defs.len() {
            let snapshot = defs.clone();
            for (_, a) in defs.iter_mut() {
                for (s, v) in &snapshot {
                    *a = a.replace(Atom::from(*s)).with(v.clone());
                }
            }
        }
        Ok(Self {
            model,
            params,
            coords,
            vels,
            definitions: defs,
        })
    }

    /// The expression with every definition substituted.
    pub fn parse(&self, e: &Expr, cx: &mut Collector) -> Result<Atom, Reported> {
        let mut a = parse_raw(e, cx)?;
        for (s, v) in &self.definitions {
            a = a.replace(Atom::from(*s)).with(v.clone());
        }
        Ok(a)
    }

    /// Velocity k as an expression.
    pub fn vel(&self, k: usize) -> Atom {
        Atom::from(self.vels[k])
    }

    /// The inputs of every emitted function: parameters, coordinates,
    /// velocities.
    pub fn inputs(&self) -> Vec<Atom> {
        self.params
            .iter()
            .chain(&self.coords)
            .chain(&self.vels)
            .map(|s| Atom::from(*s))
            .collect()
    }

    /// The inputs at the sample point: the file's parameter values,
    /// [`sample_configuration`], zero velocities.
    pub fn sample_inputs(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self.model.params.iter().map(|p| p.value.to_f64()).collect();
        v.extend(sample_configuration(self.coords.len()));
        v.extend(std::iter::repeat_n(0.0, self.vels.len()));
        v
    }

    /// The sample point, described for people.
    pub fn sample_description(&self) -> String {
        self.point_description(&sample_configuration(self.coords.len()))
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
            .map(|p| format!("{} = {}", p.name, p.value));
        let coords = self
            .model
            .coordinates
            .iter()
            .zip(q)
            .map(|(c, x)| format!("{c} = {}", trim(x)));
        params.chain(coords).collect::<Vec<_>>().join(", ")
    }
}

/// Parses one expression of the model file.
fn parse_raw(e: &Expr, cx: &mut Collector) -> Result<Atom, Reported> {
    try_parse!(e.text.as_str()).map_err(|msg| {
        let first = msg.lines().next().unwrap_or("").to_string();
        cx.error(ErrorKind::Syntax(first), Some(e.span.clone()))
    })
}

/// Where G is checked for positive definiteness: qᵢ = 0.3 + 0.41·i
/// (away from the usual coordinate singularities at 0 and π/2 multiples).
pub fn sample_configuration(n: usize) -> Vec<f64> {
    (0..n).map(|i| 0.3 + 0.41 * i as f64).collect()
}
