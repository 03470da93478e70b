//! The validator: one method per part of the model file, each recording
//! what is wrong with its file:line:col and going on.

use std::collections::HashMap;
use std::path::Path;

use indexmap::IndexMap;
use toml::Spanned;

use super::expr::MAX_DEGREE;
use super::file::{File, Names, Number, ParamDecl, WallDecl};
use super::limits::{
    self, MAX_DEFINITIONS, MAX_EXPANDED_DEPTH, MAX_EXPANDED_SIZE, MAX_NESTED_DIVISIONS,
    MAX_PARAMETERS, MAX_TERMS,
};
use super::names::ident_problem;
use super::number::rational;
use super::order::{dependency_order, reaches};
use super::{Expr, GENERATED_TYPE_NAMES, Kind, Model, Param, ProjectorMode, Wall, camel};
use crate::diag::{Collector, ErrorKind};

pub(super) struct Validator<'a> {
    pub(super) cx: &'a mut Collector,
    pub(super) text: &'a str,
    /// Declared name → what it is.
    pub(super) names: HashMap<String, &'static str>,
}

impl Validator<'_> {
    pub(super) fn model(&mut self, path: &Path, file: File) -> Option<Model> {
        let header = file.model.map(Spanned::into_inner);
        let (doc, projector) = match &header {
            Some(h) => (h.doc.trim().to_string(), h.projector.clone()),
            None => (String::new(), None),
        };
        let written = header.and_then(|h| h.name);
        // Where errors that have no place of their own go: the name, else
        // the file's start.
        let name_span = written.as_ref().map_or(0..0, |n| n.span());
        let name = match &written {
            Some(n) => n.get_ref().clone(),
            None => path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
        };
        // The file's own name gets the same checks, and says where it came from.
        let from_file = |why: String| match &written {
            Some(_) => why,
            None => {
                format!("{why} (the model is named after its file: name it with `[model] name`)")
            }
        };
        let why = ident_problem(&name, false)
            .or_else(|| {
                (name.chars().any(|c| c.is_ascii_uppercase()))
                    .then(|| "a model's name is snake_case (lower case, digits and `_`)".into())
            })
            .or_else(|| {
                GENERATED_TYPE_NAMES.contains(&camel(&name).as_str()).then(|| {
                    format!(
                        "the model's type would be `{}`, a name the generated code already uses",
                        camel(&name)
                    )
                })
            });
        if let Some(why) = why {
            self.cx.error(
                ErrorKind::BadName {
                    name: name.clone(),
                    why: from_file(why),
                },
                written.as_ref().map(|n| n.span()),
            );
        }

        let projector = self.projector_mode(projector.as_ref());
        let (params, derived) = self.params(&file.parameters);
        let (kind, coordinates, velocities) = self.variables(
            file.coordinates.as_ref(),
            file.velocities.as_ref(),
            !file.body.is_empty(),
        );
        for name in file.definitions.keys() {
            self.declare(name, "definition");
        }
        let derived_names: Vec<String> = derived.iter().map(|(n, _)| n.get_ref().clone()).collect();
        self.only_parameters(&params, &derived);
        let mut all: Vec<(Spanned<String>, Expr)> = derived;
        for (n, e) in &file.definitions {
            all.push((n.clone(), self.expr(e)));
        }
        let definitions = self.definitions(all);

        let (dyn_span, dynamics) = match file.dynamics {
            Some(d) => (d.span(), d.into_inner()),
            None => (name_span.clone(), Default::default()),
        };
        let kinetic_energy = match &dynamics.kinetic_energy {
            Some(t) => self.expr(t),
            // Bodies that gave no T: the bodies layer has said why.
            None if !file.body.is_empty() => {
                self.expr(&Spanned::new(dyn_span.clone(), "0".to_string()))
            }
            None => {
                self.cx.error(
                    ErrorKind::Structure(
                        "the model has no kinetic energy: write `kinetic_energy` in [dynamics], or declare a [[body]]"
                            .into(),
                    ),
                    Some(dyn_span.clone()),
                );
                self.expr(&Spanned::new(dyn_span.clone(), "0".to_string()))
            }
        };
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
        limits::constraint_count(self.cx, &dynamics, velocities.len());

        let walls = self.walls(kind, &file.wall);
        let defined: Vec<String> = file
            .definitions
            .keys()
            .map(|k| k.get_ref().clone())
            .collect();
        let initial = self.initial(&coordinates, &velocities, &defined, &file.initial);
        // A model with coordinates may have no wall (motion only); one
        // without describes a collision instant and needs one.
        if file.wall.is_empty() && kind == Kind::Instantaneous {
            self.cx.error(
                ErrorKind::Structure(
                    "a model without coordinates describes a collision instant: declare at least one [[wall]]".into(),
                ),
                Some(dyn_span),
            );
        }
        let state_len = coordinates.len() + velocities.len();
        let initial =
            self.initial_values(&params, &derived_names, &definitions, initial, state_len);
        Some(Model {
            name,
            doc,
            params,
            derived: derived_names,
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
            initial: initial.values,
            initial_state: initial.exprs,
            start_rates: initial.rates,
            from_bodies: Vec::new(),
            source: self.text.to_string(),
            file: path.to_path_buf(),
        })
    }

    /// Parameters: an exact number, a constant expression (`pi/6`), or an
    /// expression of other parameters (`2/5*m*r^2`), which makes it a
    /// derived parameter: returned apart, to be substituted like a
    /// definition, so that it follows the others wherever they change.
    fn params(
        &mut self,
        decls: &IndexMap<Spanned<String>, Spanned<ParamDecl>>,
    ) -> (Vec<Param>, Vec<(Spanned<String>, Expr)>) {
        let mut out = Vec::new();
        let mut derived = Vec::new();
        limits::declarations(
            self.cx,
            (decls.len(), MAX_PARAMETERS),
            "parameters",
            " (every program of the derivation takes them all)",
            decls.get_index(MAX_PARAMETERS).map(|(n, _)| n.span()),
        );
        for (name, decl) in decls {
            self.declare(name, "parameter");
            let (value, doc) = match decl.get_ref() {
                ParamDecl::Full { value, doc } => (value.as_ref(), doc.clone()),
                ParamDecl::Bare(v) => (Some(v), String::new()),
            };
            let param = |value: f64, written: String| Param {
                name: name.get_ref().clone(),
                value,
                written,
                doc: doc.clone(),
            };
            let exact = value
                .ok_or_else(|| "it has no value: write `value = \"…\"`".to_string())
                .and_then(rational);
            match (exact, value) {
                (Ok(r), _) => out.push(param(r.to_f64(), r.to_string())),
                (Err(_), Some(Number::Text(text))) => {
                    let spanned = Spanned::new(decl.span(), text.clone());
                    let e = self.expr(&spanned);
                    let mut uses_names = false;
                    e.node.visit_names(&mut |_, _| uses_names = true);
                    if uses_names {
                        derived.push((name.clone(), e));
                    } else {
                        match e.node.value(&|_| None) {
                            Some(v) if v.is_finite() => out.push(param(v, text.trim().to_string())),
                            _ => {
                                self.cx.error(
                                    ErrorKind::BadParameter {
                                        name: name.get_ref().clone(),
                                        why: format!("`{text}` has no finite real value"),
                                    },
                                    Some(decl.span()),
                                );
                                out.push(param(0.0, text.clone()));
                            }
                        }
                    }
                }
                (Err(why), _) => {
                    self.cx.error(
                        ErrorKind::BadParameter {
                            name: name.get_ref().clone(),
                            why,
                        },
                        Some(decl.span()),
                    );
                    // Still declared, so its uses are not reported as unknown;
                    // the model is rejected anyway.
                    out.push(param(0.0, String::new()));
                }
            }
        }
        (out, derived)
    }

    fn variables(
        &mut self,
        coords: Option<&Spanned<Names>>,
        vels: Option<&Spanned<Names>>,
        bodies: bool,
    ) -> (Kind, Vec<String>, Vec<String>) {
        match (coords, vels) {
            (Some(c), None) => {
                limits::variable_count(self.cx, c.get_ref().names.len(), c.span());
                self.coordinates(c)
            }
            (None, Some(v)) => {
                limits::variable_count(self.cx, v.get_ref().names.len(), v.span());
                self.instantaneous(v)
            }
            (Some(c), Some(_)) => {
                self.cx.error(
                    ErrorKind::Structure(
                        "declare either [coordinates] (velocities are their time derivatives) or [velocities] (an instantaneous model), not both".into(),
                    ),
                    Some(c.span()),
                );
                (Kind::Coordinates, Vec::new(), Vec::new())
            }
            // Bodies whose coordinates could not be found: the bodies
            // layer has said why.
            (None, None) if bodies => (Kind::Coordinates, Vec::new(), Vec::new()),
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

    /// Definitions, ordered so that each refers only to earlier ones; cycles
    /// are reported, and so is a definition that would expand past the
    /// limits once the ones it uses are substituted.
    fn definitions(&mut self, decls: Vec<(Spanned<String>, Expr)>) -> Vec<(String, Expr)> {
        let first_past = decls.get(MAX_DEFINITIONS).map(|(n, _)| n.span());
        if !limits::declarations(
            self.cx,
            (decls.len(), MAX_DEFINITIONS),
            "definitions",
            "",
            first_past,
        ) {
            return Vec::new();
        }
        let (names, exprs): (Vec<Spanned<String>>, Vec<Expr>) = decls.into_iter().unzip();
        let index: HashMap<&str, usize> = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.get_ref().as_str(), i))
            .collect();
        let uses: Vec<Vec<usize>> = exprs
            .iter()
            .map(|e| {
                let mut u = Vec::new();
                e.node.visit_names(&mut |n, _| u.extend(index.get(n)));
                u.sort_unstable();
                u.dedup();
                u
            })
            .collect();
        for (i, name) in names.iter().enumerate() {
            if reaches(&uses, i) {
                self.cx
                    .error(ErrorKind::Cycle(name.get_ref().clone()), Some(name.span()));
            }
        }
        let order = dependency_order(&uses);
        let ones = || vec![1u64; exprs.len()];
        let (mut size, mut degree, mut depth) = (ones(), ones(), ones());
        let mut divisions = vec![0u64; exprs.len()];
        let mut expanded: HashMap<&str, limits::Expansion> = HashMap::new();
        for &i in &order {
            let lookup = |table: &[u64], n: &str| index.get(n).map_or(1, |&j| table[j]);
            size[i] = exprs[i].node.size(&|n| lookup(&size, n));
            degree[i] = exprs[i].node.degree(&|n| lookup(&degree, n));
            depth[i] = exprs[i].node.depth(&|n| lookup(&depth, n));
            divisions[i] = exprs[i]
                .node
                .nested_divisions(&|n| index.get(n).map_or(0, |&j| divisions[j]));
            let e = limits::expansion(&exprs[i].node, degree[i], &expanded);
            let worst = e.worst;
            expanded.insert(names[i].get_ref(), e);
            let over = if divisions[i] > MAX_NESTED_DIVISIONS {
                Some(format!(
                    "definition `{}` nests {} divisions inside one another once the definitions it uses are substituted; the limit is {MAX_NESTED_DIVISIONS}",
                    names[i].get_ref(),
                    divisions[i]
                ))
            } else if depth[i] > MAX_EXPANDED_DEPTH {
                Some(format!(
                    "definition `{}` is nested {} levels deep once the definitions it uses are substituted; the limit is {MAX_EXPANDED_DEPTH}",
                    names[i].get_ref(),
                    depth[i]
                ))
            } else if worst > MAX_TERMS {
                Some(format!(
                    "definition `{}` may expand to {} terms as a polynomial once the definitions it uses are substituted; the limit is {MAX_TERMS}",
                    names[i].get_ref(),
                    limits::count(worst)
                ))
            } else if size[i] > MAX_EXPANDED_SIZE {
                Some(format!(
                    "definition `{}` expands to more than {MAX_EXPANDED_SIZE} terms once the definitions it uses are substituted",
                    names[i].get_ref()
                ))
            } else if degree[i] > MAX_DEGREE {
                Some(format!(
                    "definition `{}` reaches degree {} (the limit is {MAX_DEGREE})",
                    names[i].get_ref(),
                    degree[i]
                ))
            } else {
                None
            };
            if let Some(why) = over {
                self.cx.error(ErrorKind::Limit(why), Some(names[i].span()));
            }
        }
        order
            .into_iter()
            .map(|i| (names[i].get_ref().clone(), exprs[i].clone()))
            .collect()
    }

    fn walls(&mut self, kind: Kind, decls: &[Spanned<WallDecl>]) -> Vec<Wall> {
        let mut out = Vec::new();
        // Walls by their variant in the generated `Wall` enum.
        let mut variants: HashMap<String, String> = HashMap::new();
        for decl in decls {
            let w = decl.get_ref();
            let at = w.name().span();
            let name = w.name().get_ref().clone();
            self.check_ident(&name, at.clone(), false);
            if name.chars().any(|c| c.is_ascii_uppercase()) {
                self.cx.error(
                    ErrorKind::BadName {
                        name: name.clone(),
                        why: "a wall's name is snake_case (lower case, digits and `_`)".into(),
                    },
                    Some(at.clone()),
                );
            } else if let Some(first) = variants.insert(camel(&name), name.clone()) {
                let kind = if first == name {
                    ErrorKind::Duplicate {
                        name: name.clone(),
                        first: "wall",
                    }
                } else {
                    ErrorKind::BadName {
                        name: name.clone(),
                        why: format!(
                            "it and wall `{first}` would both be `Wall::{}` in the generated code",
                            camel(&name)
                        ),
                    }
                };
                self.cx.error(kind, Some(at.clone()));
            }
            match (kind, &w.surface, &w.normal_velocity) {
                // A wall met by a body (named, or the only one) or given
                // by shape, whose shape or body could not be read: the
                // bodies layer has said why.
                (Kind::Coordinates, None, _)
                    if w.body.is_some()
                        || w.plane.is_some()
                        || w.sphere.is_some()
                        || w.cylinder.is_some() => {}
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

    /// A derived parameter may use only parameters (and other derived
    /// ones), pi and e.
    fn only_parameters(&mut self, params: &[Param], derived: &[(Spanned<String>, Expr)]) {
        for (name, e) in derived {
            let mut bad = Vec::new();
            e.node.visit_names(&mut |k, r| {
                // Undeclared names are reported as unknown elsewhere.
                if self.names.contains_key(k)
                    && !params.iter().any(|p| p.name == k)
                    && !derived.iter().any(|(d, _)| d.get_ref() == k)
                {
                    bad.push((k.to_string(), r.clone()));
                }
            });
            for (k, r) in bad {
                self.cx.error(
                    ErrorKind::BadParameter {
                        name: name.get_ref().clone(),
                        why: format!(
                            "`{k}` is not a parameter: a parameter's value may use other parameters, pi and e"
                        ),
                    },
                    Some(e.at(&r)),
                );
            }
        }
    }
}
