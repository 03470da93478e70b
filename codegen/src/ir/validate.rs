//! The validator: one method per part of the model file, each recording
//! what is wrong with its file:line:col and going on.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use indexmap::IndexMap;
use toml::Spanned;

use super::file::{File, Names, Number, ParamDecl, WallDecl};
use super::lex::{Token, tokens};
use super::number::{initial_value, rational};
use super::{Expr, Kind, Model, Param, ProjectorMode, Rational, Wall};
use crate::diag::{Collector, ErrorKind};

pub(super) struct Validator<'a> {
    pub(super) cx: &'a mut Collector,
    pub(super) text: &'a str,
    /// Declared name → what it is.
    pub(super) names: HashMap<String, &'static str>,
}

impl Validator<'_> {
    pub(super) fn model(&mut self, path: &Path, file: File) -> Option<Model> {
        let header = file.model.into_inner();
        let name = header.name.get_ref().clone();
        self.check_ident(&name, header.name.span(), false);
        if name.chars().any(|c| c.is_ascii_uppercase()) {
            self.cx.error(
                ErrorKind::BadName {
                    name: name.clone(),
                    why: "a model's name is snake_case (lower case, digits and `_`)".into(),
                },
                Some(header.name.span()),
            );
        }

        let projector = self.projector_mode(header.projector.as_ref());
        let params = self.params(&file.parameters);
        let (kind, coordinates, velocities) =
            self.variables(file.coordinates.as_ref(), file.velocities.as_ref());
        let definitions = self.definitions(&file.definitions);

        let dyn_span = file.dynamics.span();
        let dynamics = file.dynamics.into_inner();
        let kinetic_energy = self.expr(&dynamics.kinetic_energy);
        let potential = dynamics.potential.as_ref().map(|p| self.expr(p));
        let holonomic = dynamics.holonomic.iter().map(|c| self.expr(c)).collect();
        if kind == Kind::Instantaneous
            && let Some(h) = dynamics.holonomic.first()
        {
            self.cx.error(
                ErrorKind::Structure(
                    "holonomic constraints h(q) = 0 need coordinates; an instantaneous model has none"
                        .into(),
                ),
                Some(h.span()),
            );
        }
        let constraints = dynamics.constraints.iter().map(|c| self.expr(c)).collect();

        let walls = self.walls(kind, &file.wall);
        let initial = self.initial(&coordinates, &velocities, &file.initial);
        if file.wall.is_empty() {
            self.cx.error(
                ErrorKind::Structure("the model has no wall: declare at least one [[wall]]".into()),
                Some(dyn_span),
            );
        }
        Some(Model {
            name,
            doc: header.doc.trim().to_string(),
            params,
            kind,
            coordinates,
            velocities,
            definitions,
            kinetic_energy,
            potential,
            holonomic,
            constraints,
            walls,
            projector,
            initial,
            source: self.text.to_string(),
            file: path.to_path_buf(),
        })
    }

    fn params(&mut self, decls: &IndexMap<Spanned<String>, Spanned<ParamDecl>>) -> Vec<Param> {
        let mut out = Vec::new();
        for (name, decl) in decls {
            self.declare(name, "parameter");
            let (value, span, doc) = match decl.get_ref() {
                ParamDecl::Full { value, doc } => (value.as_ref(), decl.span(), doc.clone()),
                ParamDecl::Bare(v) => (Some(v), decl.span(), String::new()),
            };
            let value = value.ok_or_else(|| "it has no value: write `value = \"…\"`".to_string());
            match value.and_then(rational) {
                Ok(value) => out.push(Param {
                    name: name.get_ref().clone(),
                    value,
                    doc,
                }),
                Err(why) => {
                    self.cx.error(
                        ErrorKind::BadParameter {
                            name: name.get_ref().clone(),
                            why,
                        },
                        Some(span),
                    );
                    // Still declared, so its uses are not reported as unknown;
                    // the model is rejected anyway.
                    out.push(Param {
                        name: name.get_ref().clone(),
                        value: Rational { num: 0, den: 1 },
                        doc,
                    });
                }
            }
        }
        out
    }

    fn variables(
        &mut self,
        coords: Option<&Spanned<Names>>,
        vels: Option<&Spanned<Names>>,
    ) -> (Kind, Vec<String>, Vec<String>) {
        match (coords, vels) {
            (Some(c), None) => self.coordinates(c),
            (None, Some(v)) => self.instantaneous(v),
            (Some(c), Some(_)) => {
                self.cx.error(
                    ErrorKind::Structure(
                        "declare either [coordinates] (velocities are their time derivatives) or [velocities] (an instantaneous model), not both".into(),
                    ),
                    Some(c.span()),
                );
                (Kind::Coordinates, Vec::new(), Vec::new())
            }
            (None, None) => {
                self.cx.error(
                    ErrorKind::Structure(
                        "the model declares neither [coordinates] nor [velocities]".into(),
                    ),
                    None,
                );
                (Kind::Instantaneous, Vec::new(), Vec::new())
            }
        }
    }

    /// `[model] projector`: auto (the default), symbolic or structured.
    fn projector_mode(&mut self, mode: Option<&Spanned<String>>) -> ProjectorMode {
        match mode.map(|p| (p.get_ref().as_str(), p.span())) {
            None | Some(("auto", _)) => ProjectorMode::Auto,
            Some(("symbolic", _)) => ProjectorMode::Symbolic,
            Some(("structured", _)) => ProjectorMode::Structured,
            Some((other, span)) => {
                self.cx.error(
                    ErrorKind::Structure(format!(
                        "[model] projector = `{other}`: write \"auto\", \"symbolic\" or \"structured\""
                    )),
                    Some(span),
                );
                ProjectorMode::Auto
            }
        }
    }

    /// `[coordinates]`: the names and their velocities (`<name>_dot` unless
    /// given).
    fn coordinates(&mut self, c: &Spanned<Names>) -> (Kind, Vec<String>, Vec<String>) {
        let names = c.get_ref();
        let q: Vec<String> = names
            .names
            .iter()
            .map(|n| {
                self.declare(n, "coordinate");
                n.get_ref().clone()
            })
            .collect();
        let v = match &names.velocities {
            Some(vs) => {
                if vs.len() != q.len() {
                    self.cx.error(
                        ErrorKind::Structure(format!(
                            "{} coordinates but {} velocity names",
                            q.len(),
                            vs.len()
                        )),
                        Some(c.span()),
                    );
                }
                vs.iter()
                    .map(|n| {
                        self.declare(n, "velocity");
                        n.get_ref().clone()
                    })
                    .collect()
            }
            None => q
                .iter()
                .zip(&names.names)
                .map(|(n, s)| {
                    let v = format!("{n}_dot");
                    self.declare(&Spanned::new(s.span(), v.clone()), "velocity");
                    v
                })
                .collect(),
        };
        if q.is_empty() {
            self.cx.error(
                ErrorKind::Structure("`coordinates.names` is empty".into()),
                Some(c.span()),
            );
        }
        (Kind::Coordinates, q, v)
    }

    /// `[velocities]` of an instantaneous model.
    fn instantaneous(&mut self, v: &Spanned<Names>) -> (Kind, Vec<String>, Vec<String>) {
        if v.get_ref().velocities.is_some() {
            self.cx.error(
                ErrorKind::Structure(
                    "`velocities` takes only `names`; `velocities.velocities` is for coordinates"
                        .into(),
                ),
                Some(v.span()),
            );
        }
        let names: Vec<String> = v
            .get_ref()
            .names
            .iter()
            .map(|n| {
                self.declare(n, "velocity");
                n.get_ref().clone()
            })
            .collect();
        if names.is_empty() {
            self.cx.error(
                ErrorKind::Structure("`velocities.names` is empty".into()),
                Some(v.span()),
            );
        }
        (Kind::Instantaneous, Vec::new(), names)
    }

    /// Definitions, each rewritten free of other definitions.
    fn definitions(
        &mut self,
        decls: &IndexMap<Spanned<String>, Spanned<String>>,
    ) -> Vec<(String, Expr)> {
        for name in decls.keys() {
            self.declare(name, "definition");
        }
        let raw: BTreeMap<String, Expr> = decls
            .iter()
            .map(|(n, e)| (n.get_ref().clone(), self.expr(e)))
            .collect();
        // Cycle check by depth-first search over references.
        let mut out = Vec::new();
        for name in decls.keys() {
            let mut stack = vec![name.get_ref().clone()];
            if self.refers_to_itself(&raw, &mut stack) {
                self.cx
                    .error(ErrorKind::Cycle(name.get_ref().clone()), Some(name.span()));
            }
            out.push((name.get_ref().clone(), raw[name.get_ref()].clone()));
        }
        out
    }

    fn refers_to_itself(&self, defs: &BTreeMap<String, Expr>, stack: &mut Vec<String>) -> bool {
        let Some(last) = stack.last() else {
            return false;
        };
        let Some(expr) = defs.get(last) else {
            return false;
        };
        for tok in tokens(&expr.text) {
            if let Token::Name(n, _) = tok
                && defs.contains_key(n)
            {
                if n == stack[0] {
                    return true;
                }
                if stack.iter().any(|s| s == n) {
                    continue;
                }
                stack.push(n.to_string());
                let found = self.refers_to_itself(defs, stack);
                stack.pop();
                if found {
                    return true;
                }
            }
        }
        false
    }

    fn walls(&mut self, kind: Kind, decls: &[Spanned<WallDecl>]) -> Vec<Wall> {
        let mut out = Vec::new();
        let mut seen: HashMap<String, ()> = HashMap::new();
        for decl in decls {
            let w = decl.get_ref();
            let name = w.name.get_ref().clone();
            self.check_ident(&name, w.name.span(), false);
            if seen.insert(name.clone(), ()).is_some() {
                self.cx.error(
                    ErrorKind::Duplicate {
                        name: name.clone(),
                        first: "wall",
                    },
                    Some(w.name.span()),
                );
            }
            match (kind, &w.surface, &w.normal_velocity) {
                (Kind::Coordinates, None, _) => {
                    self.cx.error(
                        ErrorKind::Structure(format!(
                            "wall `{name}` needs `surface`, the function f(q) with motion in f >= 0"
                        )),
                        Some(decl.span()),
                    );
                }
                (Kind::Coordinates, Some(_), Some(n)) => {
                    self.cx.error(
                    ErrorKind::Structure(format!(
                        "wall `{name}`: a model with coordinates derives the normal velocity from `surface`; remove `normal_velocity`"
                    )),
                    Some(n.span()),
                );
                }
                (Kind::Instantaneous, _, None) => {
                    self.cx.error(
                    ErrorKind::Structure(format!(
                        "wall `{name}` needs `normal_velocity`: an instantaneous model has no coordinates to derive it from"
                    )),
                    Some(decl.span()),
                );
                }
                (Kind::Instantaneous, Some(s), Some(_)) => {
                    self.cx.error(
                    ErrorKind::Structure(format!(
                        "wall `{name}`: an instantaneous model has no coordinates, so no `surface`"
                    )),
                    Some(s.span()),
                );
                }
                _ => {}
            }
            out.push(Wall {
                name,
                doc: w.doc.trim().to_string(),
                surface: w.surface.as_ref().map(|s| self.expr(s)),
                normal_velocity: w.normal_velocity.as_ref().map(|s| self.expr(s)),
                contact: w.contact.iter().map(|c| self.expr(c)).collect(),
                span: decl.span(),
            });
        }
        out
    }

    /// The `[initial]` table: values for coordinates and velocities, exact
    /// numbers or rational multiples of `pi`.
    fn initial(
        &mut self,
        coordinates: &[String],
        velocities: &[String],
        decls: &IndexMap<Spanned<String>, Spanned<Number>>,
    ) -> Vec<f64> {
        let mut out = vec![0.0; coordinates.len() + velocities.len()];
        for (name, value) in decls {
            let n = name.get_ref();
            let Some(slot) = coordinates.iter().chain(velocities).position(|c| c == n) else {
                self.cx.error(
                    ErrorKind::Structure(format!(
                        "[initial] `{n}` is not a coordinate or a velocity of the model"
                    )),
                    Some(name.span()),
                );
                continue;
            };
            match initial_value(value.get_ref()) {
                Ok(x) => out[slot] = x,
                Err(why) => {
                    self.cx.error(
                        ErrorKind::Structure(format!("[initial] `{n}`: {why}")),
                        Some(value.span()),
                    );
                }
            }
        }
        out
    }
}
