//! What the bodies layer reads of the file's own declarations: the
//! coordinates its bodies give (without `[coordinates]`), the parameters'
//! values for its numeric checks, the definitions it substitutes into
//! positions and angles, and every name the file declares.

use std::collections::{HashMap, HashSet};
use std::ops::Range;

use toml::Spanned;

use super::sym::Sym;
use super::text_of;
use crate::ir::expr::{Node, parse};
use crate::ir::file::{File, Names, Number, ParamDecl};
use crate::ir::names::ident_problem;

/// Without `[coordinates]`, a body model moves with the names its bodies'
/// positions and attitudes give whole (a position entry `"x"`, an angle,
/// an Euler angle, a quaternion component), in the order written, each
/// once, parameters, definitions and the velocities of the others
/// (`x_dot` beside `x`) left out: a name inside an expression
/// (`"R*sin(theta)"`) is not one (it must be declared, or be given whole
/// elsewhere). `None` when there is no such name.
pub(super) fn coordinates_of_bodies(file: &File) -> Option<Spanned<Names>> {
    let known: HashSet<&str> = (file.parameters.keys())
        .chain(file.definitions.keys())
        .map(|n| n.get_ref().as_str())
        .collect();
    let mut names: Vec<Spanned<String>> = Vec::new();
    let mut take = |text: &str, at: Range<usize>| {
        let text = text.trim();
        let fresh = !names.iter().any(|n| n.get_ref() == text);
        if fresh && !known.contains(text) && ident_problem(text, true).is_none() {
            names.push(Spanned::new(at, text.to_string()));
        }
    };
    for body in &file.body {
        let body = body.get_ref();
        for entry in body.position.get_ref() {
            if let Number::Text(t) = entry.get_ref() {
                take(t, entry.span());
            }
        }
        let Some(o) = &body.orientation else {
            continue;
        };
        let o = o.get_ref();
        let angles = (o.angles.iter())
            .chain(&o.quaternion)
            .flat_map(|a| a.get_ref());
        for n in o.angle.iter().chain(angles) {
            take(n.get_ref(), n.span());
        }
    }
    // `x_dot` beside `x` is x's velocity (by default), not a coordinate.
    let given: Vec<String> = names.iter().map(|n| n.get_ref().clone()).collect();
    names.retain(|n| !given.iter().any(|g| *n.get_ref() == format!("{g}_dot")));
    let at = file.body.first()?.span();
    (!names.is_empty()).then(|| {
        Spanned::new(
            at,
            Names {
                names,
                velocities: None,
            },
        )
    })
}

/// The parameters' values as the file gives them (derived ones computed
/// from the others), for the layer's numeric checks.
pub(super) fn parameter_values(file: &File) -> HashMap<String, f64> {
    let mut texts: Vec<(String, String)> = Vec::new();
    for (n, d) in &file.parameters {
        let value = match d.get_ref() {
            ParamDecl::Full { value: Some(v), .. } | ParamDecl::Bare(v) => text_of(v),
            ParamDecl::Full { value: None, .. } => continue,
        };
        texts.push((n.get_ref().clone(), value));
    }
    let mut values = HashMap::new();
    // Each pass computes at least one more, or stops.
    for _ in 0..texts.len() {
        let before = values.len();
        for (n, t) in &texts {
            if values.contains_key(n) {
                continue;
            }
            if let Some(v) = parse(t)
                .ok()
                .and_then(|node| node.value(&|x| values.get(x).copied()))
            {
                values.insert(n.clone(), v);
            }
        }
        if values.len() == before {
            break;
        }
    }
    values
}

/// The most nodes, and the deepest nesting, of a definition the layer
/// substitutes into positions and angles: far above a real model's, and
/// small enough that differentiating what uses it stays cheap.
pub(super) const MAX_SUBSTITUTED_SIZE: u64 = 4096;
pub(super) const MAX_SUBSTITUTED_DEPTH: u64 = 128;

/// The file's definitions as expressions, each with the definitions it
/// uses substituted, in dependency order (Kahn's algorithm: linear in the
/// definitions' size). Those in a cycle, or past the bounds above, are left
/// out: an expression of the layer that uses one is refused
/// ([`Layer::sym_text`]), and the validator reports cycles.
pub(super) fn user_definitions(file: &File) -> HashMap<String, Sym> {
    let parsed: HashMap<String, Node> = file
        .definitions
        .iter()
        .filter_map(|(n, t)| {
            parse(t.get_ref())
                .ok()
                .map(|node| (n.get_ref().clone(), node))
        })
        .collect();
    // Which definitions each one uses, and who uses it.
    let mut waiting: HashMap<&str, usize> = HashMap::new();
    let mut users: HashMap<&str, Vec<&str>> = HashMap::new();
    for (n, node) in &parsed {
        let mut uses: HashSet<&str> = HashSet::new();
        node.visit_names(&mut |x, _| {
            if let Some((m, _)) = parsed.get_key_value(x) {
                uses.insert(m.as_str());
            }
        });
        waiting.insert(n.as_str(), uses.len());
        for u in uses {
            users.entry(u).or_default().push(n.as_str());
        }
    }
    let mut ready: Vec<&str> = waiting
        .iter()
        .filter(|(_, w)| **w == 0)
        .map(|(n, _)| *n)
        .collect();
    let mut done: HashMap<String, Sym> = HashMap::new();
    let mut sizes: HashMap<&str, (u64, u64)> = HashMap::new();
    while let Some(n) = ready.pop() {
        let node = &parsed[n];
        // A name left out counts past the bounds, so what uses it is too.
        let over = (MAX_SUBSTITUTED_SIZE + 1, MAX_SUBSTITUTED_DEPTH + 1);
        let of = |x: &str| match (sizes.get(x), parsed.contains_key(x)) {
            (Some(s), _) => *s,
            (None, true) => over,
            (None, false) => (1, 1),
        };
        let size = node.size(&|x| of(x).0);
        let depth = node.depth(&|x| of(x).1);
        if size <= MAX_SUBSTITUTED_SIZE && depth <= MAX_SUBSTITUTED_DEPTH {
            sizes.insert(n, (size, depth));
            done.insert(n.to_string(), Sym::from_node(node, &done));
        }
        for u in users.get(n).into_iter().flatten() {
            if let Some(w) = waiting.get_mut(u) {
                *w -= 1;
                if *w == 0 {
                    ready.push(u);
                }
            }
        }
    }
    done
}

/// Every name the file declares.
pub(super) fn declared_names(file: &File) -> HashSet<String> {
    let mut out: HashSet<String> = file
        .parameters
        .keys()
        .map(|n| n.get_ref().clone())
        .collect();
    out.extend(file.definitions.keys().map(|n| n.get_ref().clone()));
    for names in [&file.coordinates, &file.velocities].into_iter().flatten() {
        let names = names.get_ref();
        out.extend(names.names.iter().map(|n| n.get_ref().clone()));
        if let Some(v) = &names.velocities {
            out.extend(v.iter().map(|n| n.get_ref().clone()));
        }
    }
    if let Some(c) = &file.coordinates
        && c.get_ref().velocities.is_none()
    {
        out.extend(
            c.get_ref()
                .names
                .iter()
                .map(|n| format!("{}_dot", n.get_ref())),
        );
    }
    out
}
