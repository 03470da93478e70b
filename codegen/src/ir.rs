//! Stage 1: a model file (TOML) to the validated model IR.
//!
//! Every error is collected with its place in the file; symbolic work only
//! starts on a model that passed this stage, so the symbolic engine never sees
//! an undeclared name or a malformed expression. This stage does not use the
//! symbolic engine at all.

use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::path::Path;

use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

use crate::diag::{Collector, ErrorKind, ModelErrors};

/// Functions a model's expressions may call.
pub const FUNCTIONS: &[&str] = &["sin", "cos", "tan", "exp", "log", "sqrt"];

/// Names models may not declare: functions, constants and names the
/// generated code uses itself.
const RESERVED: &[&str] = &[
    "sin", "cos", "tan", "exp", "log", "sqrt", "pi", "e", "i", "q", "v", "p", "out", "params",
    "wall", "self", "Self",
];

/// Rust keywords (strict and reserved, 2024 edition): not usable as names.
const RUST_KEYWORDS: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern",
    "false", "fn", "for", "gen", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut",
    "pub", "ref", "return", "static", "struct", "super", "trait", "true", "type", "unsafe", "use",
    "where", "while", "abstract", "become", "box", "do", "final", "macro", "override", "priv",
    "try", "typeof", "unsized", "virtual", "yield",
];

// ---------------------------------------------------------------- the file

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    model: Spanned<Header>,
    #[serde(default)]
    parameters: IndexMap<Spanned<String>, Spanned<ParamDecl>>,
    coordinates: Option<Spanned<Names>>,
    velocities: Option<Spanned<Names>>,
    #[serde(default)]
    definitions: IndexMap<Spanned<String>, Spanned<String>>,
    dynamics: Spanned<Dynamics>,
    #[serde(default)]
    wall: Vec<Spanned<WallDecl>>,
    #[serde(default)]
    initial: IndexMap<Spanned<String>, Spanned<Number>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    name: Spanned<String>,
    #[serde(default)]
    doc: String,
    projector: Option<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum ParamDecl {
    Full {
        value: Option<Number>,
        #[serde(default)]
        doc: String,
    },
    Bare(Number),
}

#[derive(Debug, Deserialize, Clone)]
#[serde(untagged)]
enum Number {
    Int(i64),
    Float(f64),
    Text(String),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Names {
    names: Vec<Spanned<String>>,
    /// For coordinates: the names of their velocities (default `<name>_dot`).
    velocities: Option<Vec<Spanned<String>>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Dynamics {
    kinetic_energy: Spanned<String>,
    potential: Option<Spanned<String>>,
    #[serde(default)]
    holonomic: Vec<Spanned<String>>,
    #[serde(default)]
    constraints: Vec<Spanned<String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct WallDecl {
    name: Spanned<String>,
    #[serde(default)]
    doc: String,
    surface: Option<Spanned<String>>,
    normal_velocity: Option<Spanned<String>>,
    #[serde(default)]
    contact: Vec<Spanned<String>>,
}

// ---------------------------------------------------------------- the IR

/// An exact rational number p/q with q > 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rational {
    /// Numerator.
    pub num: i128,
    /// Denominator (positive).
    pub den: i128,
}

impl Rational {
    /// Nearest f64.
    pub fn to_f64(self) -> f64 {
        self.num as f64 / self.den as f64
    }
}

impl std::fmt::Display for Rational {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

/// An expression from the model file, with where it stands.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    /// The text, definitions not yet substituted.
    pub text: String,
    /// Byte range of the string in the file.
    pub span: Range<usize>,
}

/// A declared parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// Its name.
    pub name: String,
    /// The file's value.
    pub value: Rational,
    /// Its doc text.
    pub doc: String,
}

/// Whether the model has coordinates or only velocities.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Generalized coordinates q; the velocities are q̇.
    Coordinates,
    /// Velocities only, at the collision instant (the paper's §3 style).
    Instantaneous,
}

/// How the walls' P and collision maps are evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProjectorMode {
    /// Symbolic while G is sparse (at most 2n non-zero entries off the
    /// diagonal: any n ≤ 3, or a G that couples few velocities), structured
    /// otherwise.
    Auto,
    /// P and (I − 2P)v derived exactly and emitted as closed forms.
    Symbolic,
    /// G and B emitted; P v solved at run time by a fixed-size
    /// factorisation (for models whose symbolic P would be too large).
    Structured,
}

/// A wall N = {f = 0} with its contact constraints.
#[derive(Debug, Clone, PartialEq)]
pub struct Wall {
    /// Its name.
    pub name: String,
    /// Its doc text.
    pub doc: String,
    /// f(q) for coordinate models.
    pub surface: Option<Expr>,
    /// The normal velocity row for instantaneous models.
    pub normal_velocity: Option<Expr>,
    /// Extra constraints that hold on the wall.
    pub contact: Vec<Expr>,
    /// Where the wall is declared.
    pub span: Range<usize>,
}

/// A validated model.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// snake_case name.
    pub name: String,
    /// Doc text.
    pub doc: String,
    /// Parameters in file order.
    pub params: Vec<Param>,
    /// Kind of model.
    pub kind: Kind,
    /// Coordinate names (empty for instantaneous models).
    pub coordinates: Vec<String>,
    /// Velocity names.
    pub velocities: Vec<String>,
    /// Definitions, in file order, each already free of other definitions.
    pub definitions: Vec<(String, Expr)>,
    /// T.
    pub kinetic_energy: Expr,
    /// V (None: zero).
    pub potential: Option<Expr>,
    /// Holonomic constraints h(q) = 0 (coordinate models only).
    pub holonomic: Vec<Expr>,
    /// Rows of A, each = 0.
    pub constraints: Vec<Expr>,
    /// Walls in file order.
    pub walls: Vec<Wall>,
    /// How P and the collision maps are evaluated.
    pub projector: ProjectorMode,
    /// The initial state for simulations: one value per coordinate, then
    /// one per velocity (zero where the file's `[initial]` is silent).
    pub initial: Vec<f64>,
    /// The model file's text.
    pub source: String,
    /// The model file.
    pub file: std::path::PathBuf,
}

impl Model {
    /// The model's type name in generated code (CamelCase).
    pub fn type_name(&self) -> String {
        camel(&self.name)
    }
}

/// CamelCase of a snake_case name.
pub fn camel(name: &str) -> String {
    name.split('_')
        .filter(|s| !s.is_empty())
        .map(|s| {
            let mut c = s.chars();
            match c.next() {
                Some(f) => f.to_uppercase().chain(c).collect::<String>(),
                None => String::new(),
            }
        })
        .collect()
}

/// Reads and validates the model file at `path`.
pub fn load(path: &Path) -> Result<Model, ModelErrors> {
    match std::fs::read_to_string(path) {
        Ok(text) => parse(path, &text),
        Err(e) => {
            let mut c = Collector::new(path, "");
            c.error(ErrorKind::Io(e.to_string()), None);
            Err(c.into_errors())
        }
    }
}

/// Validates the model text `text` (read from `path`).
pub fn parse(path: &Path, text: &str) -> Result<Model, ModelErrors> {
    let mut cx = Collector::new(path, text);
    let file: File = match toml::from_str(text) {
        Ok(f) => f,
        Err(e) => {
            let msg = e.message().to_string();
            cx.error(ErrorKind::Toml(msg), e.span());
            return Err(cx.into_errors());
        }
    };
    let model = Validator {
        cx: &mut cx,
        text,
        names: HashMap::new(),
    }
    .model(path, file);
    if let Some(m) = &model {
        check_names(m, &mut cx);
    }
    match model {
        Some(m) => cx.finish(m),
        None => Err(cx.into_errors()),
    }
}

struct Validator<'a> {
    cx: &'a mut Collector,
    text: &'a str,
    /// Declared name → what it is.
    names: HashMap<String, &'static str>,
}

impl Validator<'_> {
    fn model(&mut self, path: &Path, file: File) -> Option<Model> {
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

        let projector = match header
            .projector
            .as_ref()
            .map(|p| (p.get_ref().as_str(), p.span()))
        {
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
        };
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
            (Some(c), None) => {
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
            (None, Some(v)) => {
                if v.get_ref().velocities.is_some() {
                    self.cx.error(
                        ErrorKind::Structure(
                            "`velocities` takes only `names`; `velocities.velocities` is for coordinates".into(),
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
                (Kind::Coordinates, None, _) => self.cx.error(
                    ErrorKind::Structure(format!(
                        "wall `{name}` needs `surface`, the function f(q) with motion in f >= 0"
                    )),
                    Some(decl.span()),
                ),
                (Kind::Coordinates, Some(_), Some(n)) => self.cx.error(
                    ErrorKind::Structure(format!(
                        "wall `{name}`: a model with coordinates derives the normal velocity from `surface`; remove `normal_velocity`"
                    )),
                    Some(n.span()),
                ),
                (Kind::Instantaneous, _, None) => self.cx.error(
                    ErrorKind::Structure(format!(
                        "wall `{name}` needs `normal_velocity`: an instantaneous model has no coordinates to derive it from"
                    )),
                    Some(decl.span()),
                ),
                (Kind::Instantaneous, Some(s), Some(_)) => self.cx.error(
                    ErrorKind::Structure(format!(
                        "wall `{name}`: an instantaneous model has no coordinates, so no `surface`"
                    )),
                    Some(s.span()),
                ),
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
                Err(why) => self.cx.error(
                    ErrorKind::Structure(format!("[initial] `{n}`: {why}")),
                    Some(value.span()),
                ),
            }
        }
        out
    }

    fn declare(&mut self, name: &Spanned<String>, what: &'static str) {
        let n = name.get_ref();
        self.check_ident(n, name.span(), true);
        if let Some(first) = self.names.get(n.as_str()) {
            self.cx.error(
                ErrorKind::Duplicate {
                    name: n.clone(),
                    first,
                },
                Some(name.span()),
            );
        } else {
            self.names.insert(n.clone(), what);
        }
    }

    fn check_ident(&mut self, name: &str, span: Range<usize>, symbol: bool) {
        let why = if name.is_empty() {
            Some("it is empty".to_string())
        } else if !name.starts_with(|c: char| c.is_ascii_alphabetic()) {
            Some("a name starts with a letter".into())
        } else if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            Some("a name has only ASCII letters, digits and `_`".into())
        } else if name.ends_with('_') {
            Some("a name may not end with `_`".into())
        } else if name.contains("__") {
            Some("a name may not contain `__`".into())
        } else if RUST_KEYWORDS.contains(&name) {
            Some("it is a Rust keyword".into())
        } else if symbol && RESERVED.contains(&name) {
            Some("it is reserved (a function, a constant or a name the generated code uses)".into())
        } else {
            None
        };
        if let Some(why) = why {
            self.cx.error(
                ErrorKind::BadName {
                    name: name.to_string(),
                    why,
                },
                Some(span),
            );
        }
    }

    /// Checks an expression's tokens; unknown names are checked later, once
    /// every declaration is known ([`check_names`]).
    fn expr(&mut self, s: &Spanned<String>) -> Expr {
        let expr = Expr {
            text: s.get_ref().clone(),
            span: s.span(),
        };
        let base = content_start(self.text, &expr);
        let mut depth: i64 = 0;
        let mut empty = true;
        for tok in tokens(&expr.text) {
            empty = false;
            let at = |r: &Range<usize>| base.map(|b| b + r.start..b + r.end).or(Some(s.span()));
            match tok {
                Token::Bad(c, r) => self.cx.error(
                    ErrorKind::Syntax(format!("unexpected character `{c}`")),
                    at(&r),
                ),
                Token::Decimal(t, r) => self.cx.error(
                    ErrorKind::Syntax(format!(
                        "`{t}` is a decimal number; models are exact: write it as a fraction"
                    )),
                    at(&r),
                ),
                Token::Open => depth += 1,
                Token::Close(r) => {
                    depth -= 1;
                    if depth < 0 {
                        self.cx
                            .error(ErrorKind::Syntax("unmatched `)`".into()), at(&r));
                        depth = 0;
                    }
                }
                Token::Call(n, r) if !FUNCTIONS.contains(&n) => self.cx.error(
                    ErrorKind::UnknownFunction {
                        name: n.to_string(),
                    },
                    at(&r),
                ),
                _ => {}
            }
        }
        if empty {
            self.cx.error(
                ErrorKind::Syntax("the expression is empty".into()),
                Some(s.span()),
            );
        }
        if depth > 0 {
            self.cx
                .error(ErrorKind::Syntax("unclosed `(`".into()), Some(s.span()));
        }
        expr
    }
}

/// Reports every name used in the model's expressions that is not declared.
fn check_names(model: &Model, cx: &mut Collector) {
    let declared: std::collections::HashSet<&str> = model
        .params
        .iter()
        .map(|p| p.name.as_str())
        .chain(model.coordinates.iter().map(String::as_str))
        .chain(model.velocities.iter().map(String::as_str))
        .chain(model.definitions.iter().map(|(n, _)| n.as_str()))
        .collect();
    for e in model.expressions() {
        let base = content_start(&model.source, e);
        for tok in tokens(&e.text) {
            if let Token::Name(n, r) = tok
                && !declared.contains(n)
            {
                cx.error(
                    ErrorKind::UnknownName {
                        name: n.to_string(),
                    },
                    base.map(|b| b + r.start..b + r.end)
                        .or(Some(e.span.clone())),
                );
            }
        }
    }
}

impl Model {
    /// Every expression of the model.
    pub fn expressions(&self) -> impl Iterator<Item = &Expr> {
        self.definitions
            .iter()
            .map(|(_, e)| e)
            .chain(std::iter::once(&self.kinetic_energy))
            .chain(self.potential.iter())
            .chain(self.holonomic.iter())
            .chain(self.constraints.iter())
            .chain(self.walls.iter().flat_map(|w| {
                w.surface
                    .iter()
                    .chain(w.normal_velocity.iter())
                    .chain(w.contact.iter())
            }))
    }
}

/// Byte offset in the file of the first character of the string's content,
/// when the file's text of the string is its value verbatim (no escapes).
fn content_start(file: &str, e: &Expr) -> Option<usize> {
    let raw = file.get(e.span.clone())?;
    let (open, rest) = if raw.starts_with("\"\"\"") || raw.starts_with("'''") {
        let rest = &raw[3..];
        let skip = if rest.starts_with("\r\n") {
            2
        } else if rest.starts_with('\n') {
            1
        } else {
            0
        };
        (3 + skip, &rest[skip..])
    } else if raw.starts_with('"') || raw.starts_with('\'') {
        (1, &raw[1..])
    } else {
        return None;
    };
    rest.starts_with(e.text.as_str())
        .then_some(e.span.start + open)
}

#[derive(Debug)]
enum Token<'a> {
    Name(&'a str, Range<usize>),
    Call(&'a str, Range<usize>),
    Number,
    Decimal(&'a str, Range<usize>),
    Op,
    Open,
    Close(Range<usize>),
    Bad(char, Range<usize>),
}

/// A small lexer for the expression language: names, calls, integers,
/// + - * / ^ ( ) and white space.
fn tokens(s: &str) -> Vec<Token<'_>> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let c = s[i..].chars().next().unwrap_or(' ');
        let start = i;
        if c.is_ascii_alphabetic() || c == '_' {
            while i < s.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            let name = &s[start..i];
            let mut j = i;
            while j < s.len() && b[j].is_ascii_whitespace() {
                j += 1;
            }
            if j < s.len() && b[j] == b'(' {
                out.push(Token::Call(name, start..i));
            } else {
                out.push(Token::Name(name, start..i));
            }
        } else if c.is_ascii_digit() || c == '.' {
            let mut decimal = false;
            while i < s.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                decimal |= b[i] == b'.';
                i += 1;
            }
            if i < s.len() && (b[i] == b'e' || b[i] == b'E') && decimal {
                i += 1;
            }
            if decimal {
                out.push(Token::Decimal(&s[start..i], start..i));
            } else {
                out.push(Token::Number);
            }
        } else {
            i += c.len_utf8();
            out.push(match c {
                '+' | '-' | '*' | '/' | '^' | ',' => Token::Op,
                '(' => Token::Open,
                ')' => Token::Close(start..i),
                c if c.is_whitespace() => continue,
                c => Token::Bad(c, start..i),
            });
        }
    }
    out
}

/// An exact rational from a TOML value: an integer, a string "p/q", an
/// integer string, or a decimal (as a string or a TOML float), read exactly.
/// An initial value: an exact number, or one times `pi` (`pi/2`, `-3*pi/4`).
fn initial_value(n: &Number) -> Result<f64, String> {
    let Number::Text(t) = n else {
        return rational(n).map(Rational::to_f64);
    };
    let t: String = t.chars().filter(|c| !c.is_whitespace()).collect();
    let Some((before, after)) = t.split_once("pi") else {
        return rational(n).map(Rational::to_f64);
    };
    let coefficient = match before.strip_suffix('*').unwrap_or(before) {
        "" => 1.0,
        "-" => -1.0,
        c => rational(&Number::Text(c.to_string()))?.to_f64(),
    };
    let divisor = match after.strip_prefix('/') {
        None if after.is_empty() => 1.0,
        Some(d) => rational(&Number::Text(d.to_string()))?.to_f64(),
        None => {
            return Err(format!(
                "`{t}`: write a rational multiple of pi such as `pi/2` or `-3*pi/4`"
            ));
        }
    };
    if divisor == 0.0 {
        return Err(format!("`{t}` divides by zero"));
    }
    Ok(coefficient * std::f64::consts::PI / divisor)
}

fn rational(n: &Number) -> Result<Rational, String> {
    let text = match n {
        Number::Int(i) => {
            return Ok(Rational {
                num: *i as i128,
                den: 1,
            });
        }
        Number::Float(f) if !f.is_finite() => {
            return Err(format!("{f} is not a finite number"));
        }
        // A TOML float's shortest round-trip text is the number the user wrote.
        Number::Float(f) => format!("{f}"),
        Number::Text(t) => t.trim().to_string(),
    };
    let parse_int = |s: &str| -> Result<i128, String> {
        s.trim().parse::<i128>().map_err(|_| {
            format!(
                "`{text}` is not an exact number (write an integer, a fraction p/q or a decimal)"
            )
        })
    };
    let (num, den) = if let Some((p, q)) = text.split_once('/') {
        (parse_int(p)?, parse_int(q)?)
    } else if let Some((whole, frac)) = text.split_once('.') {
        if frac.is_empty() || !frac.chars().all(|c| c.is_ascii_digit()) || frac.len() > 18 {
            return Err(format!("`{text}` is not an exact decimal"));
        }
        let den = 10i128.pow(frac.len() as u32);
        let negative = whole.trim().starts_with('-');
        let w = if whole.trim() == "-" || whole.trim().is_empty() {
            0
        } else {
            parse_int(whole)?
        };
        let f = parse_int(frac)?;
        let num = w
            .checked_mul(den)
            .and_then(|x| {
                if negative {
                    x.checked_sub(f)
                } else {
                    x.checked_add(f)
                }
            })
            .ok_or_else(|| format!("`{text}` is too large"))?;
        (num, den)
    } else {
        (parse_int(&text)?, 1)
    };
    if den == 0 {
        return Err(format!("`{text}` divides by zero"));
    }
    let g = gcd(num.unsigned_abs(), den.unsigned_abs()) as i128;
    let (num, den) = (num / g, den / g);
    let (num, den) = if den < 0 { (-num, -den) } else { (num, den) };
    if num.unsigned_abs() > 1u128 << 60 || den > 1i128 << 60 {
        return Err(format!("`{text}` has a numerator or denominator too large"));
    }
    Ok(Rational { num, den })
}

fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a.max(1)
}
