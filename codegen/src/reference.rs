//! Comparing a derivation with a reference: a matrix P and a collision law
//! written down by hand (for instance, as printed in a paper).
//!
//! A reference file names the model and wall, gives P as an optional common
//! prefactor times a matrix, and optionally the collision law v⁺ component by
//! component. A law stated only for admissible velocities (A v = 0) lists, in
//! `[admissible]`, velocities to eliminate with the constraints; both sides
//! are compared after that substitution. Entries are compared exactly, as
//! rational functions.

use std::path::Path;

use indexmap::IndexMap;
use serde::Deserialize;

use crate::derive::inspect as symbolic;
use crate::derive::{Derivation, Projection};

/// A reference read from a file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// The model's name.
    pub model: String,
    /// The wall's name.
    pub wall: String,
    /// Where the reference comes from.
    #[serde(default)]
    pub source: String,
    /// A factor multiplying every entry of `projector`.
    pub prefactor: Option<String>,
    /// P as written.
    pub projector: Vec<Vec<String>>,
    /// v⁺ as written, in terms of v⁻ (named as the model's velocities).
    #[serde(default)]
    pub collision: Vec<String>,
    /// Velocities to eliminate before comparing collision laws.
    #[serde(default)]
    pub admissible: IndexMap<String, String>,
}

/// One entry where derivation and reference differ.
#[derive(Debug, Clone, PartialEq)]
pub struct Difference {
    /// Row (0-based).
    pub row: usize,
    /// Column (0-based; 0 for a collision-law component).
    pub col: usize,
    /// The reference's entry (prefactor applied).
    pub reference: String,
    /// The derived entry.
    pub derived: String,
}

/// The outcome of a comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Entries of P that differ.
    pub projector: Vec<Difference>,
    /// Components of the collision law that differ.
    pub collision: Vec<Difference>,
    /// Whether a collision law was compared.
    pub has_collision: bool,
}

impl Reference {
    /// Reads a reference file.
    pub fn load(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// The reference's entry (i, j) of P with the prefactor applied.
    pub fn entry(&self, i: usize, j: usize) -> String {
        match &self.prefactor {
            Some(f) => format!("({f})*({})", self.projector[i][j]),
            None => self.projector[i][j].clone(),
        }
    }

    /// Every expression of the reference, with where it is (1-based).
    fn expressions(&self) -> Vec<(String, &str)> {
        let mut out = Vec::new();
        if let Some(f) = &self.prefactor {
            out.push(("prefactor".to_string(), f.as_str()));
        }
        for (i, row) in self.projector.iter().enumerate() {
            for (j, e) in row.iter().enumerate() {
                out.push((format!("P entry ({}, {})", i + 1, j + 1), e.as_str()));
            }
        }
        for (i, e) in self.collision.iter().enumerate() {
            out.push((format!("collision component {}", i + 1), e.as_str()));
        }
        for (name, e) in &self.admissible {
            out.push((format!("[admissible] `{name}`"), e.as_str()));
        }
        out
    }

    /// That every name the reference uses is one of the model's: a name the
    /// model does not declare (a typo, or a symbol of the paper's own)
    /// would be compared as a free symbol and make the entry differ, which
    /// reads as a disagreement with the paper rather than a mistake in the
    /// reference.
    fn check_names(&self, d: &Derivation) -> Result<(), String> {
        let m = &d.model;
        let known = |name: &str| {
            m.params.iter().any(|p| p.name == name)
                || m.definitions.iter().any(|(n, _)| n == name)
                || m.coordinates.iter().any(|n| n == name)
                || m.velocities.iter().any(|n| n == name)
        };
        for (place, text) in self.expressions() {
            let node = crate::ir::expr::parse(text)
                .map_err(|e| format!("the reference's {place}, `{text}`: {}", e.message))?;
            let mut unknown = None;
            node.visit_names(&mut |name, _| {
                if unknown.is_none() && !known(name) {
                    unknown = Some(name.to_string());
                }
            });
            if let Some(name) = unknown {
                let names = |kind: &str, list: Vec<&str>| {
                    (!list.is_empty()).then(|| format!("{kind} {}", list.join(", ")))
                };
                let declared: Vec<String> = [
                    names(
                        "parameters",
                        m.params.iter().map(|p| p.name.as_str()).collect(),
                    ),
                    names(
                        "definitions",
                        m.definitions.iter().map(|(n, _)| n.as_str()).collect(),
                    ),
                    names(
                        "coordinates",
                        m.coordinates.iter().map(String::as_str).collect(),
                    ),
                    names(
                        "velocities",
                        m.velocities.iter().map(String::as_str).collect(),
                    ),
                ]
                .into_iter()
                .flatten()
                .collect();
                return Err(format!(
                    "the reference's {place}, `{text}`, names `{name}`, which `{}` does not declare ({})",
                    m.name,
                    declared.join("; ")
                ));
            }
        }
        Ok(())
    }

    /// Compares with `d`.
    #[allow(clippy::needless_range_loop)] // matrix code reads best with indices
    pub fn compare(&self, d: &Derivation) -> Result<Comparison, String> {
        if self.model != d.model.name {
            return Err(format!(
                "the reference is for model `{}`, and the model file is `{}`",
                self.model, d.model.name
            ));
        }
        if let Some(bad) = self
            .admissible
            .keys()
            .find(|k| !d.model.velocities.contains(k))
        {
            return Err(format!(
                "[admissible] `{bad}` is not a velocity of `{}` (its velocities: {})",
                d.model.name,
                d.model.velocities.join(", ")
            ));
        }
        let wall = d
            .walls
            .iter()
            .find(|w| w.name == self.wall)
            .ok_or_else(|| format!("model `{}` has no wall `{}`", d.model.name, self.wall))?;
        let Projection::ClosedForm {
            projector: derived_p,
            collision: derived_law,
        } = &wall.projection
        else {
            return Err(format!(
                "wall `{}` of `{}` has no closed-form P (structured evaluation): set `projector = \"symbolic\"` under [model]",
                self.wall, d.model.name
            ));
        };
        let n = d.model.velocities.len();
        if self.projector.len() != n {
            return Err(format!(
                "the reference P must be {n}×{n}: it has {} rows",
                self.projector.len()
            ));
        }
        if let Some((i, row)) = self
            .projector
            .iter()
            .enumerate()
            .find(|(_, r)| r.len() != n)
        {
            return Err(format!(
                "the reference P must be {n}×{n}: its row {} has {} entries",
                i + 1,
                row.len()
            ));
        }
        if !self.collision.is_empty() && self.collision.len() != n {
            return Err(format!(
                "the reference collision law must have {n} components, not {}",
                self.collision.len()
            ));
        }
        self.check_names(d)?;
        // The model's derived parameters and definitions stand for their
        // expressions on both sides: the derived entries are in the
        // model's own parameters, coordinates and velocities, and a
        // reference may be written in any of its names.
        let definitions: Vec<(String, String)> = d
            .model
            .definitions
            .iter()
            .map(|(name, e)| (name.clone(), e.text.clone()))
            .collect();
        let same = |a: &str, b: &str| symbolic::same_with(a, b, &definitions);
        let mut projector = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let reference = self.entry(i, j);
                if !same(&reference, &derived_p[i][j])? {
                    projector.push(Difference {
                        row: i,
                        col: j,
                        reference,
                        derived: derived_p[i][j].clone(),
                    });
                }
            }
        }
        let mut collision = Vec::new();
        if !self.collision.is_empty() {
            let subs: Vec<(&str, &str)> = self
                .admissible
                .iter()
                .map(|(k, v)| (k.as_str(), v.as_str()))
                .collect();
            for (i, (r, c)) in self.collision.iter().zip(derived_law).enumerate() {
                let r_sub = symbolic::substitute(r, &subs)?;
                let c_sub = symbolic::substitute(c, &subs)?;
                if !same(&r_sub, &c_sub)? {
                    collision.push(Difference {
                        row: i,
                        col: 0,
                        reference: r.clone(),
                        derived: c.clone(),
                    });
                }
            }
        }
        Ok(Comparison {
            projector,
            collision,
            has_collision: !self.collision.is_empty(),
        })
    }
}
