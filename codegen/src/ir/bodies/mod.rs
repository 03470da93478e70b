//! The bodies layer: a model file may describe rigid bodies, fields,
//! rolling and knife-edge constraints and walls by shape and law, instead of
//! T, V and the rows by hand. This stage runs on the file's shape before
//! validation and writes what it derives into the same places a hand-written
//! file fills ([definitions], [dynamics], each wall's `surface` and
//! `contact`), each text carrying the span of the declaration it came from,
//! so that everything after it (validation, derivation, both back ends)
//! takes a body model exactly as the equivalent hand-written one.
//!
//! What is derived, for a body with centre S(q), mass m, inertia I about the
//! centre in the body frame and attitude R(q):
//! - the centre's velocity Ṡ = Σ ∂S/∂qᵢ q̇ᵢ and the angular velocity ω
//!   (fixed frame) and Ω (body frame), from the attitude (`frames.rs`), as
//!   definitions `{body}_vx` … and `{body}_wx` … (`{body}_w1` … in the body
//!   frame) where a component is more than a name;
//! - T = ½ m |Ṡ|² + ½ Ωᵀ I Ω (½ J |ω|² for a ball). For a quaternion, its
//!   norm is a holonomic constraint and 2 tr(I)/3 (e · ė)² is added to T: it
//!   vanishes to second order on |e| = 1 and makes G positive definite (for
//!   a ball the sum is 2 J |ė|² on |e| = 1, which is what is written);
//! - V = −Σ m g · S for uniform gravity g, and ½ k (|P₁ − P₂| − L)² for a
//!   spring between two points, each of a body or fixed (`spring.rs`);
//! - a ball rolling on a plane: its contact point C = S − r n at rest, as
//!   the two rows Ċ · eᵢ across the normal's largest component, and the
//!   height n · S − offset − r = 0 as a holonomic constraint where it varies;
//! - a disk (radius R, axis e) rolling on a plane: its rim's point nearest
//!   the plane, C = S − R u, u = w/|w|, w = n − (n·e)e, at rest; the
//!   position keeps it on the plane (n·S − offset = R|w|, checked), so
//!   that u = R w/(n·S − offset) needs no root; a smooth plane wall meets
//!   it at the rim's point nearest it, f = n·S − offset − R√(1 − (n·e)²);
//! - a knife edge: (n × R b) · Ṡ = 0 for the blade b on the plane of normal n;
//! - a wall by shape: the surface f, the signed distance of the body's
//!   contact sphere (radius r, 0 for a point) to the plane, or, from inside
//!   a sphere or cylinder of radius R, ((R − r)² − d²)/(2(R − r)) with d the
//!   centre's distance to the centre or axis, which has the distance's zero
//!   set, side and gradient on the wall; `rough` adds the contact point's
//!   velocity as contact rows (the paper's no-slip rows), `smooth` none.

mod body;
mod contact;
mod declared;
mod frames;
mod spring;
mod sym;

use std::collections::{HashMap, HashSet};
use std::ops::Range;

use toml::Spanned;

use super::expr::parse;
use super::file::{Dynamics, File, Number};
use crate::diag::{Collector, ErrorKind};
use declared::{
    MAX_SUBSTITUTED_DEPTH, MAX_SUBSTITUTED_SIZE, coordinates_of_bodies, declared_names,
    parameter_values, user_definitions,
};
use frames::Vec3;
use sym::{Sym, add, mul, name};

/// Expands the file's bodies into definitions, T, V, rows and surfaces.
pub(super) fn expand(file: &mut File, cx: &mut Collector) -> Vec<FromBodies> {
    if file.body.is_empty() {
        refuse_without_bodies(file, cx);
        return Vec::new();
    }
    let inferred = file.coordinates.is_none() && file.velocities.is_none();
    if inferred {
        file.coordinates = coordinates_of_bodies(file);
    }
    let Some(coordinates) = file.coordinates.as_ref() else {
        let at = file.body[0].span();
        cx.error(
            structure("bodies move with coordinates: declare [coordinates] (no body's position or attitude names one whole)"),
            Some(at),
        );
        return Vec::new();
    };
    let names: Vec<String> = coordinates
        .get_ref()
        .names
        .iter()
        .map(|n| n.get_ref().clone())
        .collect();
    let rates: Vec<String> = match &coordinates.get_ref().velocities {
        Some(v) => v.iter().map(|n| n.get_ref().clone()).collect(),
        None => names.iter().map(|n| format!("{n}_dot")).collect(),
    };
    let definitions = user_definitions(file);
    let unexpanded = file
        .definitions
        .keys()
        .map(|n| n.get_ref().clone())
        .filter(|n| !definitions.contains_key(n))
        .collect();
    let mut layer = Layer {
        cx,
        values: parameter_values(file),
        definitions,
        unexpanded,
        declared_bodies: file
            .body
            .iter()
            .map(|b| b.get_ref().name.get_ref().clone())
            .collect(),
        declared: declared_names(file),
        coordinates: names,
        rates,
        out: Derived::default(),
        bodies: HashMap::new(),
    };
    let gravity = file
        .fields
        .as_ref()
        .and_then(|f| f.get_ref().gravity.as_ref())
        .and_then(|g| layer.vector(g));
    for decl in &file.body {
        layer.body(decl, gravity.as_ref());
    }
    for decl in &file.rolling {
        layer.rolling(decl);
    }
    for decl in &file.knife_edge {
        layer.knife_edge(decl);
    }
    for decl in &file.spring {
        layer.spring(decl);
    }
    for decl in &mut file.wall {
        let span = decl.span();
        layer.wall(decl.get_mut(), span);
    }
    let out = layer.out;
    let shown = |what: &str, t: &Spanned<String>| FromBodies {
        what: what.to_string(),
        text: t.get_ref().clone(),
        span: t.span(),
    };
    let mut record: Vec<FromBodies> = Vec::new();
    if let Some(c) = file.coordinates.as_ref().filter(|_| inferred) {
        let names: Vec<&str> = c
            .get_ref()
            .names
            .iter()
            .map(|n| n.get_ref().as_str())
            .collect();
        record.push(FromBodies {
            what: "coordinates".into(),
            text: names.join(", "),
            span: c.span(),
        });
    }
    record.extend(out.definitions.iter().map(|(n, t)| shown(n.get_ref(), t)));
    record.extend(out.kinetic.iter().map(|t| shown("T", t)));
    record.extend(out.potential.iter().map(|t| shown("V", t)));
    record.extend(out.holonomic.iter().map(|t| shown("holonomic h", t)));
    record.extend(out.constraints.iter().map(|t| shown("row of A", t)));
    for w in file
        .wall
        .iter()
        .map(|w| w.get_ref())
        .filter(|w| w.body.is_some())
    {
        let name = w.name().get_ref();
        record.extend(
            w.surface
                .iter()
                .map(|t| shown(&format!("wall `{name}` surface"), t)),
        );
        record.extend(
            w.contact
                .iter()
                .map(|t| shown(&format!("wall `{name}` contact row"), t)),
        );
    }
    for (n, text) in out.definitions {
        file.definitions.insert(n, text);
    }
    let body_span = file.body[0].span();
    let dynamics = file
        .dynamics
        .get_or_insert_with(|| Spanned::new(body_span.clone(), Dynamics::default()))
        .get_mut();
    let join = |own: Option<&Spanned<String>>, derived: Vec<Spanned<String>>| {
        let derived: Vec<String> = derived.into_iter().map(|t| t.into_inner()).collect();
        let derived = derived.join(" + ");
        match (own, derived.is_empty()) {
            (own, true) => own.cloned(),
            (Some(own), false) => Some(Spanned::new(
                own.span(),
                format!("{} + {derived}", own.get_ref()),
            )),
            (None, false) => Some(Spanned::new(body_span.clone(), derived)),
        }
    };
    dynamics.kinetic_energy = join(dynamics.kinetic_energy.as_ref(), out.kinetic);
    dynamics.potential = join(dynamics.potential.as_ref(), out.potential);
    dynamics.holonomic.extend(out.holonomic);
    dynamics.constraints.extend(out.constraints);
    record
}

/// One thing the bodies layer derived, for `derive` to show: what it is
/// (`T`, `constraint`, `wall floor: contact`, …), its text, and the span
/// of the declaration it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct FromBodies {
    /// What it is.
    pub what: String,
    /// The expression, in the model language.
    pub text: String,
    /// Where its declaration is in the file.
    pub span: Range<usize>,
}

/// What the layer derives, text by text with its declaration's span.
#[derive(Default)]
struct Derived {
    definitions: Vec<(Spanned<String>, Spanned<String>)>,
    kinetic: Vec<Spanned<String>>,
    potential: Vec<Spanned<String>>,
    holonomic: Vec<Spanned<String>>,
    constraints: Vec<Spanned<String>>,
}

/// A body as the later declarations use it.
#[derive(Clone)]
struct Body {
    position: Vec3,
    velocity: Vec3,
    /// ω in the fixed frame (definition names where compound).
    omega: Vec3,
    rotation: frames::Mat3,
    radius: Option<Sym>,
    /// A disk's radius and its axis in the fixed frame.
    disk: Option<(Sym, Vec3)>,
}

struct Layer<'a> {
    cx: &'a mut Collector,
    /// Parameter values from the file, for the checks that need numbers.
    values: HashMap<String, f64>,
    /// The file's definitions, to be substituted into positions and angles.
    definitions: HashMap<String, Sym>,
    /// Every name the file declares.
    declared: HashSet<String>,
    /// The file's definitions left out of `definitions`.
    unexpanded: HashSet<String>,
    /// The names of every `[[body]]`, read or not.
    declared_bodies: HashSet<String>,
    coordinates: Vec<String>,
    rates: Vec<String>,
    out: Derived,
    bodies: HashMap<String, Body>,
}

fn structure(message: impl Into<String>) -> ErrorKind {
    ErrorKind::Structure(message.into())
}

/// The text of a number or expression of the file.
fn text_of(n: &Number) -> String {
    match n {
        Number::Int(i) => i.to_string(),
        Number::Float(f) => format!("{f}"),
        Number::Text(t) => t.clone(),
    }
}

impl Layer<'_> {
    /// An expression of the file, definitions substituted.
    fn sym(&mut self, n: &Spanned<Number>) -> Option<Sym> {
        self.sym_text(&text_of(n.get_ref()), n.span())
    }

    fn sym_text(&mut self, text: &str, span: Range<usize>) -> Option<Sym> {
        match parse(text) {
            Ok(node) => {
                let (mut left_out, mut unknown) = (None, Vec::new());
                node.visit_names(&mut |x, _| {
                    if self.unexpanded.contains(x) {
                        left_out.get_or_insert_with(|| x.to_string());
                    }
                    if !self.declared.contains(x) && !unknown.iter().any(|u| u == x) {
                        unknown.push(x.to_string());
                    }
                });
                // A name nothing declares would be taken for a constant
                // (a rotor's own angle left out of [coordinates] would not
                // turn): it is refused here, since what the layer derives
                // from it may no longer contain it.
                for name in &unknown {
                    self.cx.error(
                        ErrorKind::UnknownName { name: name.clone() },
                        Some(span.clone()),
                    );
                }
                if !unknown.is_empty() {
                    return None;
                }
                if let Some(x) = left_out {
                    self.cx.error(
                        structure(format!(
                            "this uses definition `{x}`, which the bodies layer does not substitute: it is in a cycle, or larger than {MAX_SUBSTITUTED_SIZE} terms or {MAX_SUBSTITUTED_DEPTH} levels once the definitions it uses are substituted"
                        )),
                        Some(span),
                    );
                    return None;
                }
                Some(Sym::from_node(&node, &self.definitions))
            }
            Err(e) => {
                self.cx.error(ErrorKind::Syntax(e.message), Some(span));
                None
            }
        }
    }

    /// A vector of three expressions.
    fn vector(&mut self, v: &Spanned<Vec<Spanned<Number>>>) -> Option<Vec3> {
        if v.get_ref().len() != 3 {
            self.cx.error(
                structure(format!(
                    "a vector has three components (x, y, z); this one has {}",
                    v.get_ref().len()
                )),
                Some(v.span()),
            );
            return None;
        }
        let parts: Vec<Sym> = v
            .get_ref()
            .iter()
            .map(|c| self.sym(c))
            .collect::<Option<_>>()?;
        Some(std::array::from_fn(|i| parts[i].clone()))
    }

    /// Its value at the file's parameter values, where it has one.
    fn value(&self, s: &Sym) -> Option<f64> {
        s.value(&|n| self.values.get(n).copied())
    }

    fn is_coordinate(&self, n: &str) -> bool {
        self.coordinates.iter().any(|c| c == n)
    }

    /// The time derivative of an expression of the coordinates.
    fn rate(&self, s: &Sym) -> Sym {
        add(self
            .coordinates
            .iter()
            .zip(&self.rates)
            .map(|(q, v)| mul([s.derivative(q), name(v)])))
    }

    /// Refuses an expression that should depend on the coordinates only.
    fn positional(&mut self, s: &Sym, what: &str, span: Range<usize>) -> bool {
        let rates = &self.rates;
        if s.depends(&|n| rates.iter().any(|v| v == n)) {
            self.cx.error(
                structure(format!(
                    "{what} depends on a velocity; it is a function of the coordinates"
                )),
                Some(span),
            );
            return false;
        }
        true
    }

    /// `value` as a definition `{body}_{suffix}` where it is more than a
    /// name or a number, so that T and the rows read like hand-written ones.
    fn named(&mut self, value: Sym, body: &Spanned<String>, suffix: &str, what: &str) -> Sym {
        if matches!(value, Sym::Name(_) | Sym::Num(_)) {
            return value;
        }
        let n = format!("{}_{suffix}", body.get_ref());
        if self.declared.contains(&n) {
            self.cx.error(
                structure(format!(
                    "body `{}` names {what} `{n}`, a name the file already declares",
                    body.get_ref()
                )),
                Some(body.span()),
            );
        }
        self.declared.insert(n.clone());
        self.out.definitions.push((
            Spanned::new(body.span(), n.clone()),
            Spanned::new(body.span(), value.to_string()),
        ));
        name(&n)
    }
}

/// Without bodies, the declarations that need them are refused.
fn refuse_without_bodies(file: &File, cx: &mut Collector) {
    let mut spans: Vec<Range<usize>> = file.rolling.iter().map(|r| r.span()).collect();
    spans.extend(file.knife_edge.iter().map(|k| k.span()));
    spans.extend(file.spring.iter().map(|k| k.span()));
    spans.extend(file.fields.iter().map(|f| f.span()));
    spans.extend(
        file.wall
            .iter()
            .filter(|w| {
                let w = w.get_ref();
                w.body.is_some()
                    || w.plane.is_some()
                    || w.sphere.is_some()
                    || w.cylinder.is_some()
                    || w.law.is_some()
            })
            .map(|w| w.span()),
    );
    for at in spans {
        cx.error(
            structure("this declaration acts on bodies, and the file declares no [[body]]"),
            Some(at),
        );
    }
}
