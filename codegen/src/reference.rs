//! Comparing a derivation with a reference: a matrix P and a collision law
//! written down by hand (for instance, as printed in a paper).
//!
//! A reference file names the model and wall, gives P as an optional common
//! prefactor times a matrix, and optionally the collision law v⁺ component by
//! component. A law stated only for admissible velocities (A v = 0) lists, in
//! `[admissible]`, velocities to eliminate with the constraints; both sides
//! are compared after that substitution. Entries are compared exactly, as
//! rational functions.

use std::ops::Range;
use std::path::Path;

use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

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
    /// Where each expression is in the file, when read by
    /// [`Reference::load`] (messages name `file:line:col`).
    #[serde(skip)]
    places: Places,
}

/// The file a reference was read from and where its expressions are in it.
#[derive(Debug, Clone, Default)]
struct Places {
    file: String,
    text: String,
    prefactor: Option<Range<usize>>,
    projector: Vec<Vec<Range<usize>>>,
    collision: Vec<Range<usize>>,
    admissible: Vec<Range<usize>>,
}

/// A reference file as written, each expression with its place.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Located {
    model: String,
    wall: String,
    #[serde(default)]
    source: String,
    prefactor: Option<Spanned<String>>,
    projector: Vec<Vec<Spanned<String>>>,
    #[serde(default)]
    collision: Vec<Spanned<String>>,
    #[serde(default)]
    admissible: IndexMap<String, Spanned<String>>,
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
    /// Where the reference's entry is (`file:line:col`), if known.
    pub at: Option<String>,
    /// Where the two are not shown equal symbolically but agree at random
    /// points (within [`NUMERIC_AGREEMENT`]): how many points. Evidence,
    /// not proof (an identity the symbolic reduction does not know, such
    /// as sin 2φ = 2 sin φ cos φ).
    pub numerically_equal: Option<usize>,
}

/// Random points at which a difference not shown to vanish symbolically
/// is evaluated.
pub const NUMERIC_POINTS: usize = 32;

/// Two entries agree numerically where |a − b| ≤ this × max(1, |a|, |b|)
/// at every random point where both are finite, and at least half the
/// points are such.
pub const NUMERIC_AGREEMENT: f64 = 1e-9;

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
        let text = crate::ir::read_source(path).map_err(|e| e.render())?;
        let file = path.display().to_string();
        let r: Located = toml::from_str(&text).map_err(|e| match e.span() {
            Some(span) => {
                let (line, col) = crate::diag::line_col(&text, span.start);
                format!("{file}:{line}:{col}: {}", e.message())
            }
            None => format!("{file}: {}", e.message()),
        })?;
        let plain = |e: &Spanned<String>| e.get_ref().clone();
        Ok(Reference {
            model: r.model,
            wall: r.wall,
            source: r.source,
            prefactor: r.prefactor.as_ref().map(plain),
            projector: (r.projector.iter())
                .map(|row| row.iter().map(plain).collect())
                .collect(),
            collision: r.collision.iter().map(plain).collect(),
            admissible: (r.admissible.iter())
                .map(|(k, e)| (k.clone(), plain(e)))
                .collect(),
            places: Places {
                prefactor: r.prefactor.as_ref().map(Spanned::span),
                projector: (r.projector.iter())
                    .map(|row| row.iter().map(Spanned::span).collect())
                    .collect(),
                collision: r.collision.iter().map(Spanned::span).collect(),
                admissible: r.admissible.values().map(Spanned::span).collect(),
                file,
                text,
            },
        })
    }

    /// `file:line:col` of the expression at `span` in the file read, if
    /// it was read from one.
    fn at(&self, span: Option<&Range<usize>>) -> Option<String> {
        let span = span?;
        let (line, col) = crate::diag::line_col(&self.places.text, span.start);
        Some(format!("{}:{line}:{col}", self.places.file))
    }

    /// Where P's entry (i, j) is, if known.
    fn entry_at(&self, i: usize, j: usize) -> Option<String> {
        self.at(self.places.projector.get(i).and_then(|row| row.get(j)))
    }

    /// The reference's entry (i, j) of P with the prefactor applied.
    pub fn entry(&self, i: usize, j: usize) -> String {
        match &self.prefactor {
            Some(f) => format!("({f})*({})", self.projector[i][j]),
            None => self.projector[i][j].clone(),
        }
    }

    /// Every expression of the reference, with what it is (1-based) and,
    /// if known, where: `file:line:col: ` or nothing.
    fn expressions(&self) -> Vec<(String, String, &str)> {
        let prefix = |at: Option<String>| at.map(|a| format!("{a}: ")).unwrap_or_default();
        let mut out = Vec::new();
        if let Some(f) = &self.prefactor {
            let at = self.at(self.places.prefactor.as_ref());
            out.push(("prefactor".to_string(), prefix(at), f.as_str()));
        }
        for (i, row) in self.projector.iter().enumerate() {
            for (j, e) in row.iter().enumerate() {
                let what = format!("P entry ({}, {})", i + 1, j + 1);
                out.push((what, prefix(self.entry_at(i, j)), e.as_str()));
            }
        }
        for (i, e) in self.collision.iter().enumerate() {
            let at = self.at(self.places.collision.get(i));
            out.push((
                format!("collision component {}", i + 1),
                prefix(at),
                e.as_str(),
            ));
        }
        for (k, (name, e)) in self.admissible.iter().enumerate() {
            let at = self.at(self.places.admissible.get(k));
            out.push((format!("[admissible] `{name}`"), prefix(at), e.as_str()));
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
        for (place, at, text) in self.expressions() {
            let node = crate::ir::expr::parse(text)
                .map_err(|e| format!("{at}the reference's {place}, `{text}`: {}", e.message))?;
            if let Some((span, what)) = node.constant_problem() {
                let part = text.get(span).unwrap_or_default();
                return Err(format!(
                    "{at}the reference's {place}, `{text}`: `{part}` is {what}"
                ));
            }
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
                    "{at}the reference's {place}, `{text}`, names `{name}`, which `{}` does not declare ({})",
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
            let at = self
                .entry_at(i, 0)
                .map(|a| format!("{a}: "))
                .unwrap_or_default();
            return Err(format!(
                "{at}the reference P must be {n}×{n}: its row {} has {} entries",
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
        let (names, points) = random_points(d);
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        // Not shown equal: at how many random points they agree, if at all.
        let numerically = |a: &str, b: &str| -> Result<Option<usize>, String> {
            let (worst, finite) =
                symbolic::numeric_difference(a, b, &definitions, &names, &points)?;
            Ok((worst <= NUMERIC_AGREEMENT && 2 * finite >= points.len()).then_some(finite))
        };
        let mut projector = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let reference = self.entry(i, j);
                if !same(&reference, &derived_p[i][j])? {
                    projector.push(Difference {
                        row: i,
                        col: j,
                        at: self.entry_at(i, j),
                        numerically_equal: numerically(&reference, &derived_p[i][j])?,
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
                        at: self.at(self.places.collision.get(i)),
                        numerically_equal: numerically(&r_sub, &c_sub)?,
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

/// The model's parameters, coordinates and velocities, and
/// [`NUMERIC_POINTS`] random values of them: each parameter its file's
/// value times a factor in [1/2, 2] (in [−1, 1] where the file's is 0), each
/// coordinate in [−3/2, 3/2], each velocity in [−1, 1]; the same points on
/// every run.
fn random_points(d: &Derivation) -> (Vec<String>, Vec<Vec<f64>>) {
    let m = &d.model;
    let mut names: Vec<String> = m.params.iter().map(|p| p.name.clone()).collect();
    names.extend(m.coordinates.iter().cloned());
    names.extend(m.velocities.iter().cloned());
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let points = (0..NUMERIC_POINTS)
        .map(|_| {
            let mut x: Vec<f64> = m
                .params
                .iter()
                .map(|p| {
                    if p.value == 0.0 {
                        2.0 * uniform() - 1.0
                    } else {
                        p.value * 2f64.powf(2.0 * uniform() - 1.0)
                    }
                })
                .collect();
            x.extend(m.coordinates.iter().map(|_| 3.0 * uniform() - 1.5));
            x.extend(m.velocities.iter().map(|_| 2.0 * uniform() - 1.0));
            x
        })
        .collect();
    (names, points)
}
