//! Stage 1: a model file (TOML) to the validated model IR.
//!
//! Every error is collected with its place in the file; symbolic work only
//! starts on a model that passed this stage, so the symbolic engine never sees
//! an undeclared name or a malformed expression. This stage does not use the
//! symbolic engine at all.

mod bodies;
pub mod expr;
pub use bodies::FromBodies;
mod file;
mod initial;
mod limits;
mod names;
mod number;
mod order;
mod validate;

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use crate::diag::{Collector, ErrorKind, ModelErrors};
use file::File;
use validate::Validator;

pub use expr::{Constant, Function, Node, NodeKind};

/// Names models may not declare besides the functions': constants and
/// names the generated code uses itself.
pub(crate) const RESERVED: &[&str] = &[
    "pi", "e", "i", "q", "v", "p", "out", "params", "wall", "self", "Self",
];

/// Rust keywords (strict and reserved, 2024 edition): not usable as names.
pub(crate) const RUST_KEYWORDS: &[&str] = &[
    "self", "Self", "union", "as", "async", "await", "break", "const", "continue", "crate", "dyn",
    "else", "enum", "extern", "false", "fn", "for", "gen", "if", "impl", "in", "let", "loop",
    "match", "mod", "move", "mut", "pub", "ref", "return", "static", "struct", "super", "trait",
    "true", "type", "unsafe", "use", "where", "while", "abstract", "become", "box", "do", "final",
    "macro", "override", "priv", "try", "typeof", "unsized", "virtual", "yield",
];

/// Type names a generated file uses or defines besides the model's own: the
/// model's type (its name in CamelCase) may not be one of them.
pub(crate) const GENERATED_TYPE_NAMES: &[&str] = &[
    "Params",
    "Wall",
    "SeriesScratch",
    "Self",
    "Default",
    "Clone",
    "Copy",
    "Debug",
    "PartialEq",
    "Eq",
    "Hash",
    "Option",
    "Some",
    "None",
    "Result",
    "Ok",
    "Err",
    "Sized",
    "Send",
    "Sync",
    "Unpin",
    "Drop",
    "Fn",
    "FnMut",
    "FnOnce",
    "Box",
    "String",
    "Vec",
    "ToString",
    "ToOwned",
    "Iterator",
    "IntoIterator",
    "DoubleEndedIterator",
    "ExactSizeIterator",
    "Extend",
    "FromIterator",
    "Into",
    "From",
    "TryInto",
    "TryFrom",
    "AsRef",
    "AsMut",
    "Ord",
    "PartialOrd",
];

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
    /// Byte offset in the file of the text's first character, when the
    /// file holds the text verbatim (no escapes).
    pub base: Option<usize>,
    /// The parsed expression (spans relative to `text`).
    pub node: Node,
}

impl Expr {
    /// The file's byte range of `r`, a range in the expression's text (the
    /// whole string when the text is not verbatim in the file).
    pub fn at(&self, r: &Range<usize>) -> Range<usize> {
        match self.base {
            Some(b) => b + r.start..b + r.end.max(r.start + 1).min(self.text.len().max(1)),
            None => self.span.clone(),
        }
    }
}

/// A declared parameter (one with a value of its own; derived parameters
/// are definitions).
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// Its name.
    pub name: String,
    /// The file's value.
    pub value: f64,
    /// The value as the file writes it (`1/2`, `pi/6`).
    pub written: String,
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
    /// diagonal: any n ≤ 3, or a G that couples few velocities) and det G
    /// is within the budget, structured otherwise; and, with G⁻¹ exact,
    /// structured for a wall whose det(BG⁻¹Bᵀ) is past the budget.
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

/// A condition of `[initial]` on a rate that is not a velocity: the
/// definition `rate`, linear in the velocities (L(q) q̇), equals `value` at
/// the start.
#[derive(Debug, Clone, PartialEq)]
pub struct StartRate {
    /// The definition's name.
    pub name: String,
    /// The definition's name as an expression, placed at its `[initial]`
    /// key (errors in its row are reported there).
    pub rate: Expr,
    /// Its value, an expression of the parameters.
    pub value: Expr,
}

/// A validated model.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// snake_case name.
    pub name: String,
    /// Doc text.
    pub doc: String,
    /// Parameters in file order (those with values of their own).
    pub params: Vec<Param>,
    /// Derived parameters: values computed from other parameters, among
    /// the definitions (first there).
    pub derived: Vec<String>,
    /// Kind of model.
    pub kind: Kind,
    /// Coordinate names (empty for instantaneous models).
    pub coordinates: Vec<String>,
    /// Velocity names.
    pub velocities: Vec<String>,
    /// Derived parameters, then definitions, ordered so that each uses only
    /// earlier ones.
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
    /// The same state as expressions of the parameters, slot by slot
    /// (`None`: zero), so that it follows parameters set later.
    pub initial_state: Vec<Option<Expr>>,
    /// Conditions `[initial]` puts on rates that are not velocities (a
    /// definition linear in them, given a value), in file order.
    pub start_rates: Vec<StartRate>,
    /// What the bodies layer derived (T, V, rows, surfaces, definitions),
    /// in the file's order; empty for a file without `[[body]]`.
    pub from_bodies: Vec<FromBodies>,
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

    /// Which velocities the file's `[initial]` gives; the others follow
    /// from the constraints at the start (the runtime's
    /// `simulate::starting_velocity`).
    pub fn velocities_given(&self) -> Vec<bool> {
        let q = self.coordinates.len();
        self.initial_state
            .iter()
            .skip(q)
            .map(Option::is_some)
            .collect()
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

/// The most bytes a model file may have: far above any model's (the
/// built-in ones have a few KiB), so that a huge file or a device cannot
/// make the reader use memory without bound.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Reads and validates the model file at `path`.
pub fn load(path: &Path) -> Result<Model, ModelErrors> {
    let text = read_source(path)?;
    parse(path, &text)
}

/// The text of the file at `path`, read whole: a regular file (a FIFO
/// would block the reader, a device like /dev/zero never end) of at most
/// [`MAX_FILE_BYTES`], in UTF-8 (else the error is located at the first
/// byte that is not).
pub fn read_source(path: &Path) -> Result<String, ModelErrors> {
    use std::io::Read;
    let fail = |text: &str, kind: ErrorKind, span: Option<Range<usize>>| {
        let mut c = Collector::new(path, text);
        c.error(kind, span);
        c.into_errors()
    };
    let io = |e: std::io::Error| fail("", ErrorKind::Io(e.to_string()), None);
    let kind = std::fs::metadata(path).map_err(io)?.file_type();
    if !kind.is_file() {
        let what = if kind.is_dir() {
            "a directory"
        } else if kind.is_symlink() {
            "a broken link"
        } else {
            "a FIFO, socket or device"
        };
        return Err(fail("", ErrorKind::NotAFile(what.into()), None));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes))
        .map_err(io)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        let limit = MAX_FILE_BYTES;
        return Err(fail("", ErrorKind::TooLarge { limit }, None));
    }
    String::from_utf8(bytes).map_err(|e| {
        // The text up to the bad byte is as read, so positions in the
        // lossy text are the file's.
        let at = e.utf8_error().valid_up_to();
        let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
        fail(&text, ErrorKind::NotUtf8, Some(at..at + 1))
    })
}

/// Validates the model text `text` (read from `path`).
pub fn parse(path: &Path, text: &str) -> Result<Model, ModelErrors> {
    let mut cx = Collector::new(path, text);
    let mut file: File = match toml::from_str(text) {
        Ok(f) => f,
        Err(e) => {
            let msg = e.message().to_string();
            cx.error(ErrorKind::Toml(msg), e.span());
            return Err(cx.into_errors());
        }
    };
    name_the_only_wall(&mut file, &mut cx);
    let from_bodies = bodies::expand(&mut file, &mut cx);
    let model = Validator {
        cx: &mut cx,
        text,
        names: HashMap::new(),
    }
    .model(path, file);
    let model = model.map(|m| Model { from_bodies, ..m });
    if let Some(m) = &model {
        check_names(m, &mut cx);
        check_degrees(m, &mut cx);
        check_polynomial_in_velocities(m, &mut cx);
        check_velocity_degrees(m, &mut cx);
        check_constants(m, &mut cx);
    }
    match model {
        Some(m) => cx.finish(m),
        None => Err(cx.into_errors()),
    }
}

/// The name a model's only wall has when its file gives none.
const ONLY_WALL: &str = "wall";

/// A wall without `name` is [`ONLY_WALL`] when it is the model's only
/// one; among several, each unnamed wall is an error at its declaration
/// (and is left out, so that what follows reads named walls only).
fn name_the_only_wall(file: &mut File, cx: &mut Collector) {
    let count = file.wall.len();
    file.wall.retain_mut(|decl| {
        let span = decl.span();
        let w = decl.get_mut();
        if w.name.is_some() {
            return true;
        }
        if count == 1 {
            w.name = Some(toml::Spanned::new(span, ONLY_WALL.to_string()));
            return true;
        }
        cx.error(
            ErrorKind::Structure(format!(
                "the model has {count} walls: give each a `name` (only a model's only wall may leave it out: it is then `{ONLY_WALL}`)"
            )),
            Some(span),
        );
        false
    });
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
        e.node.visit_names(&mut |n, r| {
            if !declared.contains(n) {
                cx.error(
                    ErrorKind::UnknownName {
                        name: n.to_string(),
                    },
                    Some(e.at(r)),
                );
            }
        });
    }
}

/// Reports every expression whose polynomial degree, definitions
/// substituted, exceeds [`expr::MAX_DEGREE`].
fn check_degrees(model: &Model, cx: &mut Collector) {
    let mut degree: HashMap<&str, u64> = HashMap::new();
    let mut depth: HashMap<&str, u64> = HashMap::new();
    let mut expanded: HashMap<&str, limits::Expansion> = HashMap::new();
    let mut divisions: HashMap<&str, u64> = HashMap::new();
    let of = |table: &HashMap<&str, u64>, n: &str| table.get(n).copied().unwrap_or(1);
    let nested = |table: &HashMap<&str, u64>, n: &str| table.get(n).copied().unwrap_or(0);
    for (name, e) in &model.definitions {
        let d = e.node.degree(&|n| of(&degree, n));
        degree.insert(name, d);
        divisions.insert(name, e.node.nested_divisions(&|n| nested(&divisions, n)));
        depth.insert(name, e.node.depth(&|n| of(&depth, n)));
        let x = limits::expansion(&e.node, d, &expanded);
        expanded.insert(name, x);
    }
    let definitions = model.definitions.len();
    for e in model.expressions().skip(definitions) {
        let nesting = e.node.depth(&|n| of(&depth, n));
        let d = e.node.degree(&|n| of(&degree, n));
        let worst = limits::expansion(&e.node, d, &expanded).worst;
        let fractions = e.node.nested_divisions(&|n| nested(&divisions, n));
        if fractions > limits::MAX_NESTED_DIVISIONS {
            cx.error(
                ErrorKind::Limit(format!(
                    "the expression nests {fractions} divisions inside one another (definitions substituted); the limit is {}",
                    limits::MAX_NESTED_DIVISIONS
                )),
                Some(e.span.clone()),
            );
        } else if nesting > limits::MAX_EXPANDED_DEPTH {
            cx.error(
                ErrorKind::Limit(format!(
                    "the expression is nested {nesting} levels deep once the definitions it uses are substituted; the limit is {}",
                    limits::MAX_EXPANDED_DEPTH
                )),
                Some(e.span.clone()),
            );
        } else if worst > limits::MAX_TERMS {
            cx.error(
                ErrorKind::Limit(format!(
                    "the expression may expand to {} terms as a polynomial (definitions substituted); the limit is {}",
                    limits::count(worst),
                    limits::MAX_TERMS
                )),
                Some(e.span.clone()),
            );
        } else if d > expr::MAX_DEGREE {
            cx.error(
                ErrorKind::Limit(format!(
                    "the expression reaches polynomial degree {d}; the limit is {}",
                    expr::MAX_DEGREE
                )),
                Some(e.span.clone()),
            );
        }
    }
}

/// Reports every expression in which a velocity (or a definition that
/// depends on one) occurs inside a function, in a divisor or under a
/// fractional or negative power. T must be a quadratic form in the
/// velocities and every constraint row linear in them, so they can only
/// occur in sums, products and whole powers; the derivation's exact checks
/// of those degrees then stay polynomial arithmetic (with a definition of
/// the velocities raised to the power 41/2 in T, the derivation had not
/// returned after 90 s).
fn check_polynomial_in_velocities(model: &Model, cx: &mut Collector) {
    let mut varies: std::collections::HashSet<&str> =
        model.velocities.iter().map(String::as_str).collect();
    for (name, e) in &model.definitions {
        if e.node.depends(&|n| varies.contains(n)) {
            varies.insert(name);
        }
    }
    for e in model.expressions() {
        if let Some((span, name, place)) = e.node.non_polynomial(&|n| varies.contains(n)) {
            cx.error(
                ErrorKind::VelocityNotPolynomial { name, place },
                Some(e.at(&span)),
            );
        }
    }
}

/// Reports every expression with a constant part (one that names
/// nothing) that is not a finite number or is 0 where it divides, as
/// [`Node::constant_problem`](expr::Node::constant_problem) finds it: emitted
/// code would compute NaN, an infinity or a huge number there.
fn check_constants(model: &Model, cx: &mut Collector) {
    for e in model.expressions() {
        if let Some((span, what)) = e.node.constant_problem() {
            let text = e.text.get(span.clone()).unwrap_or_default().to_string();
            cx.error(
                ErrorKind::UndefinedConstant { text, what },
                Some(e.at(&span)),
            );
        }
    }
}

/// Reports T of degree above 2 in the velocities as written, and
/// constraint, contact and normal-velocity rows of degree above 1 (counted
/// through definitions), before the derivation expands anything: the
/// exact checks of those degrees come later, but the expansion of a
/// product of squared sums alone can take tens of gigabytes (a T of degree
/// 4 in chain_3's velocities did).
fn check_velocity_degrees(model: &Model, cx: &mut Collector) {
    let mut degree: HashMap<&str, u64> = model.velocities.iter().map(|v| (v.as_str(), 1)).collect();
    for (name, e) in &model.definitions {
        let d = e.node.degree_in(&|n| degree.get(n).copied().unwrap_or(0));
        if d > 0 {
            degree.insert(name, d);
        }
    }
    let of = |e: &Expr| e.node.degree_in(&|n| degree.get(n).copied().unwrap_or(0));
    let d = of(&model.kinetic_energy);
    if d > 2 {
        cx.error(
            ErrorKind::NotQuadratic(format!(
                "as written it has terms of degree {d} in the velocities"
            )),
            Some(model.kinetic_energy.span.clone()),
        );
    }
    let rows = (model.constraints.iter())
        .chain((model.walls.iter()).flat_map(|w| w.normal_velocity.iter().chain(w.contact.iter())))
        .chain(model.start_rates.iter().map(|r| &r.rate));
    for e in rows {
        let d = of(e);
        if d > 1 {
            cx.error(
                ErrorKind::NotLinear(format!(
                    "as written it has terms of degree {d} in the velocities"
                )),
                Some(e.span.clone()),
            );
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
