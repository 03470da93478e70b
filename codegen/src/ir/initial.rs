//! The `[initial]` table: the starting coordinates and velocities, and
//! conditions on rates that are not velocities themselves: a definition
//! linear in the velocities (a body's angular velocity `ball_wz`, a hand
//! written `omega_z`) given a value, which the start's velocity meets with
//! the constraints (the runtime's `simulate::starting_velocity`).

use std::collections::HashMap;
use std::ops::Range;

use indexmap::IndexMap;
use toml::Spanned;

use super::file::Number;
use super::validate::Validator;
use super::{Expr, Param, StartRate};
use crate::diag::{Collector, ErrorKind};

/// What an `[initial]` entry sets.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Target {
    /// A coordinate or a velocity: its slot in the state.
    Slot(usize),
    /// A definition: a condition on the rate it names.
    Rate,
}

/// One entry of the table, its value not yet checked.
pub(super) struct Entry {
    target: Target,
    name: String,
    /// Where the name stands.
    key: Range<usize>,
    value: Expr,
}

/// The checked table.
pub(super) struct Initial {
    /// The state at the file's parameter values (zero where silent).
    pub values: Vec<f64>,
    /// The state as expressions, slot by slot (`None`: silent).
    pub exprs: Vec<Option<Expr>>,
    /// The conditions on rates, in file order.
    pub rates: Vec<StartRate>,
}

impl Validator<'_> {
    /// The `[initial]` table: for each coordinate, velocity or definition
    /// it names, an expression of the parameters (`pi/2`, `r + 1`).
    pub(super) fn initial(
        &mut self,
        coordinates: &[String],
        velocities: &[String],
        definitions: &[String],
        decls: &IndexMap<Spanned<String>, Spanned<Number>>,
    ) -> Vec<Entry> {
        let mut out = Vec::new();
        // A model of the collision instant has no motion to start.
        if coordinates.is_empty()
            && let Some((name, _)) = decls.first()
        {
            self.cx.error(
                ErrorKind::Structure(
                    "[initial] starts a motion, and a model without coordinates (the collision instant only) has none"
                        .into(),
                ),
                Some(name.span()),
            );
            return out;
        }
        for (name, value) in decls {
            let n = name.get_ref();
            let target = match coordinates.iter().chain(velocities).position(|c| c == n) {
                Some(slot) => Target::Slot(slot),
                None if definitions.contains(n) => Target::Rate,
                None => {
                    self.cx.error(
                        ErrorKind::Structure(format!(
                            "[initial] `{n}` is not a coordinate, a velocity or a definition of the model"
                        )),
                        Some(name.span()),
                    );
                    continue;
                }
            };
            let text = match value.get_ref() {
                Number::Int(i) => i.to_string(),
                Number::Float(f) if f.is_finite() => format!("{f:e}"),
                Number::Float(f) => {
                    self.cx.error(
                        ErrorKind::Structure(format!("[initial] `{n}`: {f} is not finite")),
                        Some(value.span()),
                    );
                    continue;
                }
                Number::Text(t) => t.clone(),
            };
            let e = self.expr(&Spanned::new(value.span(), text));
            out.push(Entry {
                target,
                name: n.clone(),
                key: name.span(),
                value: e,
            });
        }
        let rates = out.iter().filter(|e| e.target == Target::Rate);
        if let Some(extra) = rates.clone().nth(velocities.len()) {
            self.cx.error(
                ErrorKind::Structure(format!(
                    "[initial] gives {} rates that are definitions, more than the model's {} velocities can meet",
                    rates.count(),
                    velocities.len()
                )),
                Some(extra.key.clone()),
            );
        }
        out
    }

    /// The initial values at the file's parameter values, the expressions
    /// slot by slot, and the conditions on rates; names other than
    /// parameters in a value are reported.
    pub(super) fn initial_values(
        &mut self,
        params: &[Param],
        derived: &[String],
        definitions: &[(String, Expr)],
        entries: Vec<Entry>,
        n: usize,
    ) -> Initial {
        let mut env: HashMap<String, f64> =
            params.iter().map(|p| (p.name.clone(), p.value)).collect();
        for (name, e) in definitions.iter().filter(|(d, _)| derived.contains(d)) {
            if let Some(v) = e.node.value(&|k| env.get(k).copied()) {
                env.insert(name.clone(), v);
            }
        }
        let mut out = Initial {
            values: vec![0.0; n],
            exprs: vec![None; n],
            rates: Vec::new(),
        };
        for Entry {
            target,
            name,
            key,
            value: e,
        } in entries
        {
            if !parameters_only(self.cx, params, derived, &name, &e) {
                continue;
            }
            if let Some((r, what)) = e.node.constant_problem() {
                let text = e.text.get(r.clone()).unwrap_or_default().to_string();
                self.cx
                    .error(ErrorKind::UndefinedConstant { text, what }, Some(e.at(&r)));
                continue;
            }
            match (e.node.value(&|k| env.get(k).copied()), target) {
                (Some(v), Target::Slot(slot)) if v.is_finite() && slot < n => {
                    out.values[slot] = v;
                    out.exprs[slot] = Some(e);
                }
                (Some(v), Target::Rate) if v.is_finite() => {
                    let rate = self.expr(&Spanned::new(key, name.clone()));
                    out.rates.push(StartRate {
                        name,
                        rate,
                        value: e,
                    });
                }
                _ => {
                    self.cx.error(
                        ErrorKind::Structure(format!(
                            "[initial] `{name}`: `{}` has no finite real value at the file's parameters",
                            e.text
                        )),
                        Some(e.span.clone()),
                    );
                }
            }
        }
        out
    }
}

/// Whether the value `e` of `[initial]` entry `name` names only
/// parameters (and derived ones); the first other name is reported.
fn parameters_only(
    cx: &mut Collector,
    params: &[Param],
    derived: &[String],
    name: &str,
    e: &Expr,
) -> bool {
    let mut foreign = None;
    e.node.visit_names(&mut |k, r| {
        if !params.iter().any(|p| p.name == k)
            && !derived.iter().any(|d| d == k)
            && foreign.is_none()
        {
            foreign = Some((k.to_string(), r.clone()));
        }
    });
    match foreign {
        Some((k, r)) => {
            cx.error(
                ErrorKind::Structure(format!(
                    "[initial] `{name}`: `{k}` is not a parameter; initial values may use parameters, pi and e"
                )),
                Some(e.at(&r)),
            );
            false
        }
        None => true,
    }
}
